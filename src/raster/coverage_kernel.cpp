// Raster stage, coverage mode: the SIMD kernel and column set-up, one source compiled for
// every Highway target and picked at run time. They mirror coverage_rows_scalar and
// setup_column_group_scalar (coverage_setup.cpp) operation for operation (no FMA, round
// to nearest even, true division), so every target gives the same bits;
// tests/test_coverage_kernel.cpp checks that on every target this CPU has.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/coverage_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "raster/coverage_kernel.hpp"

#include <climits>

HWY_BEFORE_NAMESPACE();
namespace covrast::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

void CoverageRows(const CoverageColumns& columns, int col, int row_begin, int row_end, int sign,
                  std::uint16_t* out, std::size_t stride) {
  // At most one group of columns per vector: wider targets use a narrower vector.
  const hn::CappedTag<float, kColumnGroup> df;
  const hn::RebindToSigned<decltype(df)> di;
  const hn::Rebind<std::uint16_t, decltype(df)> du16;
  const std::size_t lanes = hn::Lanes(df);
  const auto zero = hn::Zero(df);
  const auto one = hn::Set(df, 1.0f);
  const auto half = hn::Set(df, 0.5f);
  const auto eps = hn::Set(df, kFlatEdgeEps);
  const auto izero = hn::Zero(di);
  const auto ifull = hn::Set(di, kCoverageOne);
  for (int r = row_begin; r < row_end; ++r, out += stride) {
    const auto row = hn::Set(di, r);
    for (std::size_t j = 0; j < std::size_t(kColumnGroup); j += lanes) {
      const std::size_t c = std::size_t(col) + j;
      hn::Vec<decltype(di)> q[3];
      for (int e = 0; e < 3; ++e) {
        // k = r - base_row; a, b = the edge's y at the piece ends relative to row r.
        const auto k = hn::ConvertTo(df, hn::Sub(row, hn::LoadU(di, &columns.base_row[e][c])));
        const auto a = hn::Sub(hn::LoadU(df, &columns.t_left[e][c]), k);
        const auto b = hn::Sub(hn::LoadU(df, &columns.t_right[e][c]), k);
        const auto lo = hn::Min(a, b);
        const auto hi = hn::Max(a, b);
        const auto simple = hn::Or(
            hn::Or(hn::Le(hi, zero), hn::Ge(lo, one)),
            hn::Or(hn::And(hn::Ge(lo, zero), hn::Le(hi, one)), hn::Lt(hn::Sub(hi, lo), eps)));
        const auto mid = hn::Min(hn::Max(hn::Mul(hn::Add(a, b), half), zero), one);
        const auto ca = hn::Min(hn::Max(a, zero), one);
        const auto cb = hn::Min(hn::Max(b, zero), one);
        // H(t) = clamp(t, 0, 1)^2 / 2 + max(t - 1, 0)
        const auto ha = hn::Add(hn::Mul(hn::Mul(ca, ca), half), hn::Max(hn::Sub(a, one), zero));
        const auto hb = hn::Add(hn::Mul(hn::Mul(cb, cb), half), hn::Max(hn::Sub(b, one), zero));
        const auto area =
            hn::IfThenElse(simple, hn::Mul(hn::LoadU(df, &columns.width_q[e][c]), mid),
                           hn::Mul(hn::Sub(hb, ha), hn::LoadU(df, &columns.slope_q[e][c])));
        q[e] = hn::NearestInt(area);
      }
      auto cov = hn::Sub(hn::Sub(q[0], q[1]), q[2]);
      if (sign < 0) cov = hn::Neg(cov);
      cov = hn::Min(hn::Max(cov, izero), ifull);
      hn::StoreU(hn::DemoteTo(du16, cov), du16, out + j);
    }
  }
}

GroupRows SetupColumnGroup(const CoverageTriangle& tri, int col, int lanes, int row_min,
                           int row_max, CoverageColumns& columns) {
  // setup_column (coverage_setup.cpp) on all lanes of the group at once: the same double
  // operations in the same order (separate Mul/Add, no FMA; the float division is a true
  // division), then the row bookkeeping as lane-wise min/max. Lanes whose piece of an edge
  // is empty (xl >= xr, or a lane past `lanes`) get exact zeros and contribute the
  // identities INT_MAX / INT_MIN, exactly as the scalar loop skips them. Row numbers stay in
  // double until the end: they are integers far inside int32, so min/max are exact.
  const hn::CappedTag<double, kColumnGroup> dd;
  const hn::Rebind<float, decltype(dd)> df;
  const hn::Rebind<std::int32_t, decltype(dd)> di;
  const std::size_t n = hn::Lanes(dd);
  const auto zero = hn::Zero(dd);
  const auto one = hn::Set(dd, 1.0);
  const auto qone = hn::Set(dd, double(kCoverageOne));
  const auto int_max = hn::Set(dd, double(INT_MAX));
  const auto int_min = hn::Set(dd, double(INT_MIN));
  const auto eps = hn::Set(df, kFlatEdgeEps);
  const auto col_end = hn::Set(dd, double(col + lanes));
  // ac is the top edge when sign < 0, else ab and bc are.
  const auto ac_top = hn::Lt(hn::Set(dd, double(tri.sign)), zero);
  auto g_first = int_max, g_end = int_min, g_interior_begin = int_min, g_interior_end = int_max;
  for (std::size_t j = 0; j < std::size_t(kColumnGroup); j += n) {
    const auto cl = hn::Iota(dd, double(col) + double(j));  // exact: small integers
    const auto cr = hn::Add(cl, one);
    const auto inside = hn::Lt(cl, col_end);
    // Per edge: the row band's first row (floor of the upper end), one past its last row
    // (ceil of the lower end), both INT_MAX / INT_MIN where the piece is empty.
    hn::Vec<decltype(dd)> band_first[3], band_end[3], column_end = int_min;
    auto column_first = int_max;
    for (int e = 0; e < 3; ++e) {
      const CoverageEdge& edge = tri.edge[e];
      const auto x0 = hn::Set(dd, edge.x0), x1 = hn::Set(dd, edge.x1);
      const auto y0 = hn::Set(dd, edge.y0), slope = hn::Set(dd, edge.slope);
      const auto xl = hn::Max(cl, x0), xr = hn::Min(cr, x1);
      const auto valid = hn::And(hn::Lt(xl, xr), inside);
      const auto yl =
          hn::IfThenElse(hn::Eq(xl, x0), y0, hn::Add(y0, hn::Mul(hn::Sub(xl, x0), slope)));
      const auto yr = hn::IfThenElse(hn::Eq(xr, x1), hn::Set(dd, edge.y1),
                                     hn::Add(y0, hn::Mul(hn::Sub(xr, x0), slope)));
      const auto base = hn::Floor(hn::Min(yl, yr));
      const auto ceil_max = hn::Ceil(hn::Max(yl, yr));
      const auto tl = hn::DemoteTo(df, hn::IfThenElseZero(valid, hn::Sub(yl, base)));
      const auto tr = hn::DemoteTo(df, hn::IfThenElseZero(valid, hn::Sub(yr, base)));
      const auto wq = hn::DemoteTo(df, hn::IfThenElseZero(valid, hn::Mul(qone, hn::Sub(xr, xl))));
      const auto dt = hn::Sub(tr, tl);
      const auto slope_q = hn::IfThenElseZero(hn::Ge(hn::Abs(dt), eps), hn::Div(wq, dt));
      hn::StoreU(tl, df, &columns.t_left[e][j]);
      hn::StoreU(tr, df, &columns.t_right[e][j]);
      hn::StoreU(wq, df, &columns.width_q[e][j]);
      hn::StoreU(slope_q, df, &columns.slope_q[e][j]);
      hn::StoreU(hn::DemoteTo(di, hn::IfThenElseZero(valid, base)), di, &columns.base_row[e][j]);
      band_first[e] = hn::IfThenElse(valid, base, int_max);
      band_end[e] = hn::IfThenElse(valid, ceil_max, int_min);
      column_first = hn::Min(column_first, band_first[e]);
      // The band covers at least one row: max(band_end, band_first + 1).
      column_end = hn::Max(column_end,
                           hn::IfThenElse(valid, hn::Max(ceil_max, hn::Add(base, one)), int_min));
    }
    // Interior: below every top edge's band, above every bottom edge's band.
    const auto short_top = hn::Max(band_end[1], band_end[2]);
    const auto short_bottom = hn::Min(band_first[1], band_first[2]);
    const auto interior_begin = hn::IfThenElse(ac_top, band_end[0], short_top);
    const auto interior_end =
        hn::Max(interior_begin, hn::IfThenElse(ac_top, short_bottom, band_first[0]));
    // Columns no edge touches hold the identities of min/max here, as the scalar loop skips
    // them: first = INT_MAX, end = INT_MIN, interior_begin = INT_MIN, interior_end = INT_MAX.
    g_first = hn::Min(g_first, column_first);
    g_end = hn::Max(g_end, column_end);
    g_interior_begin = hn::Max(g_interior_begin, interior_begin);
    g_interior_end = hn::Min(g_interior_end, interior_end);
  }
  return clip_group_rows(int(hn::GetLane(hn::MinOfLanes(dd, g_first))),
                         int(hn::GetLane(hn::MaxOfLanes(dd, g_end))),
                         int(hn::GetLane(hn::MaxOfLanes(dd, g_interior_begin))),
                         int(hn::GetLane(hn::MinOfLanes(dd, g_interior_end))), row_min, row_max);
}

}  // namespace covrast::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace covrast::detail {

HWY_EXPORT(CoverageRows);
HWY_EXPORT(SetupColumnGroup);

GroupRows setup_column_group(const CoverageTriangle& tri, int col, int lanes, int row_min,
                             int row_max, CoverageColumns& columns) {
  return HWY_DYNAMIC_DISPATCH(SetupColumnGroup)(tri, col, lanes, row_min, row_max, columns);
}

void coverage_rows_simd(const CoverageColumns& columns, int col, int row_begin, int row_end,
                        int sign, std::uint16_t* out, std::size_t stride) {
  HWY_DYNAMIC_DISPATCH(CoverageRows)(columns, col, row_begin, row_end, sign, out, stride);
}

std::int64_t coverage_kernel_targets() { return HWY_TARGETS; }

void force_coverage_kernel_target(std::int64_t target) {
  hwy::SetSupportedTargetsForTest(target);
  // Makes the next dispatch pick again among the (now mocked) supported targets.
  hwy::GetChosenTarget().Update(hwy::SupportedTargets());
}

const char* coverage_kernel_target_name() {
  // Lower bits are better targets; dispatch takes the best one compiled and supported.
  std::int64_t usable = HWY_TARGETS & hwy::SupportedTargets();
  return hwy::TargetName(usable & -usable);
}

}  // namespace covrast::detail
#endif
