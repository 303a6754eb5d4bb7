// Splitting an OBJ polygon into triangles (mesh_obj.cpp): the fan for convex polygons, ear
// clipping in the polygon's dominant plane for the others (docs/scene-format.md).
#pragma once

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace covrast::detail {

/// How triangulate_polygon split a polygon.
enum class PolygonSplit : std::uint8_t {
  Fan,         ///< convex (or a triangle): the fan (0, k, k + 1), k = 1 .. n - 2
  EarClipped,  ///< concave: ear clipping
  Fallback,    ///< degenerate, self-intersecting or too large to clip: the fan, as for convex
};

/// Polygons with more corners than this are not ear-clipped (clipping is O(n^2) or worse)
/// but split as the fan, with PolygonSplit::Fallback.
inline constexpr std::size_t kMaxEarClipCorners = 4096;

/// Appends the triangles of the polygon whose corners, in file order, are at `ring` (object
/// space) to `out`, as triples of corner numbers 0 .. ring.size() - 1. Every triangle keeps
/// the ring's winding. Always n - 2 triangles.
PolygonSplit triangulate_polygon(const std::vector<glm::dvec3>& ring,
                                 std::vector<std::uint32_t>& out);

}  // namespace covrast::detail
