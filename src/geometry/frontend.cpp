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

inline unsigned GeometryFrontEnd::outcode(const glm::dvec4& clip) const {
  unsigned code = 0;
  for (int p = 0; p < 6; ++p) {
    if (glm::dot(planes_[p], clip) < 0.0) code |= 1u << p;
  }
  return code;
}

// Inline, so that transform_vertices writes the snapped vertex in place (a returned copy
// costs a store-forwarding stall per vertex).
inline SnappedVertex GeometryFrontEnd::snap(const glm::dvec4& c) const {
  const double inv_w = 1.0 / c.w;
  const double x_px = (c.x * inv_w + 1.0) * 0.5 * width_px_;
  const double y_px = (1.0 - c.y * inv_w) * 0.5 * height_px_;
  return SnappedVertex{std::int32_t(std::llrint(x_px * kSubpixelOne)),
                       std::int32_t(std::llrint(y_px * kSubpixelOne)),
                       std::clamp(c.z * inv_w * 0.5 + 0.5, 0.0, 1.0), float(inv_w)};
}

void GeometryFrontEnd::transform_vertices(std::size_t instance, std::size_t begin,
                                          std::size_t end) {
  const MeshInstance& inst = scene_.meshes[instance];
  const glm::dmat4 mvp = view_projection_ * inst.model;
  InstanceVertices& out = vertices_[instance];
  for (std::size_t v = begin; v < end; ++v) {
    const glm::dvec4 clip = mvp * glm::dvec4(glm::dvec3(inst.mesh->positions[v]), 1.0);
    const auto code = std::uint8_t(outcode(clip));
    out.clip[v] = clip;
    out.outcode[v] = code;
    if (code == 0) out.snapped[v] = snap(clip);
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
  Sink sink{&out, nullptr, nullptr, counters};
  setup_range(chunk, sink);
}

void GeometryFrontEnd::setup_chunk(std::uint32_t chunk, SetupVector& out,
                                   std::vector<PixelBounds16>& bounds,
                                   SetupCounters& counters) const {
  Sink sink{nullptr, &out, &bounds, counters};
  setup_range(chunk, sink);
}

void GeometryFrontEnd::setup_range(std::uint32_t chunk, Sink& sink) const {
  const std::uint64_t first = std::uint64_t(chunk) * kTrianglesPerChunk;
  const std::uint64_t last = std::min<std::uint64_t>(first + kTrianglesPerChunk, triangle_count());
  // The instance holding `first`: first_triangle_ is sorted, find the last entry <= first.
  std::size_t instance =
      std::size_t(std::upper_bound(first_triangle_.begin(), first_triangle_.end(), first) -
                  first_triangle_.begin()) -
      1;
  // One run of triangles per instance, with the instance's data looked up once.
  for (std::uint64_t g = first; g < last; ++instance) {
    const std::uint64_t run_end = std::min(last, first_triangle_[instance + 1]);
    if (g >= run_end) continue;  // an instance without triangles
    const MeshInstance& inst = scene_.meshes[instance];
    const InstanceVertices& iv = vertices_[instance];
    const std::uint32_t* indices = inst.mesh->indices.data() + (g - first_triangle_[instance]) * 3;
    // A uniform colour is flat unless it is NaN (the per-triangle comparison's result).
    const glm::vec3 uniform = inst.color_linear;
    const bool uniform_flat = uniform == uniform;
    for (; g < run_end; ++g, indices += 3) {
      const auto primitive = std::uint32_t(g);
      glm::vec3 color[3];
      bool flat;
      switch (inst.color_source) {
        case ColorSource::Uniform:
          color[0] = color[1] = color[2] = uniform;
          flat = uniform_flat;
          break;
        case ColorSource::PerTriangle: {
          const glm::vec3 c = per_triangle_color_srgb(primitive);
          color[0] = color[1] = color[2] =
              glm::vec3(srgb_to_linear(c.r), srgb_to_linear(c.g), srgb_to_linear(c.b));
          flat = color[0] == color[0];
          break;
        }
        case ColorSource::Vertex:
        default:
          for (int k = 0; k < 3; ++k) color[k] = iv.color_linear[indices[k]];
          flat = color[0] == color[1] && color[0] == color[2];
          break;
      }
      // Outcodes: trivially reject when all three are outside one plane; trivially accept
      // (with the vertices snapped once in transform_vertices) when none is outside any.
      const unsigned c0 = iv.outcode[indices[0]], c1 = iv.outcode[indices[1]],
                     c2 = iv.outcode[indices[2]];
      if ((c0 & c1 & c2) != 0) {
        ++sink.counters.culled;
      } else if ((c0 | c1 | c2) == 0) {
        emit_triangle(iv.snapped[indices[0]], iv.snapped[indices[1]], iv.snapped[indices[2]], color,
                      flat, primitive, std::uint32_t(instance), sink);
      } else {
        clip_triangle(instance, indices, color, flat, c0 | c1 | c2, primitive, sink);
      }
    }
  }
}

void GeometryFrontEnd::emit_triangle(const SnappedVertex& v0, const SnappedVertex& v1,
                                     const SnappedVertex& v2, const glm::vec3* color, bool flat,
                                     std::uint32_t primitive, std::uint32_t surface,
                                     Sink& sink) const {
  const std::int64_t ax = v1.x_fx8 - v0.x_fx8, ay = v1.y_fx8 - v0.y_fx8;
  const std::int64_t bx = v2.x_fx8 - v0.x_fx8, by = v2.y_fx8 - v0.y_fx8;
  const std::int64_t area2 = ax * by - bx * ay;
  if (area2 == 0) {
    ++sink.counters.culled;
    return;
  }
  // Reject triangles wholly outside the image (touched_pixels of the vertices, in any order).
  const std::int32_t minx = std::min(v0.x_fx8, std::min(v1.x_fx8, v2.x_fx8));
  const std::int32_t maxx = std::max(v0.x_fx8, std::max(v1.x_fx8, v2.x_fx8));
  const std::int32_t miny = std::min(v0.y_fx8, std::min(v1.y_fx8, v2.y_fx8));
  const std::int32_t maxy = std::max(v0.y_fx8, std::max(v1.y_fx8, v2.y_fx8));
  const PixelRect r{minx >> kSubpixelBits, miny >> kSubpixelBits,
                    (maxx + kSubpixelOne - 1) >> kSubpixelBits,
                    (maxy + kSubpixelOne - 1) >> kSubpixelBits};
  if (r.x1 <= 0 || r.y1 <= 0 || r.x0 >= width_px_ || r.y0 >= height_px_) {
    ++sink.counters.culled;
    return;
  }
  if (sink.bounds != nullptr) {
    // Non-empty: a triangle of non-zero area has min < max on both axes.
    sink.bounds->push_back(PixelBounds16{
        std::uint16_t(std::max(r.x0, 0)), std::uint16_t(std::max(r.y0, 0)),
        std::uint16_t(std::min(r.x1, width_px_)), std::uint16_t(std::min(r.y1, height_px_))});
  }
  // CCW in NDC (y up) is negative area with y down; reorder to positive area.
  const bool front = area2 < 0;
  const SnappedVertex& s0 = v0;
  const SnappedVertex& s1 = front ? v2 : v1;
  const SnappedVertex& s2 = front ? v1 : v2;
  // Written in place: building a copy on the stack and pushing it costs store-forwarding
  // stalls on this hot path.
  TriangleSetup& t = sink.next();
  t.x_fx8[0] = s0.x_fx8;
  t.x_fx8[1] = s1.x_fx8;
  t.x_fx8[2] = s2.x_fx8;
  t.y_fx8[0] = s0.y_fx8;
  t.y_fx8[1] = s1.y_fx8;
  t.y_fx8[2] = s2.y_fx8;
  // Depth plane from the snapped positions.
  const double inv_one = 1.0 / kSubpixelOne;
  const double dx1 = (s1.x_fx8 - s0.x_fx8) * inv_one, dy1 = (s1.y_fx8 - s0.y_fx8) * inv_one;
  const double dx2 = (s2.x_fx8 - s0.x_fx8) * inv_one, dy2 = (s2.y_fx8 - s0.y_fx8) * inv_one;
  const double dz1 = s1.z_window - s0.z_window;
  const double dz2 = s2.z_window - s0.z_window;
  const double det = dx1 * dy2 - dx2 * dy1;
  t.z0 = s0.z_window;
  // Both slopes in one two-lane division (the same IEEE quotients as two scalar ones, at
  // half the divider time on this hot path).
  using Double2 = double __attribute__((vector_size(16)));
  const Double2 numerator = {dz1 * dy2 - dz2 * dy1, dx1 * dz2 - dx2 * dz1};
  const Double2 slope = numerator / Double2{det, det};
  t.dzdx = slope[0];
  t.dzdy = slope[1];
  t.inv_w[0] = s0.inv_w;
  t.inv_w[1] = s1.inv_w;
  t.inv_w[2] = s2.inv_w;
  t.color[0] = color[0];
  t.color[1] = color[front ? 2 : 1];
  t.color[2] = color[front ? 1 : 2];
  t.primitive = primitive;
  t.surface = surface;
  t.front_facing = front;
  t.flat_color = flat;
}

void GeometryFrontEnd::clip_triangle(std::size_t instance, const std::uint32_t* idx,
                                     const glm::vec3* color, bool flat, unsigned out_any,
                                     std::uint32_t primitive, Sink& sink) const {
  const InstanceVertices& iv = vertices_[instance];
  ++sink.counters.clipped;
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
    ++sink.counters.culled;
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
    const glm::vec3 tc[3] = {pc[0], pc[k], pc[k + 1]};
    emit_triangle(s[0], s[k], s[k + 1], tc, flat, primitive, std::uint32_t(instance), sink);
  }
}

}  // namespace covrast::detail
