// Raster stage, coverage mode: the SIMD kernel, one source compiled for every Highway
// target and picked at run time. It mirrors coverage_rows_scalar (coverage_setup.cpp)
// operation for operation (no FMA, round to nearest even), so every target gives the
// same bits; tests/test_coverage_kernel.cpp checks that on every target this CPU has.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/coverage_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "raster/coverage_kernel.hpp"

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

}  // namespace covrast::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace covrast::detail {

HWY_EXPORT(CoverageRows);

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
