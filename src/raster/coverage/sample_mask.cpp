// Coverage mode: the 256-sample sub-pixel mask (sample_mask.hpp), the SIMD version, one
// source compiled for every Highway target; its scalar twin is sample_mask_scalar.cpp.
//
// Why the SIMD version is exact. In units of 1/512 pixel (fx9) edge e at sample k of pixel
// (x, y) is, exactly in int64, twice the fx8 edge function:
//
//   E2(k) = C + dx * Y(k) - dy * X(k),   C = dx (512 y - 2 y0) - dy (512 x - 2 x0) + bias,
//
// with (X(k), Y(k)) the sample's offset [fx9] (odd, in [1, 511]), (dx, dy) the edge vector
// and (x0, y0) its first vertex [fx8]; inside <=> E2 >= 0 (the bias of the top-left rule is
// the same as for integer positions, as E2 is an integer and E2 = 0 exactly on the edge).
// T(k) = dx Y - dy X lies in [T_lo, T_hi], its extremes over the box [1, 511]^2.
// C + T_lo >= 0: the edge holds every sample (it is skipped); C + T_hi < 0: it holds none
// (mask 0). Otherwise the edge crosses the pixel and is tested per sample on int32 lanes:
// with |dx|, |dy| <= 2^20 (edges up to 4096 px) |T| <= 511 * 2^21 < 2^30, a crossing edge
// has -T_hi <= C < -T_lo, so |C| < 2^30 and every C + T fits in int32, as do the products.
// Longer edges take the scalar reference. tests/test_sample_mask.cpp checks the bits on every
// target.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/coverage/sample_mask.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "core/edge_function.hpp"
#include "raster/coverage/sample_mask.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>

#ifndef COVRAST_COVERAGE_SAMPLE_MASK_ONCE_
#define COVRAST_COVERAGE_SAMPLE_MASK_ONCE_
namespace covrast::detail {

/// Largest |dx|, |dy| [fx8] of an edge the int32 lanes take (see the top of the file).
inline constexpr std::int64_t kMaxLaneEdgeFx8 = std::int64_t(1) << 20;

/// The edges that cross the pixel's samples: C[e] + dx[e] Y(k) - dy[e] X(k) >= 0 inside.
struct CrossingEdges {
  std::int32_t c[3];
  std::int32_t dx[3];
  std::int32_t dy[3];
  int count;  ///< 1 to 3
  /// Samples [k_begin, k_end) can be inside: those within the triangle's x extent (the
  /// rest are 0 without a test, see pixel_sample_mask).
  int k_begin;
  int k_end;
};

}  // namespace covrast::detail
#endif

HWY_BEFORE_NAMESPACE();
namespace covrast::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Up to 16 int32 lanes: one row of samples per vector on AVX-512, half a row on AVX2, a
// quarter on 128-bit targets, one sample on the scalar one (Lanes(d) divides 16 always).
using DI = hn::CappedTag<std::int32_t, 16>;

/// Bits of the lanes that are set in `inside`, as the low Lanes(d) bits of an integer.
HWY_INLINE std::uint64_t LaneBits(DI d, hn::Mask<DI> inside) {
  std::uint8_t bytes[8] = {};  // StoreMaskBits may write up to 8 bytes
  hn::StoreMaskBits(d, inside, bytes);
  std::uint64_t bits;
  std::memcpy(&bits, bytes, sizeof(bits));
  return bits;
}

/// Mask of the samples inside all kEdges crossing edges, N = Lanes(d) samples a vector:
/// lane l of the vector at k0 is sample k0 + l, bit k0 + l; as N divides 64, a vector's
/// bits never straddle two words.
template <int kEdges>
HWY_INLINE SampleMask CrossingMask(const CrossingEdges& c) {
  const DI d;
  const int n = int(hn::Lanes(d));
  const auto minus_one = hn::Set(d, -1);
  hn::Vec<DI> base[kEdges], dx[kEdges], dy[kEdges];
  for (int e = 0; e < kEdges; ++e) {
    base[e] = hn::Set(d, c.c[e]);
    dx[e] = hn::Set(d, c.dx[e]);
    dy[e] = hn::Set(d, c.dy[e]);
  }
  SampleMask mask = SampleMask::none();
  // From the vector holding k_begin: lanes outside the range are tested like the others
  // (and are outside), so the bits are those of the whole loop.
  for (int k0 = c.k_begin - c.k_begin % n; k0 < c.k_end; k0 += n) {
    const auto sx = hn::LoadU(d, kMaskSampleX_fx9.data() + k0);
    const auto sy = hn::LoadU(d, kMaskSampleY_fx9.data() + k0);
    auto any = hn::Sub(hn::Add(base[0], hn::Mul(dx[0], sy)), hn::Mul(dy[0], sx));
    for (int e = 1; e < kEdges; ++e) {
      any = hn::Or(any, hn::Sub(hn::Add(base[e], hn::Mul(dx[e], sy)), hn::Mul(dy[e], sx)));
    }
    // Inside every edge <=> no sign bit in any of the values.
    mask.word[k0 >> 6] |= LaneBits(d, hn::Gt(any, minus_one)) << (k0 & 63);
  }
  return mask;
}

SampleMask SampleMaskCrossing(const CrossingEdges& c) {
  switch (c.count) {
    case 1:
      return CrossingMask<1>(c);
    case 2:
      return CrossingMask<2>(c);
    default:
      return CrossingMask<3>(c);
  }
}

}  // namespace covrast::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace covrast::detail {

HWY_EXPORT(SampleMaskCrossing);

namespace {

/// 2 E + bias at the corner (x, y) of the pixel in fx9 units, less the sample offset's
/// part: C of the top of the file.
std::int64_t corner_term(const EdgeFunction& e, int x, int y) {
  return e.dx * (std::int64_t(y) * kMaskUnitsPerPixel - 2 * e.y0) -
         e.dy * (std::int64_t(x) * kMaskUnitsPerPixel - 2 * e.x0) + e.bias;
}

}  // namespace

SampleMask pixel_sample_mask(const TriangleSetup& t, int x, int y) {
  const TriangleEdges edges(t);
  constexpr std::int64_t kLo = 1, kHi = kMaskUnitsPerPixel - 1;  // sample offsets [fx9]
  CrossingEdges crossing;
  crossing.count = 0;
  bool narrow = true;  // every crossing edge fits the int32 lanes
  for (const EdgeFunction& edge : edges.e) {
    const std::int64_t c = corner_term(edge, x, y);
    const std::int64_t t_lo =
        std::min(edge.dx * kLo, edge.dx * kHi) - std::max(edge.dy * kLo, edge.dy * kHi);
    const std::int64_t t_hi =
        std::max(edge.dx * kLo, edge.dx * kHi) - std::min(edge.dy * kLo, edge.dy * kHi);
    if (c + t_hi < 0) return SampleMask::none();  // the whole sample box outside this edge
    if (c + t_lo >= 0) continue;                  // all inside: so is every sample
    narrow = narrow && std::max(std::abs(edge.dx), std::abs(edge.dy)) <= kMaxLaneEdgeFx8;
    const int k = crossing.count++;
    crossing.c[k] = std::int32_t(narrow ? c : 0);
    crossing.dx[k] = std::int32_t(edge.dx);
    crossing.dy[k] = std::int32_t(edge.dy);
  }
  if (crossing.count == 0) return SampleMask::all();
  if (!narrow) return pixel_sample_mask_scalar(t, x, y);
  // Sample k lies at x offset 2k + 1 [fx9], odd, and the vertices on even ones (the 24.8
  // grid): a sample left of the triangle's leftmost vertex (2k + 1 < 2 min_x, k < min_x)
  // or right of its rightmost (k >= max_x), x relative to the pixel [fx8], is strictly
  // outside an edge, so no bias can take it in. Tiny triangles of dense meshes cover a
  // fraction of the pixel's width: only the samples over it are tested.
  const std::int32_t left_fx8 = std::int32_t(x) * kSubpixelOne;
  const std::int32_t min_x = std::min({t.x_fx8[0], t.x_fx8[1], t.x_fx8[2]}) - left_fx8;
  const std::int32_t max_x = std::max({t.x_fx8[0], t.x_fx8[1], t.x_fx8[2]}) - left_fx8;
  crossing.k_begin = int(std::clamp<std::int32_t>(min_x, 0, kMaskSamples));
  crossing.k_end = int(std::clamp<std::int32_t>(max_x, 0, kMaskSamples));
  return HWY_DYNAMIC_DISPATCH(SampleMaskCrossing)(crossing);
}

}  // namespace covrast::detail
#endif
