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

#include "core/triangle_setup.hpp"

#include <cstdint>

namespace covrast::detail {

/// Whether the edge i -> j of `a` has the vertices of `b` other than `skip` (-1: none) on
/// its closed outer side.
inline bool edge_separates(const TriangleSetup& a, int i, const TriangleSetup& b, int skip) {
  const int j = i == 2 ? 0 : i + 1;
  const std::int64_t xi = a.x_fx8[i], yi = a.y_fx8[i];
  const std::int64_t dx = a.x_fx8[j] - xi, dy = a.y_fx8[j] - yi;
  bool outside = true;
  for (int k = 0; k < 3; ++k) {
    if (k != skip) outside &= dx * (b.y_fx8[k] - yi) - dy * (b.x_fx8[k] - xi) <= 0;
  }
  return outside;
}

/// Whether some edge line of `a` has all of `b` on its closed outer side.
inline bool separated_by_edge_of(const TriangleSetup& a, const TriangleSetup& b) {
  return edge_separates(a, 0, b, -1) || edge_separates(a, 1, b, -1) || edge_separates(a, 2, b, -1);
}

/// Whether the interiors of `a` and `b` are disjoint (their overlap has zero area).
///  - Sharing an edge (both its vertices): disjoint exactly when the edge runs the other way
///    in b, i.e. the two lie on its opposite sides (with both oriented alike, the same way
///    means the same side, and they overlap along it).
///  - Sharing one vertex v: a separating line must pass through v, so it is the line of an
///    edge at v; only those four edges, against the other two vertices, need testing.
///  - Otherwise all six edges.
inline bool interiors_disjoint(const TriangleSetup& a, const TriangleSetup& b) {
  int shared = 0, ia = -1, ib = -1, ia2 = -1, ib2 = -1;
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) {
      if (a.x_fx8[i] == b.x_fx8[k] && a.y_fx8[i] == b.y_fx8[k]) {
        ++shared;
        if (ia < 0) {
          ia = i;
          ib = k;
        } else {
          ia2 = i;
          ib2 = k;
        }
      }
    }
  }
  if (shared >= 2) {
    if (shared > 2) return false;  // the same triangle
    // a's edge ia -> ia2 or ia2 -> ia; reversed in b when b's order of the two is the other.
    const bool a_forward = ia2 == (ia == 2 ? 0 : ia + 1);  // ia -> ia2 is an edge of a
    const bool b_forward = ib2 == (ib == 2 ? 0 : ib + 1);  // ib -> ib2 is an edge of b
    return a_forward != b_forward;
  }
  if (shared == 1) {
    const int a_prev = ia == 0 ? 2 : ia - 1, b_prev = ib == 0 ? 2 : ib - 1;
    return edge_separates(a, ia, b, ib) || edge_separates(a, a_prev, b, ib) ||
           edge_separates(b, ib, a, ia) || edge_separates(b, b_prev, a, ia);
  }
  return separated_by_edge_of(a, b) || separated_by_edge_of(b, a);
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
