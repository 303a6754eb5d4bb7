// Geometry stage implementation; see frontend.hpp.
#include "geometry/frontend.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <array>
#include <cmath>

namespace covrast::detail {
namespace {

struct ClipVertex {
  glm::dvec4 position;
  glm::vec3 color;
};

/// Up to 3 + 6 planes' worth of vertices after Sutherland-Hodgman.
using ClipPolygon = std::array<ClipVertex, 12>;

/// Homogeneous plane: inside where dot(plane, position) >= 0.
using ClipPlane = glm::dvec4;

}  // namespace

GeometryFrontEnd::GeometryFrontEnd(const Scene& scene, int width_px, int height_px)
    : scene_(scene), width_px_(width_px), height_px_(height_px) {
  const Camera& cam = scene.camera;
  glm::dmat4 view = glm::lookAt(cam.eye, cam.target, cam.up);
  glm::dmat4 projection = glm::perspective(glm::radians(cam.fovy_deg),
                                           double(width_px) / double(height_px), cam.near, cam.far);
  view_projection_ = projection * view;
  guard_x_ = 1.0 + 2.0 * kGuardBandPx / width_px;
  guard_y_ = 1.0 + 2.0 * kGuardBandPx / height_px;
  planes_[0] = ClipPlane(0, 0, 1, 1);          // near: z >= -w
  planes_[1] = ClipPlane(0, 0, -1, 1);         // far: z <= w
  planes_[2] = ClipPlane(1, 0, 0, guard_x_);   // guard band left
  planes_[3] = ClipPlane(-1, 0, 0, guard_x_);  // guard band right
  planes_[4] = ClipPlane(0, 1, 0, guard_y_);   // guard band bottom
  planes_[5] = ClipPlane(0, -1, 0, guard_y_);  // guard band top
  first_triangle_.push_back(0);
  for (const MeshInstance& m : scene.meshes) {
    first_triangle_.push_back(first_triangle_.back() + m.mesh->triangle_count());
  }
  vertices_.resize(scene.meshes.size());
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    vertices_[i].clip.resize(scene.meshes[i].mesh->positions.size());
    vertices_[i].outcode.resize(scene.meshes[i].mesh->positions.size());
    vertices_[i].snapped.resize(scene.meshes[i].mesh->positions.size());
    if (scene.meshes[i].color_source == ColorSource::Vertex) {
      vertices_[i].color_linear.resize(scene.meshes[i].mesh->positions.size());
    }
  }
}

std::size_t GeometryFrontEnd::vertex_count(std::size_t instance) const {
  return scene_.meshes[instance].mesh->positions.size();
}

void GeometryFrontEnd::transform_vertices(std::size_t instance, std::size_t begin,
                                          std::size_t end) {
  const MeshInstance& inst = scene_.meshes[instance];
  const glm::dmat4 mvp = view_projection_ * inst.model;
  InstanceVertices& out = vertices_[instance];
  for (std::size_t v = begin; v < end; ++v) {
    const glm::dvec4 clip = mvp * glm::dvec4(glm::dvec3(inst.mesh->positions[v]), 1.0);
    out.clip[v] = clip;
    out.outcode[v] = std::uint8_t(outcode(clip));
    if (out.outcode[v] == 0) out.snapped[v] = snap(clip);
  }
  if (inst.color_source == ColorSource::Vertex) {
    const auto& colors = inst.mesh->colors_linear;
    for (std::size_t v = begin; v < end; ++v) {
      glm::vec3 c = v < colors.size() ? colors[v] : glm::vec3(1.0f);
      out.color_linear[v] = c * inst.color_factor_linear;
    }
  }
}

void GeometryFrontEnd::setup_chunk(std::uint32_t chunk, std::vector<TriangleSetup>& out,
                                   SetupCounters& counters) const {
  std::uint64_t first = std::uint64_t(chunk) * kTrianglesPerChunk;
  std::uint64_t last = std::min<std::uint64_t>(first + kTrianglesPerChunk, triangle_count());
  // The instance holding `first`: first_triangle_ is sorted, find the last entry <= first.
  std::size_t instance =
      std::size_t(std::upper_bound(first_triangle_.begin(), first_triangle_.end(), first) -
                  first_triangle_.begin()) -
      1;
  for (std::uint64_t g = first; g < last; ++g) {
    while (g >= first_triangle_[instance + 1]) ++instance;
    setup_triangle(instance, std::uint32_t(g - first_triangle_[instance]), std::uint32_t(g), out,
                   counters);
  }
}

unsigned GeometryFrontEnd::outcode(const glm::dvec4& clip) const {
  unsigned code = 0;
  for (int p = 0; p < 6; ++p) {
    if (glm::dot(planes_[p], clip) < 0.0) code |= 1u << p;
  }
  return code;
}

SnappedVertex GeometryFrontEnd::snap(const glm::dvec4& c) const {
  const double inv_w = 1.0 / c.w;
  const double x_px = (c.x * inv_w + 1.0) * 0.5 * width_px_;
  const double y_px = (1.0 - c.y * inv_w) * 0.5 * height_px_;
  return SnappedVertex{std::int32_t(std::llrint(x_px * kSubpixelOne)),
                       std::int32_t(std::llrint(y_px * kSubpixelOne)),
                       std::clamp(c.z * inv_w * 0.5 + 0.5, 0.0, 1.0), float(inv_w)};
}

void GeometryFrontEnd::emit_triangle(const SnappedVertex* s, const glm::vec3* color, bool flat,
                                     std::uint32_t primitive, std::uint32_t surface,
                                     std::vector<TriangleSetup>& out,
                                     SetupCounters& counters) const {
  int v[3] = {0, 1, 2};
  const std::int64_t ax = s[1].x_fx8 - s[0].x_fx8, ay = s[1].y_fx8 - s[0].y_fx8;
  const std::int64_t bx = s[2].x_fx8 - s[0].x_fx8, by = s[2].y_fx8 - s[0].y_fx8;
  const std::int64_t area2 = ax * by - bx * ay;
  if (area2 == 0) {
    ++counters.culled;
    return;
  }
  // CCW in NDC (y up) is negative area with y down; reorder to positive area.
  const bool front = area2 < 0;
  if (front) std::swap(v[1], v[2]);
  TriangleSetup t;
  for (int j = 0; j < 3; ++j) {
    t.x_fx8[j] = s[v[j]].x_fx8;
    t.y_fx8[j] = s[v[j]].y_fx8;
    t.inv_w[j] = s[v[j]].inv_w;
    t.color[j] = color[v[j]];
  }
  // Reject triangles wholly outside the image.
  const PixelRect r = touched_pixels(t);
  if (r.x1 <= 0 || r.y1 <= 0 || r.x0 >= width_px_ || r.y0 >= height_px_) {
    ++counters.culled;
    return;
  }
  // Depth plane from the snapped positions.
  const double inv_one = 1.0 / kSubpixelOne;
  const double dx1 = (t.x_fx8[1] - t.x_fx8[0]) * inv_one, dy1 = (t.y_fx8[1] - t.y_fx8[0]) * inv_one;
  const double dx2 = (t.x_fx8[2] - t.x_fx8[0]) * inv_one, dy2 = (t.y_fx8[2] - t.y_fx8[0]) * inv_one;
  const double dz1 = s[v[1]].z_window - s[v[0]].z_window;
  const double dz2 = s[v[2]].z_window - s[v[0]].z_window;
  const double det = dx1 * dy2 - dx2 * dy1;
  t.z0 = s[v[0]].z_window;
  t.dzdx = (dz1 * dy2 - dz2 * dy1) / det;
  t.dzdy = (dx1 * dz2 - dx2 * dz1) / det;
  t.primitive = primitive;
  t.surface = surface;
  t.front_facing = front;
  t.flat_color = flat;
  out.push_back(t);
}

void GeometryFrontEnd::setup_triangle(std::size_t instance, std::uint32_t local_index,
                                      std::uint32_t primitive, std::vector<TriangleSetup>& out,
                                      SetupCounters& counters) const {
  const MeshInstance& inst = scene_.meshes[instance];
  const InstanceVertices& iv = vertices_[instance];
  const std::uint32_t* idx = &inst.mesh->indices[std::size_t(local_index) * 3];

  glm::vec3 color[3];
  switch (inst.color_source) {
    case ColorSource::Uniform:
      color[0] = color[1] = color[2] = inst.color_linear;
      break;
    case ColorSource::PerTriangle: {
      const glm::vec3 s = per_triangle_color_srgb(primitive);
      color[0] = color[1] = color[2] =
          glm::vec3(srgb_to_linear(s.r), srgb_to_linear(s.g), srgb_to_linear(s.b));
      break;
    }
    case ColorSource::Vertex:
      for (int k = 0; k < 3; ++k) color[k] = iv.color_linear[idx[k]];
      break;
  }
  const bool flat = color[0] == color[1] && color[0] == color[2];

  // Outcodes: trivially reject when all three are outside one plane; trivially accept
  // (with the vertices snapped once in transform_vertices) when none is outside any.
  const unsigned c0 = iv.outcode[idx[0]], c1 = iv.outcode[idx[1]], c2 = iv.outcode[idx[2]];
  if ((c0 & c1 & c2) != 0) {
    ++counters.culled;
    return;
  }
  if ((c0 | c1 | c2) == 0) {
    const SnappedVertex s[3] = {iv.snapped[idx[0]], iv.snapped[idx[1]], iv.snapped[idx[2]]};
    emit_triangle(s, color, flat, primitive, std::uint32_t(instance), out, counters);
    return;
  }
  ++counters.clipped;
  const unsigned out_any = c0 | c1 | c2;
  ClipPolygon poly, next;
  for (int k = 0; k < 3; ++k) poly[k] = ClipVertex{iv.clip[idx[k]], color[k]};
  int count = 3;
  // Sutherland-Hodgman. The intersection on an edge is always computed from its inside
  // vertex towards its outside vertex, so that two triangles sharing the edge get the
  // same point bit for bit (watertight clipping).
  for (int p = 0; p < 6 && count >= 3; ++p) {
    if (!(out_any & (1u << p))) continue;
    int n = 0;
    for (int k = 0; k < count; ++k) {
      const ClipVertex& a = poly[k];
      const ClipVertex& b = poly[(k + 1) % count];
      const double da = glm::dot(planes_[p], a.position);
      const double db = glm::dot(planes_[p], b.position);
      if (da >= 0.0) next[n++] = a;
      if ((da >= 0.0) != (db >= 0.0)) {
        const ClipVertex& in = da >= 0.0 ? a : b;
        const ClipVertex& outv = da >= 0.0 ? b : a;
        const double din = da >= 0.0 ? da : db;
        const double dout = da >= 0.0 ? db : da;
        const double t = din / (din - dout);
        next[n].position = in.position + t * (outv.position - in.position);
        next[n].color = in.color + float(t) * (outv.color - in.color);
        ++n;
      }
    }
    std::swap(poly, next);
    count = n;
  }
  if (count < 3) {
    ++counters.culled;
    return;
  }
  SnappedVertex s[12];
  glm::vec3 pc[12];
  for (int k = 0; k < count; ++k) {
    s[k] = snap(poly[k].position);
    pc[k] = poly[k].color;
  }
  // Fan (0, k, k+1) over the clipped polygon.
  for (int k = 1; k + 1 < count; ++k) {
    const SnappedVertex tri[3] = {s[0], s[k], s[k + 1]};
    const glm::vec3 tc[3] = {pc[0], pc[k], pc[k + 1]};
    emit_triangle(tri, tc, flat, primitive, std::uint32_t(instance), out, counters);
  }
}

}  // namespace covrast::detail
