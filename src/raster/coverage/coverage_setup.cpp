// Raster stage, coverage mode: per-triangle and per-column set-up of the kernel's inputs,
// in double precision from the snapped vertices (see coverage_kernel.hpp for the formula).
// The scalar twins built on it are in coverage_kernel_scalar.cpp.
#include "raster/coverage/coverage_kernel.hpp"

#include <algorithm>
#include <climits>
#include <cmath>

namespace covrast::detail {
namespace {

CoverageEdge make_edge(double xa, double ya, double xb, double yb) {
  // The canonical direction (left to right, then top to bottom), so that both triangles of
  // a shared edge compute every term from the same numbers in the same order: the caller
  // passes the vertices in (x, y) order, so (xa, ya) <= (xb, yb) lexicographically.
  CoverageEdge e{xa, ya, xb, yb, 0.0};
  if (xb > xa) e.slope = (yb - ya) / (xb - xa);
  return e;
}

}  // namespace

CoverageTriangle make_coverage_triangle(const TriangleSetup& t) {
  // Sort the vertices by x, then y, with a three-comparator network on one int64 key per
  // vertex: x in the high half, y with its sign bit flipped (order-preserving as unsigned)
  // in the low half, so the key order is the lexicographic (x, y) order. Vertices with
  // equal keys are equal, so the order among them does not matter.
  auto key = [&](int i) {
    return std::int64_t(std::uint64_t(std::uint32_t(t.x_fx8[i])) << 32 |
                        (std::uint32_t(t.y_fx8[i]) ^ 0x80000000u));
  };
  std::int64_t k0 = key(0), k1 = key(1), k2 = key(2);
  // Compare-exchange by masked xor: g++ turns a std::min/std::max pair into a branch, which
  // mispredicts on the random vertex order of a mesh.
  auto sort2 = [](std::int64_t& lo, std::int64_t& hi) {
    const std::int64_t flip = (lo ^ hi) & -std::int64_t(hi < lo);
    lo ^= flip;
    hi ^= flip;
  };
  sort2(k0, k1);
  sort2(k1, k2);
  sort2(k0, k1);
  auto x_of = [](std::int64_t k) { return std::int64_t(std::int32_t(k >> 32)); };
  auto y_of = [](std::int64_t k) {
    return std::int64_t(std::int32_t(std::uint32_t(k) ^ 0x80000000u));
  };
  const std::int64_t xa = x_of(k0), ya = y_of(k0);
  const std::int64_t xb = x_of(k1), yb = y_of(k1);
  const std::int64_t xc = x_of(k2), yc = y_of(k2);
  const double s = 1.0 / kSubpixelOne;
  CoverageTriangle tri;
  tri.edge[0] = make_edge(xa * s, ya * s, xc * s, yc * s);
  tri.edge[1] = make_edge(xa * s, ya * s, xb * s, yb * s);
  tri.edge[2] = make_edge(xb * s, yb * s, xc * s, yc * s);
  // b below the line ac (larger y) <=> cross(c - a, b - a) > 0; exact in int64.
  std::int64_t cross = (xc - xa) * (yb - ya) - (yc - ya) * (xb - xa);
  tri.sign = cross > 0 ? -1 : +1;
  tri.x_min = xa * s;
  tri.x_max = xc * s;
  return tri;
}

ColumnRows setup_column(const CoverageTriangle& tri, int col, CoverageColumns& columns, int lane) {
  ColumnRows rows{INT_MAX, INT_MIN, INT_MIN, INT_MAX};
  const double cl = col, cr = col + 1.0;
  for (int e = 0; e < 3; ++e) {
    const CoverageEdge& edge = tri.edge[e];
    const double xl = std::max(cl, edge.x0), xr = std::min(cr, edge.x1);
    if (!(xl < xr)) {
      columns.t_left[e][lane] = 0.0f;
      columns.t_right[e][lane] = 0.0f;
      columns.width_q[e][lane] = 0.0f;
      columns.slope_q[e][lane] = 0.0f;
      columns.base_row[e][lane] = 0;
      continue;
    }
    // Exact endpoints where the piece ends at a vertex; the line equation elsewhere.
    const double yl = xl == edge.x0 ? edge.y0 : edge.y0 + (xl - edge.x0) * edge.slope;
    const double yr = xr == edge.x1 ? edge.y1 : edge.y0 + (xr - edge.x0) * edge.slope;
    const double ymin = std::min(yl, yr), ymax = std::max(yl, yr);
    const double base = std::floor(ymin);
    const float tl = float(yl - base), tr = float(yr - base);
    const float wq = float(kCoverageOne * (xr - xl));  // exact: xr - xl is a multiple of 1/256
    columns.t_left[e][lane] = tl;
    columns.t_right[e][lane] = tr;
    columns.width_q[e][lane] = wq;
    columns.slope_q[e][lane] = std::fabs(tr - tl) >= kFlatEdgeEps ? wq / (tr - tl) : 0.0f;
    columns.base_row[e][lane] = int(base);
    const int band_first = int(base), band_end = int(std::ceil(ymax));
    const bool top = (e == 0) == (tri.sign < 0);  // ac is top when sign < 0
    rows.first = std::min(rows.first, band_first);
    rows.end = std::max(rows.end, std::max(band_end, band_first + 1));
    if (top) {
      rows.interior_begin = std::max(rows.interior_begin, band_end);
    } else {
      rows.interior_end = std::min(rows.interior_end, band_first);
    }
  }
  if (rows.first > rows.end) rows = ColumnRows{0, 0, 0, 0};
  if (rows.interior_begin > rows.interior_end) rows.interior_end = rows.interior_begin;
  return rows;
}

}  // namespace covrast::detail
