// Coverage mode: the per-sample depth test (sample_depth.hpp), the SIMD version, one source
// compiled for every Highway target; its scalar twin is sample_depth_scalar.cpp.
//
// Lanes are samples: up to 8 doubles a vector (one 64-bit word of the mask holds 8 vectors on
// AVX-512, 16 on AVX2, 32 on 128-bit targets). Each lane computes z_s with the twin's
// operations in the twin's order (Mul, Add, Mul, Add: no contraction), so the comparison sees
// the same bits; lanes outside `owned` are masked out of the update. A vector whose mask bits
// are all clear is skipped, which is most of them for a small triangle.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/coverage/sample_depth.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "raster/coverage/sample_depth.hpp"

HWY_BEFORE_NAMESPACE();
namespace covrast::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Up to 8 double lanes: Lanes(d) divides 64, so a vector's mask bits lie in one word and fit
// one byte.
using DD = hn::CappedTag<double, 8>;
using DU = hn::RebindToUnsigned<DD>;

SampleMask DepthTestSamples(const PixelPlane& plane, const SampleMask& owned,
                            std::uint64_t primitive, double* best_z,
                            std::uint64_t* best_primitive) {
  const DD d;
  const DU du;
  const int n = int(hn::Lanes(d));
  const std::uint64_t lane_bits = (std::uint64_t(1) << n) - 1;
  const auto z0 = hn::Set(d, plane.z0);
  const auto dzdx = hn::Set(d, plane.dzdx);
  const auto dzdy = hn::Set(d, plane.dzdy);
  const auto id = hn::Set(du, primitive);
  SampleMask won = SampleMask::none();
  for (int s0 = 0; s0 < kMaskSamples; s0 += n) {
    const std::uint64_t bits = (owned.word[s0 >> 6] >> (s0 & 63)) & lane_bits;
    if (bits == 0) continue;
    const std::uint8_t bit_byte = std::uint8_t(bits);  // lane l is bit l (n <= 8)
    const auto in_mask = hn::LoadMaskBits(d, &bit_byte);
    const auto x = hn::LoadU(d, kSampleOffsetX.data() + s0);
    const auto y = hn::LoadU(d, kSampleOffsetY.data() + s0);
    const auto z = hn::Add(hn::Add(z0, hn::Mul(dzdx, x)), hn::Mul(dzdy, y));
    const auto best = hn::LoadU(d, best_z + s0);
    const auto best_id = hn::LoadU(du, best_primitive + s0);
    const auto earlier = hn::RebindMask(d, hn::Lt(id, best_id));
    const auto nearer = hn::Or(hn::Lt(z, best), hn::And(hn::Eq(z, best), earlier));
    const auto take = hn::And(nearer, in_mask);
    hn::StoreU(hn::IfThenElse(take, z, best), d, best_z + s0);
    hn::StoreU(hn::IfThenElse(hn::RebindMask(du, take), id, best_id), du, best_primitive + s0);
    std::uint8_t take_bytes[8] = {};  // StoreMaskBits may write up to 8 bytes; n <= 8 use one
    hn::StoreMaskBits(d, take, take_bytes);
    won.word[s0 >> 6] |= (std::uint64_t(take_bytes[0]) & lane_bits) << (s0 & 63);
  }
  return won;
}

}  // namespace covrast::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace covrast::detail {

HWY_EXPORT(DepthTestSamples);

SampleMask depth_test_samples_simd(const PixelPlane& plane, const SampleMask& owned,
                                   std::uint64_t primitive, double* best_z,
                                   std::uint64_t* best_primitive) {
  return HWY_DYNAMIC_DISPATCH(DepthTestSamples)(plane, owned, primitive, best_z, best_primitive);
}

SampleMask depth_test_samples(const PixelPlane& plane, const SampleMask& owned,
                              std::uint64_t primitive, double* best_z,
                              std::uint64_t* best_primitive) {
  // Both give the same bits; the vectors visit every sample of a non-empty vector, the twin
  // only the owned ones, so a sparse mask (a sub-pixel triangle) is cheaper sample by sample.
  if (owned.count() < kSparseMaskSamples) {
    return depth_test_samples_scalar(plane, owned, primitive, best_z, best_primitive);
  }
  return depth_test_samples_simd(plane, owned, primitive, best_z, best_primitive);
}

}  // namespace covrast::detail
#endif
