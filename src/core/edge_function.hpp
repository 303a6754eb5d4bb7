// Edge functions on the 24.8 fixed-point vertices, shared by the sample-based modes
// (aliased, MSAA, SSAA) and by the sub-pixel masks of the coverage resolve.
//
//   E_ij(p) = (x_j - x_i)(p_y - y_i) - (y_j - y_i)(p_x - x_i)   [fx8^2 units, int64]
//
// With the setup's orientation (positive doubled area) a point is inside when all three
// are positive. Ties use the top-left rule (D3D/OpenGL): a sample exactly on an edge
// belongs to the triangle only if the edge is a top edge (horizontal, interior below) or a
// left edge (interior to its right); so a sample on an edge shared by two triangles
// belongs to exactly one of them. With y down and the interior normal n = (-dy, dx):
// top  <=> dy == 0 && dx > 0,   left <=> dy < 0.
#pragma once

#include "core/triangle_setup.hpp"

#include <cstdint>

namespace covrast::detail {

struct EdgeFunction {
  std::int64_t dx;    ///< x_j - x_i [fx8]
  std::int64_t dy;    ///< y_j - y_i [fx8]
  std::int64_t x0;    ///< x_i [fx8]
  std::int64_t y0;    ///< y_i [fx8]
  std::int64_t bias;  ///< 0 for top-left edges, -1 otherwise: inside <=> E + bias >= 0

  EdgeFunction(std::int32_t xi, std::int32_t yi, std::int32_t xj, std::int32_t yj)
      : dx(std::int64_t(xj) - xi), dy(std::int64_t(yj) - yi), x0(xi), y0(yi) {
    bool top_left = dy < 0 || (dy == 0 && dx > 0);
    bias = top_left ? 0 : -1;
  }
  /// E + bias at a point in fx8 units: >= 0 means inside this edge.
  std::int64_t at(std::int64_t px_fx8, std::int64_t py_fx8) const {
    return dx * (py_fx8 - y0) - dy * (px_fx8 - x0) + bias;
  }
  std::int64_t step_x(std::int64_t step_fx8) const { return -dy * step_fx8; }
  std::int64_t step_y(std::int64_t step_fx8) const { return dx * step_fx8; }
};

struct TriangleEdges {
  EdgeFunction e[3];
  explicit TriangleEdges(const TriangleSetup& t)
      : e{EdgeFunction(t.x_fx8[0], t.y_fx8[0], t.x_fx8[1], t.y_fx8[1]),
          EdgeFunction(t.x_fx8[1], t.y_fx8[1], t.x_fx8[2], t.y_fx8[2]),
          EdgeFunction(t.x_fx8[2], t.y_fx8[2], t.x_fx8[0], t.y_fx8[0])} {}
};

}  // namespace covrast::detail
