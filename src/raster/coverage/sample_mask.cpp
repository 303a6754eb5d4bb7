// Resolve stage, coverage mode: the 16x16 sub-pixel sample mask (sample_mask.hpp), scalar
// reference and SIMD version, one source compiled for every Highway target.
//
// Why the SIMD version is exact. With samples 16 fx8 units apart, edge e at sample (i, j)
// is, exactly in int64,
//
//   E(i, j) = E00 + 16 * o(i, j),   o(i, j) = j * dx - i * dy,
//
// E00 = E + bias at sample (0, 0), (dx, dy) the edge vector [fx8]. As o is an integer,
//
//   E(i, j) >= 0  <=>  o >= -E00 / 16  <=>  o + F >= 0,   F = floor(E00 / 16) = E00 >> 4.
//
// o is extreme at the grid's corners: o_min = 15 min(dx, 0) - 15 max(dy, 0), o_max likewise.
// F + o_min >= 0: the edge holds every sample (it is skipped); F + o_max < 0: it holds
// none (mask 0). Otherwise the edge crosses the grid and is tested per sample on int32
// lanes: with |dx|, |dy| <= 2^25 (vertices within +-2^24 fx8, i.e. +-65536 px; the guard
// band keeps them within +-32768 px) |o| <= 15 * 2^26 < 2^30, and F clamped to
// [-2^30, 2^30] leaves the sign of o + F unchanged while |o + F| < 2^31. The lanes step
// from sample to sample, so every value they hold is such an o + F (never one past the
// grid), and the steps themselves (dx a row, -N dy a vector of N <= 16 lanes: at most 2^29)
// and lane * dy (at most 15 * 2^25) fit as well. Larger edges take the scalar reference.
// tests/test_sample_mask.cpp checks the bits on every target.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/coverage/sample_mask.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "core/edge_function.hpp"
#include "raster/coverage/sample_mask.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>

#ifndef COVRAST_RESOLVE_SAMPLE_MASK_ONCE_
#define COVRAST_RESOLVE_SAMPLE_MASK_ONCE_
namespace covrast::detail {

/// Largest |dx|, |dy| [fx8] of an edge the int32 lanes take (see the top of the file).
inline constexpr std::int64_t kMaxLaneEdgeFx8 = std::int64_t(1) << 25;
/// F is clamped to +-kLaneClamp: beyond it o + F has the sign of F for every sample.
inline constexpr std::int64_t kLaneClamp = std::int64_t(1) << 30;

/// The edges that cross the sample grid: o + f[e] >= 0 inside, o = j * dx[e] - i * dy[e].
struct CrossingEdges {
  std::int32_t f[3];
  std::int32_t dx[3];
  std::int32_t dy[3];
  int count;  ///< 1 to 3
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

/// Mask of the samples inside all kEdges crossing edges. Row j is walked in vectors of
/// N = Lanes(d) samples: lane l of the vector at column c0 is sample (c0 + l, j), bit
/// s = 16 j + c0 + l; as N divides 64, a vector's bits never straddle two words.
template <int kEdges>
HWY_INLINE SampleMask CrossingMask(const CrossingEdges& c) {
  const DI d;
  const int n = int(hn::Lanes(d));
  const auto minus_one = hn::Set(d, -1);
  const auto lane = hn::Iota(d, 0);
  // row[e]: o + F at samples (l, j) of the current row; o grows by dx a row and by -dy a
  // column, so by -N dy a vector.
  hn::Vec<DI> row[kEdges], column_step[kEdges];
  for (int e = 0; e < kEdges; ++e) {
    row[e] = hn::Sub(hn::Set(d, c.f[e]), hn::Mul(lane, hn::Set(d, c.dy[e])));
    column_step[e] = hn::Set(d, -c.dy[e] * n);
  }
  SampleMask mask = SampleMask::none();
  for (int j = 0;;) {
    hn::Vec<DI> v[kEdges];
    for (int e = 0; e < kEdges; ++e) v[e] = row[e];
    for (int c0 = 0;;) {
      auto any = v[0];
      for (int e = 1; e < kEdges; ++e) any = hn::Or(any, v[e]);
      // Inside every edge <=> no sign bit in any of the values.
      const int s = j * kMaskGridSide + c0;
      mask.word[s >> 6] |= LaneBits(d, hn::Gt(any, minus_one)) << (s & 63);
      c0 += n;
      if (c0 >= kMaskGridSide) break;
      for (int e = 0; e < kEdges; ++e) v[e] = hn::Add(v[e], column_step[e]);
    }
    if (++j == kMaskGridSide) break;
    for (int e = 0; e < kEdges; ++e) row[e] = hn::Add(row[e], hn::Set(d, c.dx[e]));
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

constexpr std::int64_t kSampleStepFx8 = kSubpixelOne / kMaskGridSide;  // 16 fx8 units
constexpr std::int64_t kLastSample = kMaskGridSide - 1;

}  // namespace

SampleMask pixel_sample_mask_scalar(const TriangleSetup& t, int x, int y) {
  TriangleEdges edges(t);
  const std::int64_t sx = std::int64_t(x) * kSubpixelOne + kSampleStepFx8 / 2;
  const std::int64_t sy = std::int64_t(y) * kSubpixelOne + kSampleStepFx8 / 2;
  SampleMask mask = SampleMask::none();
  std::int64_t row[3], dx[3], dy[3];
  for (int e = 0; e < 3; ++e) {
    row[e] = edges.e[e].at(sx, sy);
    dx[e] = edges.e[e].step_x(kSampleStepFx8);
    dy[e] = edges.e[e].step_y(kSampleStepFx8);
  }
  for (int j = 0; j < kMaskGridSide; ++j) {
    std::int64_t e0 = row[0], e1 = row[1], e2 = row[2];
    for (int i = 0; i < kMaskGridSide; ++i) {
      const int s = j * kMaskGridSide + i;
      if ((e0 | e1 | e2) >= 0) mask.word[s >> 6] |= std::uint64_t(1) << (s & 63);
      e0 += dx[0];
      e1 += dx[1];
      e2 += dx[2];
    }
    for (int e = 0; e < 3; ++e) row[e] += dy[e];
  }
  return mask;
}

SampleMask pixel_sample_mask(const TriangleSetup& t, int x, int y) {
  const TriangleEdges edges(t);
  const std::int64_t sx = std::int64_t(x) * kSubpixelOne + kSampleStepFx8 / 2;
  const std::int64_t sy = std::int64_t(y) * kSubpixelOne + kSampleStepFx8 / 2;
  CrossingEdges crossing;
  crossing.count = 0;
  bool narrow = true;  // every crossing edge fits the int32 lanes
  for (const EdgeFunction& edge : edges.e) {
    // F = floor(E00 / 16): the arithmetic shift rounds towards -infinity.
    const std::int64_t f = edge.at(sx, sy) >> 4;
    const std::int64_t o_min =
        kLastSample * (std::min<std::int64_t>(edge.dx, 0) - std::max<std::int64_t>(edge.dy, 0));
    const std::int64_t o_max =
        kLastSample * (std::max<std::int64_t>(edge.dx, 0) - std::min<std::int64_t>(edge.dy, 0));
    if (f + o_max < 0) return SampleMask::none();  // all four extreme samples outside this edge
    if (f + o_min >= 0) continue;                  // all four inside: so is every sample
    narrow = narrow && std::max(std::abs(edge.dx), std::abs(edge.dy)) <= kMaxLaneEdgeFx8;
    const int k = crossing.count++;
    crossing.f[k] = std::int32_t(std::clamp(f, -kLaneClamp, kLaneClamp));
    crossing.dx[k] = std::int32_t(edge.dx);
    crossing.dy[k] = std::int32_t(edge.dy);
  }
  if (crossing.count == 0) return SampleMask::all();
  if (!narrow) return pixel_sample_mask_scalar(t, x, y);
  return HWY_DYNAMIC_DISPATCH(SampleMaskCrossing)(crossing);
}

std::int64_t sample_mask_targets() { return HWY_TARGETS; }

void force_sample_mask_target(std::int64_t target) {
  hwy::SetSupportedTargetsForTest(target);
  // Makes the next dispatch pick again among the (now mocked) supported targets.
  hwy::GetChosenTarget().Update(hwy::SupportedTargets());
}

const char* sample_mask_target_name() {
  // Lower bits are better targets; dispatch takes the best one compiled and supported.
  const std::int64_t usable = HWY_TARGETS & hwy::SupportedTargets();
  return hwy::TargetName(usable & -usable);
}

}  // namespace covrast::detail
#endif
