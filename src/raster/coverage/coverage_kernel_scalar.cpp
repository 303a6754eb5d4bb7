// Raster stage, coverage mode: the scalar twins of the SIMD column set-up, kernel and fused
// group function (coverage_kernel.cpp), which are the references those must match bit for
// bit (coverage_kernel.hpp): setup_column on each lane, then the row formula term by term.
#include "raster/coverage/coverage_kernel.hpp"

#include <algorithm>
#include <climits>
#include <cmath>

namespace covrast::detail {

GroupRows setup_column_group_scalar(const CoverageTriangle& tri, int col, int lanes, int row_min,
                                    int row_max, CoverageColumns& columns) {
  int first = INT_MAX, end = INT_MIN, interior_begin = INT_MIN, interior_end = INT_MAX;
  for (int lane = 0; lane < kColumnGroup; ++lane) {
    if (lane >= lanes) {
      for (int e = 0; e < 3; ++e) {
        columns.t_left[e][lane] = columns.t_right[e][lane] = 0.0f;
        columns.width_q[e][lane] = columns.slope_q[e][lane] = 0.0f;
        columns.base_row[e][lane] = 0;
      }
      continue;
    }
    const ColumnRows rows = setup_column(tri, col + lane, columns, lane);
    if (rows.first >= rows.end) continue;
    first = std::min(first, rows.first);
    end = std::max(end, rows.end);
    interior_begin = std::max(interior_begin, rows.interior_begin);
    interior_end = std::min(interior_end, rows.interior_end);
  }
  return clip_group_rows(first, end, interior_begin, interior_end, row_min, row_max);
}

void coverage_rows_scalar(const CoverageColumns& columns, int col, int row_begin, int row_end,
                          int sign, std::uint16_t* out, std::size_t stride) {
  for (int r = row_begin; r < row_end; ++r, out += stride) {
    for (int c = col; c < col + kColumnGroup; ++c) {
      std::int32_t q[3];
      for (int e = 0; e < 3; ++e) {
        const float k = float(r - columns.base_row[e][c]);
        const float a = columns.t_left[e][c] - k;
        const float b = columns.t_right[e][c] - k;
        const float lo = std::min(a, b), hi = std::max(a, b);
        const bool simple =
            hi <= 0.0f || lo >= 1.0f || (lo >= 0.0f && hi <= 1.0f) || (hi - lo) < kFlatEdgeEps;
        const float mid = std::min(std::max((a + b) * 0.5f, 0.0f), 1.0f);
        const float ca = std::min(std::max(a, 0.0f), 1.0f);
        const float cb = std::min(std::max(b, 0.0f), 1.0f);
        const float ha = ca * ca * 0.5f + std::max(a - 1.0f, 0.0f);
        const float hb = cb * cb * 0.5f + std::max(b - 1.0f, 0.0f);
        const float area = simple ? columns.width_q[e][c] * mid : (hb - ha) * columns.slope_q[e][c];
        q[e] = std::int32_t(std::nearbyint(area));
      }
      std::int32_t cov = sign * (q[0] - q[1] - q[2]);
      out[c - col] = std::uint16_t(std::clamp(cov, 0, kCoverageOne));
    }
  }
}

GroupRows cover_group_scalar(const CoverageTriangle& tri, int col, int lanes, int row_min,
                             int row_max, std::uint16_t* out, std::size_t stride) {
  CoverageColumns columns;  // only lanes [0, kColumnGroup) are written and read
  const GroupRows rows = setup_column_group_scalar(tri, col, lanes, row_min, row_max, columns);
  if (rows.empty()) return rows;
  auto row_out = [&](int y) { return out + std::size_t(y - row_min) * stride; };
  coverage_rows_scalar(columns, 0, rows.first, rows.interior_begin, tri.sign, row_out(rows.first),
                       stride);
  for (int y = rows.interior_begin; y < rows.interior_end; ++y) {
    for (int lane = 0; lane < kColumnGroup; ++lane) {
      row_out(y)[lane] = std::uint16_t(columns.width_q[0][lane]);
    }
  }
  coverage_rows_scalar(columns, 0, rows.interior_end, rows.end, tri.sign,
                       row_out(rows.interior_end), stride);
  return rows;
}

}  // namespace covrast::detail
