// Resolve stage, coverage mode: whether two snapped triangles can overlap, exactly.
//
// The A-buffer adds the exact areas of fragments only where it has proven that they do not
// overlap (abuffer.hpp). The proof is the separating-axis theorem for convex polygons: two
// triangles have disjoint interiors if and only if the line of one of their six edges has
// the other triangle wholly on its closed outer side. With the set-up's orientation (positive
// doubled area, clockwise on screen, y down) the inside of edge i -> j is
//
//   E_ij(p) = (x_j - x_i)(p_y - y_i) - (y_j - y_i)(p_x - x_i) >= 0,
//
// so triangle b lies outside edge i -> j of a when E_ij(b_k) <= 0 for its three vertices. All
// in int64 on the 24.8 vertices (|coordinate| < 2^24 fx8 units, products < 2^50): exact, no
// tolerance, and two triangles that share an edge from opposite sides (a conforming
// tessellation) are separated by that edge. Touching along an edge or at a point counts as
// disjoint: the overlap has zero area.
#pragma once

#include "geometry/triangle_setup.hpp"

#include <cstdint>

namespace covrast::detail {

/// Whether some edge line of `a` has all of `b` on its closed outer side.
inline bool separated_by_edge_of(const TriangleSetup& a, const TriangleSetup& b) {
  for (int i = 0; i < 3; ++i) {
    const int j = i == 2 ? 0 : i + 1;
    const std::int64_t xi = a.x_fx8[i], yi = a.y_fx8[i];
    const std::int64_t dx = a.x_fx8[j] - xi, dy = a.y_fx8[j] - yi;
    bool outside = true;
    for (int k = 0; k < 3; ++k) {
      outside &= dx * (b.y_fx8[k] - yi) - dy * (b.x_fx8[k] - xi) <= 0;
    }
    if (outside) return true;
  }
  return false;
}

/// Whether `b` runs along an edge of `a` in the opposite direction (a -> b in a, b -> a in
/// b): then the two lie on opposite sides of that edge's line, as neighbours in a
/// consistently oriented tessellation do, and are disjoint. The cheap common case, first.
inline bool share_edge_reversed(const TriangleSetup& a, const TriangleSetup& b) {
  for (int i = 0; i < 3; ++i) {
    const int i1 = i == 2 ? 0 : i + 1;
    for (int k = 0; k < 3; ++k) {
      const int k1 = k == 2 ? 0 : k + 1;
      if (a.x_fx8[i] == b.x_fx8[k1] && a.y_fx8[i] == b.y_fx8[k1] && a.x_fx8[i1] == b.x_fx8[k] &&
          a.y_fx8[i1] == b.y_fx8[k]) {
        return true;
      }
    }
  }
  return false;
}

/// Whether the interiors of `a` and `b` are disjoint (their overlap has zero area).
inline bool interiors_disjoint(const TriangleSetup& a, const TriangleSetup& b) {
  return share_edge_reversed(a, b) || separated_by_edge_of(a, b) || separated_by_edge_of(b, a);
}

/// Whether `inner` lies inside or on the edges of `outer` (so inner is a subset of outer).
inline bool contains_triangle(const TriangleSetup& outer, const TriangleSetup& inner) {
  for (int i = 0; i < 3; ++i) {
    const int j = i == 2 ? 0 : i + 1;
    const std::int64_t xi = outer.x_fx8[i], yi = outer.y_fx8[i];
    const std::int64_t dx = outer.x_fx8[j] - xi, dy = outer.y_fx8[j] - yi;
    for (int k = 0; k < 3; ++k) {
      if (dx * (inner.y_fx8[k] - yi) - dy * (inner.x_fx8[k] - xi) < 0) return false;
    }
  }
  return true;
}

}  // namespace covrast::detail
