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
  first_triangle_.push_back(0);
  for (const MeshInstance& m : scene.meshes) {
    first_triangle_.push_back(first_triangle_.back() + m.mesh->triangle_count());
  }
  vertices_.resize(scene.meshes.size());
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    vertices_[i].clip.resize(scene.meshes[i].mesh->positions.size());
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
    out.clip[v] = mvp * glm::dvec4(glm::dvec3(inst.mesh->positions[v]), 1.0);
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

void GeometryFrontEnd::setup_triangle(std::size_t instance, std::uint32_t local_index,
                                      std::uint32_t primitive, std::vector<TriangleSetup>& out,
                                      SetupCounters& counters) const {
  const MeshInstance& inst = scene_.meshes[instance];
  const InstanceVertices& iv = vertices_[instance];
  const std::uint32_t* idx = &inst.mesh->indices[std::size_t(local_index) * 3];

  ClipPolygon poly;
  for (int k = 0; k < 3; ++k) {
    poly[k].position = iv.clip[idx[k]];
    switch (inst.color_source) {
      case ColorSource::Uniform:
        poly[k].color = inst.color_linear;
        break;
      case ColorSource::PerTriangle: {
        glm::vec3 s = per_triangle_color_srgb(primitive);
        poly[k].color = glm::vec3(srgb_to_linear(s.r), srgb_to_linear(s.g), srgb_to_linear(s.b));
        break;
      }
      case ColorSource::Vertex:
        poly[k].color = iv.color_linear[idx[k]];
        break;
    }
  }
  const bool flat = inst.color_source != ColorSource::Vertex ||
                    (poly[0].color == poly[1].color && poly[0].color == poly[2].color);

  const std::array<ClipPlane, 6> planes = {
      ClipPlane(0, 0, 1, 1),          // near: z >= -w
      ClipPlane(0, 0, -1, 1),         // far: z <= w
      ClipPlane(1, 0, 0, guard_x_),   // guard band left
      ClipPlane(-1, 0, 0, guard_x_),  // guard band right
      ClipPlane(0, 1, 0, guard_y_),   // guard band bottom
      ClipPlane(0, -1, 0, guard_y_),  // guard band top
  };
  // Outcodes: trivially reject when all three are outside one plane.
  unsigned out_any = 0;
  unsigned out_all = 0x3f;
  for (int k = 0; k < 3; ++k) {
    unsigned code = 0;
    for (int p = 0; p < 6; ++p) {
      if (glm::dot(planes[p], poly[k].position) < 0.0) code |= 1u << p;
    }
    out_any |= code;
    out_all &= code;
  }
  if (out_all != 0) {
    ++counters.culled;
    return;
  }
  int count = 3;
  if (out_any != 0) {
    ++counters.clipped;
    // Sutherland-Hodgman. The intersection on an edge is always computed from its inside
    // vertex towards its outside vertex, so that two triangles sharing the edge get the
    // same point bit for bit (watertight clipping).
    ClipPolygon next;
    for (int p = 0; p < 6 && count >= 3; ++p) {
      if (!(out_any & (1u << p))) continue;
      int n = 0;
      for (int k = 0; k < count; ++k) {
        const ClipVertex& a = poly[k];
        const ClipVertex& b = poly[(k + 1) % count];
        double da = glm::dot(planes[p], a.position);
        double db = glm::dot(planes[p], b.position);
        if (da >= 0.0) next[n++] = a;
        if ((da >= 0.0) != (db >= 0.0)) {
          const ClipVertex& in = da >= 0.0 ? a : b;
          const ClipVertex& outv = da >= 0.0 ? b : a;
          double din = da >= 0.0 ? da : db;
          double dout = da >= 0.0 ? db : da;
          double t = din / (din - dout);
          next[n].position = in.position + t * (outv.position - in.position);
          next[n].color = in.color + float(t) * (outv.color - in.color);
          ++n;
        }
      }
      poly = next;
      count = n;
    }
    if (count < 3) {
      ++counters.culled;
      return;
    }
  }

  // Viewport transform and snapping, once per polygon vertex.
  struct Snapped {
    std::int32_t x, y;
    double z;
    float inv_w;
  };
  std::array<Snapped, 12> s;
  for (int k = 0; k < count; ++k) {
    const glm::dvec4& c = poly[k].position;
    double inv_w = 1.0 / c.w;
    double x_px = (c.x * inv_w + 1.0) * 0.5 * width_px_;
    double y_px = (1.0 - c.y * inv_w) * 0.5 * height_px_;
    s[k].x = std::int32_t(std::llrint(x_px * kSubpixelOne));
    s[k].y = std::int32_t(std::llrint(y_px * kSubpixelOne));
    s[k].z = std::clamp(c.z * inv_w * 0.5 + 0.5, 0.0, 1.0);
    s[k].inv_w = float(inv_w);
  }

  // Fan (0, k, k+1) over the clipped polygon.
  for (int k = 1; k + 1 < count; ++k) {
    int v[3] = {0, k, k + 1};
    std::int64_t ax = s[v[1]].x - s[v[0]].x, ay = s[v[1]].y - s[v[0]].y;
    std::int64_t bx = s[v[2]].x - s[v[0]].x, by = s[v[2]].y - s[v[0]].y;
    std::int64_t area2 = ax * by - bx * ay;
    if (area2 == 0) {
      ++counters.culled;
      continue;
    }
    // CCW in NDC (y up) is negative area with y down.
    bool front = area2 < 0;
    if (area2 < 0) std::swap(v[1], v[2]);
    TriangleSetup t;
    for (int j = 0; j < 3; ++j) {
      t.x_fx8[j] = s[v[j]].x;
      t.y_fx8[j] = s[v[j]].y;
      t.inv_w[j] = s[v[j]].inv_w;
      t.color[j] = poly[v[j]].color;
    }
    // Reject triangles wholly outside the image.
    PixelRect r = touched_pixels(t);
    if (r.x1 <= 0 || r.y1 <= 0 || r.x0 >= width_px_ || r.y0 >= height_px_) {
      ++counters.culled;
      continue;
    }
    const double inv_one = 1.0 / kSubpixelOne;
    double dx1 = (t.x_fx8[1] - t.x_fx8[0]) * inv_one, dy1 = (t.y_fx8[1] - t.y_fx8[0]) * inv_one;
    double dx2 = (t.x_fx8[2] - t.x_fx8[0]) * inv_one, dy2 = (t.y_fx8[2] - t.y_fx8[0]) * inv_one;
    double dz1 = s[v[1]].z - s[v[0]].z, dz2 = s[v[2]].z - s[v[0]].z;
    double det = dx1 * dy2 - dx2 * dy1;
    t.z0 = s[v[0]].z;
    t.dzdx = (dz1 * dy2 - dz2 * dy1) / det;
    t.dzdy = (dx1 * dz2 - dx2 * dz1) / det;
    t.primitive = primitive;
    t.surface = std::uint32_t(instance);
    t.front_facing = front;
    t.flat_color = flat;
    out.push_back(t);
  }
}

}  // namespace covrast::detail
