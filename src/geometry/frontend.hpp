// Geometry stage: model-view-projection transform, homogeneous clipping, viewport
// transform, snapping to 24.8 fixed point, and triangle setup.
//
// Work is split into fixed chunks of the global triangle sequence (all meshes in list
// order, faces in file order), so that the output order, and so the image, never depends
// on the thread count.
#pragma once

#include "geometry/triangle_setup.hpp"

#include <covrast/scene.hpp>

#include <cstdint>
#include <vector>

namespace covrast::detail {

/// Triangles per setup/binning chunk: large enough to amortise a task, small enough to
/// balance 500k triangles over a few cores.
inline constexpr std::uint32_t kTrianglesPerChunk = 8192;

/// A vertex after the viewport transform, snapped to 24.8 fixed point.
struct SnappedVertex {
  std::int32_t x_fx8;
  std::int32_t y_fx8;
  double z_window;  ///< [0, 1]
  float inv_w;      ///< 1 / clip w
};

/// Clip-space vertices of one mesh instance, with their clip outcodes and, for vertices
/// inside every plane, their snapped screen position (shared by all their triangles).
struct InstanceVertices {
  std::vector<glm::dvec4> clip;
  std::vector<std::uint8_t> outcode;     ///< bit p set: outside clip plane p
  std::vector<SnappedVertex> snapped;    ///< valid where outcode == 0
  std::vector<glm::vec3> color_linear;   ///< only for ColorSource::Vertex
};

struct SetupCounters {
  std::uint64_t culled = 0;   ///< outside the view volume, or zero area after snapping
  std::uint64_t clipped = 0;  ///< crossed a clip plane
};

class GeometryFrontEnd {
public:
  GeometryFrontEnd(const Scene& scene, int width_px, int height_px);

  std::uint64_t triangle_count() const { return first_triangle_.back(); }
  std::uint32_t chunk_count() const {
    return std::uint32_t((triangle_count() + kTrianglesPerChunk - 1) / kTrianglesPerChunk);
  }
  std::size_t instance_count() const { return scene_.meshes.size(); }

  /// Transforms the vertices of one instance (vertices [begin, end)) to clip space.
  void transform_vertices(std::size_t instance, std::size_t begin, std::size_t end);
  std::size_t vertex_count(std::size_t instance) const;

  /// Clips, snaps and sets up the triangles of one chunk, appending to `out` in order.
  void setup_chunk(std::uint32_t chunk, std::vector<TriangleSetup>& out,
                   SetupCounters& counters) const;

private:
  SnappedVertex snap(const glm::dvec4& clip) const;
  unsigned outcode(const glm::dvec4& clip) const;
  void emit_triangle(const SnappedVertex* v, const glm::vec3* color, bool flat,
                     std::uint32_t primitive, std::uint32_t surface,
                     std::vector<TriangleSetup>& out, SetupCounters& counters) const;
  void setup_triangle(std::size_t instance, std::uint32_t local_index, std::uint32_t primitive,
                      std::vector<TriangleSetup>& out, SetupCounters& counters) const;

  const Scene& scene_;
  int width_px_;
  int height_px_;
  glm::dmat4 view_projection_;
  double guard_x_;  ///< guard band half-extent in NDC units, x
  double guard_y_;  ///< same, y
  glm::dvec4 planes_[6];  ///< homogeneous clip planes: inside where dot(plane, v) >= 0
  std::vector<std::uint64_t> first_triangle_;  ///< prefix sums of triangle counts
  std::vector<InstanceVertices> vertices_;
};

}  // namespace covrast::detail
