// Raster stage, coverage mode: the exact per-column area kernel
// (../shared/design/coverage-math.md, docs/coverage.md).
//
// A triangle's vertices sorted by x are a, b, c. In each pixel column its cross-section
// lies between the long edge ac and the two short edges ab (left of b) and bc (right of b).
// For an edge over the part [xl, xr] of column col that it spans, the area of pixel row r
// lying above the edge (smaller y) is
//
//   A_e(r) = (xr - xl) * (H(yr - r) - H(yl - r)) / (yr - yl),
//   H(t)   = clamp(t, 0, 1)^2 / 2 + max(t - 1, 0)
//
// (or (xr - xl) * clamp(mid - r, 0, 1) when both ends are in one regime of H or yr ~ yl),
// and the coverage of pixel (col, r) is the bottom edges' A minus the top edges' A:
//
//   coverage = sign * (A_ac - A_ab - A_bc),  sign = +1 when b lies above ac, else -1.
//
// Each edge term is quantised on its own to 1/65280 of a pixel, from the edge's canonical
// endpoints (left to right), so two triangles sharing an edge subtract exactly the same
// integer: coverages of a tessellation add up to exactly one pixel. Coverage is kept as
// 8.8 fixed point in units of 1/255 (65280 = 255 * 256 = a full pixel); its high byte,
// rounded, is the 8-bit alpha round(255 * area).
#pragma once

#include "core/triangle_setup.hpp"

#include <algorithm>
#include <cstdint>

namespace covrast::detail {

/// A full pixel in the kernel's fixed point: 255 * 256.
inline constexpr std::int32_t kCoverageOne = 65280;
/// 8-bit alpha of an 8.8 coverage value: round(coverage / 256).
inline std::uint8_t coverage_to_alpha8(std::uint32_t coverage) {
  return std::uint8_t((coverage + 128) >> 8);
}

/// Columns the kernel processes per call; every SIMD target splits them into its own
/// vectors, so the result does not depend on the vector width.
inline constexpr int kColumnGroup = 8;
/// Most columns one triangle can span inside a tile, plus a partial group.
inline constexpr int kMaxSpanColumns = 256 + kColumnGroup;

/// Below this |yr - yl| [pixels] the difference quotient of H is replaced by the mid-point
/// value (H is C1, the error is below |yr - yl| / 8 of the piece width).
inline constexpr float kFlatEdgeEps = 1.0f / 1024.0f;

/// Per-column inputs of the three edges, structure of arrays over columns. Index 0 = ac,
/// 1 = ab, 2 = bc. Lanes of columns a triangle does not span have width 0 (term = 0).
struct CoverageColumns {
  alignas(64) float t_left[3][kMaxSpanColumns];           ///< yl - base_row [pixels]
  alignas(64) float t_right[3][kMaxSpanColumns];          ///< yr - base_row [pixels]
  alignas(64) float width_q[3][kMaxSpanColumns];          ///< 65280 * (xr - xl), integer-valued
  alignas(64) float slope_q[3][kMaxSpanColumns];          ///< width_q / (yr - yl), 0 when flat
  alignas(64) std::int32_t base_row[3][kMaxSpanColumns];  ///< floor(min(yl, yr))
};

/// Computes coverage for columns [col, col + kColumnGroup) of `columns` and rows
/// [row_begin, row_end), writing 8.8 values to out[(r - row_begin) * stride + (c - col)].
/// `sign` is +1 or -1 as above.
using CoverageRowsFn = void (*)(const CoverageColumns& columns, int col, int row_begin, int row_end,
                                int sign, std::uint16_t* out, std::size_t stride);

/// The scalar twin and reference: the formula above term by term, one column at a time.
void coverage_rows_scalar(const CoverageColumns& columns, int col, int row_begin, int row_end,
                          int sign, std::uint16_t* out, std::size_t stride);

/// The SIMD kernel for the best target of this CPU (Highway dynamic dispatch), for tests
/// and benchmarks (the coverage mode runs the same row math inside cover_group_simd). It
/// gives the scalar twin's bits on inputs as the set-up makes them: slope_q the quotient
/// width_q / (t_right - t_left) (or 0), width_q >= 0, rows and base rows below 2^23.
void coverage_rows_simd(const CoverageColumns& columns, int col, int row_begin, int row_end,
                        int sign, std::uint16_t* out, std::size_t stride);

/// The three edges of a triangle in the kernel's canonical form.
struct CoverageEdge {
  double x0, y0, x1, y1;  ///< endpoints in pixels, x0 < x1 or (x0 == x1, y0 <= y1)
  double slope;           ///< (y1 - y0) / (x1 - x0), 0 when vertical
};

struct CoverageTriangle {
  CoverageEdge edge[3];  ///< ac, ab, bc
  int sign;              ///< +1: ac is the bottom edge; -1: ac is the top edge
  double x_min, x_max;   ///< [pixels]
};

CoverageTriangle make_coverage_triangle(const TriangleSetup& t);

/// Row extent of column `col` (absolute pixel x) and its interior run, in absolute rows.
struct ColumnRows {
  int first;           ///< first row touched
  int end;             ///< one past the last row touched
  int interior_begin;  ///< rows [interior_begin, interior_end) are fully covered
  int interior_end;
};

/// Fills lane `lane` of `columns` for absolute column `col` and returns its rows.
ColumnRows setup_column(const CoverageTriangle& tri, int col, CoverageColumns& columns, int lane);

/// Rows of one group of columns, clipped: the kernel runs on [first, interior_begin) and
/// [interior_end, end); the rows between are the interior run (the long edge's width_q).
struct GroupRows {
  int first;
  int end;
  int interior_begin;
  int interior_end;
  bool empty() const { return first >= end; }
};

/// Sets up columns [col, col + kColumnGroup) of `tri` in `columns` (lanes from `lanes` on
/// get zero width, so the kernel writes 0 there) and returns the group's rows clipped to
/// [row_min, row_max). The SIMD set-up for the best target of this CPU (Highway dynamic
/// dispatch, the lanes of the group in double precision), bit-identical to
/// setup_column_group_scalar; for tests and benchmarks (the coverage mode runs the same
/// set-up inside cover_group_simd).
GroupRows setup_column_group(const CoverageTriangle& tri, int col, int lanes, int row_min,
                             int row_max, CoverageColumns& columns);

/// The scalar twin and reference of setup_column_group: setup_column on each lane, the
/// same operations in the same order.
GroupRows setup_column_group_scalar(const CoverageTriangle& tri, int col, int lanes, int row_min,
                                    int row_max, CoverageColumns& columns);

/// The whole of one column group, the coverage mode's per-group step: the set-up of
/// columns [col, col + kColumnGroup) as setup_column_group, then its rows as draw needs
/// them: the kernel on the top partial run [first, interior_begin) and the bottom one
/// [interior_end, end), the long edge's width_q on the interior run. Row y of the group
/// goes to out[(y - row_min) * stride + (c - col)] for y in [first, end) of the returned
/// rows (nothing is written when they are empty).
using CoverGroupFn = GroupRows (*)(const CoverageTriangle& tri, int col, int lanes, int row_min,
                                   int row_max, std::uint16_t* out, std::size_t stride);

/// The scalar twin and reference: setup_column_group_scalar, then coverage_rows_scalar on
/// the partial runs and width_q[0] on the interior run.
GroupRows cover_group_scalar(const CoverageTriangle& tri, int col, int lanes, int row_min,
                             int row_max, std::uint16_t* out, std::size_t stride);

/// The fused SIMD version for the best target of this CPU (Highway dynamic dispatch): one
/// call per group, the set-up kept in registers for the rows; bit-identical to
/// cover_group_scalar.
GroupRows cover_group_simd(const CoverageTriangle& tri, int col, int lanes, int row_min,
                           int row_max, std::uint16_t* out, std::size_t stride);

/// The group's rows from the unclipped union over its columns (first = INT_MAX, end =
/// INT_MIN when no column is touched): clipped to [row_min, row_max), interior run inside.
inline GroupRows clip_group_rows(int first, int end, int interior_begin, int interior_end,
                                 int row_min, int row_max) {
  GroupRows g{std::max(first, row_min), std::min(end, row_max), 0, 0};
  if (g.empty()) return GroupRows{0, 0, 0, 0};
  g.interior_begin = std::clamp(interior_begin, g.first, g.end);
  g.interior_end = std::clamp(interior_end, g.interior_begin, g.end);
  return g;
}

}  // namespace covrast::detail
