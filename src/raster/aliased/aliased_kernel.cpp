// Raster stage, aliased mode: the SIMD depth-test kernel (aliased_kernel.hpp), one source
// compiled for every Highway target; the best is picked at run time. It evaluates the int64
// edge functions and the double depth plane exactly as the scalar twin does, lane by lane,
// then rounds depth to float: every target gives the same bits.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/aliased/aliased_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "raster/aliased/aliased_kernel.hpp"

HWY_BEFORE_NAMESPACE();
namespace covrast::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// The SIMD kernel: column groups of N lanes (N = lanes of int64), and in each group the
/// rows top to bottom. Lanes past the rectangle's right end are never inside; their
/// depth and owner are read and written back unchanged (the tile buffers are padded).
void RasterAliased(const TriangleSetup& t, const PixelRect& r, const AliasedTile& tile,
                   std::uint64_t id_value) {
  // Built here, in registers: read through a pointer, the stores through depth and owner
  // could alias the job and force its fields to be reloaded on every row.
  const AliasedJob job = make_aliased_job(t, r, tile, id_value);
  const hn::ScalableTag<std::int64_t> di;
  const hn::RebindToUnsigned<decltype(di)> du;
  const hn::RebindToFloat<decltype(di)> df;
  const hn::Rebind<float, decltype(df)> df32;
  const std::size_t n = hn::Lanes(di);
  // Lane offsets k * step_x of each edge, k = 0 .. N-1, from the bits of k (there is no
  // 64-bit multiply on every target; building them in memory stalls on store forwarding).
  const auto lane = hn::Iota(di, 0);
  auto off0 = hn::Zero(di), off1 = hn::Zero(di), off2 = hn::Zero(di);
  for (std::int64_t bit = 1; bit < std::int64_t(n); bit *= 2) {
    const auto has = hn::TestBit(lane, hn::Set(di, bit));
    off0 = hn::Add(off0, hn::IfThenElseZero(has, hn::Set(di, job.step_x[0] * bit)));
    off1 = hn::Add(off1, hn::IfThenElseZero(has, hn::Set(di, job.step_x[1] * bit)));
    off2 = hn::Add(off2, hn::IfThenElseZero(has, hn::Set(di, job.step_x[2] * bit)));
  }
  const auto sy0 = hn::Set(di, job.step_y[0]);
  const auto sy1 = hn::Set(di, job.step_y[1]);
  const auto sy2 = hn::Set(di, job.step_y[2]);
  const auto zero = hn::Zero(di);
  const auto id = hn::Set(du, job.id);
  const auto iota = hn::Iota(df, 0.0);
  for (int gx = 0; gx < job.width; gx += int(n)) {
    const auto valid = hn::FirstN(di, std::size_t(job.width - gx));
    auto v0 = hn::Add(hn::Set(di, job.e[0] + gx * job.step_x[0]), off0);
    auto v1 = hn::Add(hn::Set(di, job.e[1] + gx * job.step_x[1]), off1);
    auto v2 = hn::Add(hn::Set(di, job.e[2] + gx * job.step_x[2]), off2);
    // z0 + dzdx (px - vx) with px = x + 0.5 per lane (small integers and halves: exact).
    const auto px = hn::Add(hn::Add(hn::Set(df, double(job.x0 + gx)), iota), hn::Set(df, 0.5));
    const auto zx = hn::Add(hn::Set(df, job.z0),
                            hn::Mul(hn::Set(df, job.dzdx), hn::Sub(px, hn::Set(df, job.vx))));
    double* depth = job.depth + gx;
    std::uint64_t* owner = job.owner + gx;
    // Every row of the rectangle, empty or not: a test-and-branch per row mispredicts
    // more than the masked work costs.
    for (int j = 0; j < job.height; ++j, depth += job.stride, owner += job.stride) {
      // Outside some edge <=> a sign bit in the OR of the three.
      const auto outside = hn::Lt(hn::Or(hn::Or(v0, v1), v2), zero);
      const double zy = job.dzdy * ((job.y0 + j + 0.5) - job.vy);
      // Rounded to float as the scalar float(z); in range wherever it is used (inside the
      // triangle z lies between its vertices' depths), where every target's DemoteTo is
      // the IEEE conversion.
      const auto z = hn::PromoteTo(df, hn::DemoteTo(df32, hn::Add(zx, hn::Set(df, zy))));
      const auto old = hn::LoadU(df, depth);
      const auto pass = hn::RebindMask(
          df, hn::AndNot(outside, hn::And(valid, hn::RebindMask(di, hn::Lt(z, old)))));
      hn::StoreU(hn::IfThenElse(pass, z, old), df, depth);
      hn::StoreU(hn::IfThenElse(hn::RebindMask(du, pass), id, hn::LoadU(du, owner)), du, owner);
      v0 = hn::Add(v0, sy0);
      v1 = hn::Add(v1, sy1);
      v2 = hn::Add(v2, sy2);
    }
  }
}

}  // namespace covrast::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace covrast::detail {

HWY_EXPORT(RasterAliased);

RasterAliasedFn raster_aliased_simd() {
  // HWY_DYNAMIC_DISPATCH's first table entry is an initialising trampoline, so make the
  // choice first.
  hwy::ChosenTarget& chosen = hwy::GetChosenTarget();
  if (!chosen.IsInitialized()) chosen.Update(hwy::SupportedTargets());
  return HWY_DISPATCH_TABLE(RasterAliased)[chosen.GetIndex()];
}

}  // namespace covrast::detail
#endif  // HWY_ONCE
