// Raster stage, sample-based modes: the SIMD kernels (sample_kernel.hpp), one source
// compiled for every Highway target and picked at run time. Every operation is exact
// integer arithmetic or a single IEEE float add / multiply / compare in the same order as
// the scalar twins (sample_kernel_scalar.cpp), so every target gives the same bits;
// tests/test_supersampling.cpp checks that on every target this CPU has.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/samples/sample_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "raster/samples/sample_kernel.hpp"

#include <limits>

HWY_BEFORE_NAMESPACE();
namespace covrast::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// At most 16 lanes of 32 bits: a group's lane count is a multiple of 16.
using DF = hn::CappedTag<float, kGroupLaneBlock>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;

// Inlined into RasterTriangle (the walk calls it once per triangle); SetupGroup is its
// exported form for the dispatch table.
HWY_INLINE void SetupGroupImpl(const GroupPattern& pattern, const std::int32_t dx[3],
                               const std::int32_t dy[3], bool with_edges, float dzdx, float dzdy,
                               GroupTriangle& tri) {
  const DF df;
  const DI di;
  const std::size_t n = hn::Lanes(df);
  const std::size_t lanes = std::size_t(pattern.lanes);
  const auto vdzdx = hn::Set(df, dzdx);
  const auto vdzdy = hn::Set(df, dzdy);
  for (std::size_t i = 0; i < lanes; i += n) {
    const auto a = hn::Mul(vdzdx, hn::Load(df, pattern.ox_px + i));
    const auto b = hn::Mul(vdzdy, hn::Load(df, pattern.oy_px + i));
    hn::Store(hn::Add(a, b), df, tri.dz + i);
  }
  if (!with_edges) return;
  const auto padding = hn::Set(di, kPaddingOffset);
  for (int e = 0; e < 3; ++e) {
    const auto vdx = hn::Set(di, dx[e]);
    const auto vdy = hn::Set(di, dy[e]);
    for (std::size_t i = 0; i < lanes; i += n) {
      auto c = hn::Sub(hn::Mul(vdx, hn::Load(di, pattern.oy_fx8 + i)),
                       hn::Mul(vdy, hn::Load(di, pattern.ox_fx8 + i)));
      if (e == 0) c = hn::IfThenElse(hn::MaskFromVec(hn::Load(di, pattern.valid + i)), c, padding);
      hn::Store(c, di, tri.c[e] + i);
    }
  }
}

void SetupGroup(const GroupPattern& pattern, const std::int32_t dx[3], const std::int32_t dy[3],
                bool with_edges, float dzdx, float dzdy, GroupTriangle& tri) {
  SetupGroupImpl(pattern, dx, dy, with_edges, dzdx, dzdy, tri);
}

template <bool kTestEdges>
HWY_INLINE bool SampleGroupImpl(const GroupPattern& pattern, const GroupTriangle& tri,
                                const std::int32_t* f, float z_base, const std::uint32_t* rgb,
                                const GroupSamples& out, std::uint64_t* written) {
  const DF df;
  const DI di;
  const DU du;
  const std::size_t n = hn::Lanes(df);
  const std::size_t lanes = std::size_t(pattern.lanes);
  const auto zb = hn::Set(df, z_base);
  const auto minus_one = hn::Set(di, -1);
  hn::Vec<DI> f0, f1, f2;
  if constexpr (kTestEdges) {
    f0 = hn::Set(di, f[0]);
    f1 = hn::Set(di, f[1]);
    f2 = hn::Set(di, f[2]);
  }
  bool any = false;
  for (std::size_t i = 0; i < lanes; i += n) {
    hn::Mask<DI> inside;
    if constexpr (kTestEdges) {
      // Inside all three edges <=> no sign bit in any of the sums.
      const auto s0 = hn::Add(f0, hn::Load(di, tri.c[0] + i));
      const auto s1 = hn::Add(f1, hn::Load(di, tri.c[1] + i));
      const auto s2 = hn::Add(f2, hn::Load(di, tri.c[2] + i));
      inside = hn::Gt(hn::Or(hn::Or(s0, s1), s2), minus_one);
    } else {
      inside = hn::MaskFromVec(hn::Load(di, pattern.valid + i));
    }
    const auto z = hn::Add(zb, hn::Load(df, tri.dz + i));
    const auto d = hn::LoadU(df, out.depth + i);
    const auto m = hn::And(hn::RebindMask(df, inside), hn::Lt(z, d));
    if (hn::AllFalse(df, m)) continue;
    any = true;
    hn::StoreU(hn::IfThenElse(m, z, d), df, out.depth + i);
    if (rgb != nullptr) {
      const auto mu = hn::RebindMask(du, m);
#if HWY_TARGET <= HWY_AVX3
      hn::BlendedStore(hn::Set(du, rgb[0]), mu, du, out.r + i);
      hn::BlendedStore(hn::Set(du, rgb[1]), mu, du, out.g + i);
      hn::BlendedStore(hn::Set(du, rgb[2]), mu, du, out.b + i);
#else
      hn::StoreU(hn::IfThenElse(mu, hn::Set(du, rgb[0]), hn::LoadU(du, out.r + i)), du, out.r + i);
      hn::StoreU(hn::IfThenElse(mu, hn::Set(du, rgb[1]), hn::LoadU(du, out.g + i)), du, out.g + i);
      hn::StoreU(hn::IfThenElse(mu, hn::Set(du, rgb[2]), hn::LoadU(du, out.b + i)), du, out.b + i);
#endif
    }
    if (written != nullptr) {
      // n <= 16 and i is a multiple of n, so the n bits stay inside one 64-bit word.
      std::uint8_t bits[8] = {};
      hn::StoreMaskBits(df, m, bits);
      const std::uint64_t v = std::uint64_t(bits[0]) | std::uint64_t(bits[1]) << 8;
      written[i / 64] |= v << (i % 64);
    }
  }
  return any;
}

bool SampleGroup(const GroupPattern& pattern, const GroupTriangle& tri, const std::int32_t* f,
                 float z_base, const std::uint32_t* rgb, const GroupSamples& out,
                 std::uint64_t* written) {
  if (f != nullptr) return SampleGroupImpl<true>(pattern, tri, f, z_base, rgb, out, written);
  return SampleGroupImpl<false>(pattern, tri, f, z_base, rgb, out, written);
}

#include "raster/samples/sample_walk-inl.hpp"  // walk_triangle_groups, for this target

void RasterTriangle(const GroupPattern& pattern, const RasterJob& job, GroupTriangle& tri) {
  walk_triangle_groups(
      pattern, job,
      [&] { SetupGroupImpl(pattern, job.dx, job.dy, true, job.dzdx_f, job.dzdy_f, tri); },
      [&](const std::int32_t* f32, float z_base, const GroupSamples& out, std::uint64_t* written) {
        return f32 == nullptr
                   ? SampleGroupImpl<false>(pattern, tri, nullptr, z_base, job.rgb, out, written)
                   : SampleGroupImpl<true>(pattern, tri, f32, z_base, job.rgb, out, written);
      });
}

void ResolvePixels(const GroupPattern& pattern, int pixels, const GroupSamples& in,
                   const std::uint32_t background[3], std::uint32_t* sums, float* min_depth) {
  const int s_count = pattern.samples;
  const std::size_t stride = std::size_t(pattern.stride);
  const float inf = std::numeric_limits<float>::infinity();
  if (stride < std::size_t(kGroupLaneBlock)) {
    // 1, 2, 4 or 8 samples per pixel: short sums, left to the compiler.
    for (int p = 0; p < pixels; ++p) {
      const std::size_t base = std::size_t(p) * stride;
      std::uint32_t r = 0, g = 0, b = 0;
      float z = inf;
      for (int s = 0; s < s_count; ++s) {
        const float d = in.depth[base + s];
        const bool empty = !(d < inf);
        r += empty ? background[0] : in.r[base + s];
        g += empty ? background[1] : in.g[base + s];
        b += empty ? background[2] : in.b[base + s];
        z = d < z ? d : z;
      }
      sums[3 * p] = r;
      sums[3 * p + 1] = g;
      sums[3 * p + 2] = b;
      if (min_depth != nullptr) min_depth[p] = z;
    }
    return;
  }
  const DF df;
  const DU du;
  const std::size_t n = hn::Lanes(du);
  const auto vinf = hn::Set(df, inf);
  const auto bg_r = hn::Set(du, background[0]);
  const auto bg_g = hn::Set(du, background[1]);
  const auto bg_b = hn::Set(du, background[2]);
  for (int p = 0; p < pixels; ++p) {
    const std::size_t base = std::size_t(p) * stride;
    auto r = hn::Zero(du), g = hn::Zero(du), b = hn::Zero(du);
    auto z = vinf;
    std::size_t i = 0;
    for (; i + n <= std::size_t(s_count); i += n) {
      const auto d = hn::LoadU(df, in.depth + base + i);
      const auto written = hn::RebindMask(du, hn::Lt(d, vinf));
      r = hn::Add(r, hn::IfThenElse(written, hn::LoadU(du, in.r + base + i), bg_r));
      g = hn::Add(g, hn::IfThenElse(written, hn::LoadU(du, in.g + base + i), bg_g));
      b = hn::Add(b, hn::IfThenElse(written, hn::LoadU(du, in.b + base + i), bg_b));
      z = hn::Min(z, d);
    }
    if (i < std::size_t(s_count)) {
      // The last chunk of a padded pixel: only its first S - i lanes are samples.
      const auto real = hn::FirstN(du, std::size_t(s_count) - i);
      const auto d = hn::LoadU(df, in.depth + base + i);
      const auto written = hn::RebindMask(du, hn::Lt(d, vinf));
      r = hn::Add(r, hn::IfThenElseZero(
                         real, hn::IfThenElse(written, hn::LoadU(du, in.r + base + i), bg_r)));
      g = hn::Add(g, hn::IfThenElseZero(
                         real, hn::IfThenElse(written, hn::LoadU(du, in.g + base + i), bg_g)));
      b = hn::Add(b, hn::IfThenElseZero(
                         real, hn::IfThenElse(written, hn::LoadU(du, in.b + base + i), bg_b)));
      z = hn::Min(z, hn::IfThenElse(hn::RebindMask(df, real), d, vinf));
    }
    sums[3 * p] = hn::GetLane(hn::SumOfLanes(du, r));
    sums[3 * p + 1] = hn::GetLane(hn::SumOfLanes(du, g));
    sums[3 * p + 2] = hn::GetLane(hn::SumOfLanes(du, b));
    if (min_depth != nullptr) min_depth[p] = hn::GetLane(hn::MinOfLanes(df, z));
  }
}

void ClearDepth(float* depth, std::size_t count) {
  const DF df;
  const std::size_t n = hn::Lanes(df);
  const auto vinf = hn::Set(df, std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < count; i += n) hn::Store(vinf, df, depth + i);
}

}  // namespace covrast::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace covrast::detail {

HWY_EXPORT(SetupGroup);
HWY_EXPORT(SampleGroup);
HWY_EXPORT(RasterTriangle);
HWY_EXPORT(ResolvePixels);
HWY_EXPORT(ClearDepth);

SampleKernels sample_kernels_simd() {
  // The function pointers of the chosen target, looked up once here (a rasterizer keeps
  // them) rather than on every group. HWY_DYNAMIC_DISPATCH's first table entry is an
  // initialising trampoline, so make the choice first.
  hwy::ChosenTarget& chosen = hwy::GetChosenTarget();
  if (!chosen.IsInitialized()) chosen.Update(hwy::SupportedTargets());
  const std::size_t index = chosen.GetIndex();
  return SampleKernels{
      HWY_DISPATCH_TABLE(SetupGroup)[index], HWY_DISPATCH_TABLE(SampleGroup)[index],
      HWY_DISPATCH_TABLE(RasterTriangle)[index], HWY_DISPATCH_TABLE(ResolvePixels)[index],
      HWY_DISPATCH_TABLE(ClearDepth)[index]};
}

}  // namespace covrast::detail
#endif
