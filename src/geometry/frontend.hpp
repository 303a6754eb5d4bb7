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

/// Clip-space vertices of one mesh instance.
struct InstanceVertices {
  std::vector<glm::dvec4> clip;
  std::vector<glm::vec3> color_linear;  ///< only for ColorSource::Vertex
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
  void setup_triangle(std::size_t instance, std::uint32_t local_index, std::uint32_t primitive,
                      std::vector<TriangleSetup>& out, SetupCounters& counters) const;

  const Scene& scene_;
  int width_px_;
  int height_px_;
  glm::dmat4 view_projection_;
  double guard_x_;  ///< guard band half-extent in NDC units, x
  double guard_y_;  ///< same, y
  std::vector<std::uint64_t> first_triangle_;  ///< prefix sums of triangle counts
  std::vector<InstanceVertices> vertices_;
};

}  // namespace covrast::detail
