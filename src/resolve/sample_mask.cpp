// Resolve stage, coverage mode: the 8x8 sub-pixel sample mask (sample_mask.hpp), scalar
// reference and SIMD version, one source compiled for every Highway target.
//
// Why the SIMD version is exact. With samples 32 fx8 units apart, edge e at sample (i, j)
// is, exactly in int64,
//
//   E(i, j) = E00 + 32 * o(i, j),   o(i, j) = j * dx - i * dy,
//
// E00 = E + bias at sample (0, 0), (dx, dy) the edge vector [fx8]. As o is an integer,
//
//   E(i, j) >= 0  <=>  o >= -E00 / 32  <=>  o + F >= 0,   F = floor(E00 / 32) = E00 >> 5.
//
// o is extreme at the grid's corners: o_min = 7 min(dx, 0) - 7 max(dy, 0), o_max likewise.
// F + o_min >= 0: the edge holds every sample (it is skipped); F + o_max < 0: it holds
// none (mask 0). Otherwise the edge crosses the grid and is tested per sample on int32
// lanes: with |dx|, |dy| <= 2^25 (vertices within +-2^24 fx8, i.e. +-65536 px; the guard
// band keeps them within +-32768 px) |o| <= 7 * 2^26 < 2^29, and F clamped to
// [-2^30, 2^30] leaves the sign of o + F unchanged while |o + F| < 2^31. Larger edges take
// the scalar reference. tests/test_sample_mask.cpp checks the bits on every target.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "resolve/sample_mask.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "raster/edge_function.hpp"
#include "resolve/sample_mask.hpp"

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

// Up to 16 int32 lanes: two rows of samples per vector on AVX-512, one on AVX2, half a
// row on 128-bit targets, one sample on the scalar one.
using DI = hn::CappedTag<std::int32_t, 16>;

/// Bits of the lanes that are set in `inside`, as the low Lanes(d) bits of an integer.
HWY_INLINE std::uint64_t LaneBits(DI d, hn::Mask<DI> inside) {
  std::uint8_t bytes[8] = {};  // StoreMaskBits may write up to 8 bytes
  hn::StoreMaskBits(d, inside, bytes);
  std::uint64_t bits;
  std::memcpy(&bits, bytes, sizeof(bits));
  return bits;
}

/// Mask of the samples inside all kEdges crossing edges. Lane l of vector k is sample
/// s = k N + l, i = s & 7, j = s >> 3.
template <int kEdges>
HWY_INLINE std::uint64_t CrossingMask(const CrossingEdges& c) {
  const DI d;
  const std::size_t n = hn::Lanes(d);
  const auto minus_one = hn::Set(d, -1);
  const auto lane = hn::Iota(d, 0);
  std::uint64_t mask = 0;
  if (n % 8 == 0) {
    // Whole rows per vector: the next vector is n / 8 rows further, o grows by n / 8 * dx.
    const auto col = hn::And(lane, hn::Set(d, 7));
    const auto row = hn::ShiftRight<3>(lane);
    hn::Vec<DI> v[kEdges], step[kEdges];
    for (int e = 0; e < kEdges; ++e) {
      v[e] = hn::Add(hn::Set(d, c.f[e]),
                     hn::Sub(hn::Mul(row, hn::Set(d, c.dx[e])), hn::Mul(col, hn::Set(d, c.dy[e]))));
      step[e] = hn::Set(d, c.dx[e] * std::int32_t(n / 8));
    }
    for (std::size_t k = 0;;) {
      auto any = v[0];
      for (int e = 1; e < kEdges; ++e) any = hn::Or(any, v[e]);
      // Inside every edge <=> no sign bit in any of the values.
      mask |= LaneBits(d, hn::Gt(any, minus_one)) << k;
      k += n;
      if (k >= 64) break;
      for (int e = 0; e < kEdges; ++e) v[e] = hn::Add(v[e], step[e]);
    }
  } else {
    for (std::size_t k = 0; k < 64; k += n) {
      const auto s = hn::Add(lane, hn::Set(d, std::int32_t(k)));
      const auto col = hn::And(s, hn::Set(d, 7));
      const auto row = hn::ShiftRight<3>(s);
      auto any = hn::Zero(d);
      for (int e = 0; e < kEdges; ++e) {
        any = hn::Or(any, hn::Add(hn::Set(d, c.f[e]), hn::Sub(hn::Mul(row, hn::Set(d, c.dx[e])),
                                                              hn::Mul(col, hn::Set(d, c.dy[e])))));
      }
      mask |= LaneBits(d, hn::Gt(any, minus_one)) << k;
    }
  }
  return mask;
}

std::uint64_t SampleMaskCrossing(const CrossingEdges& c) {
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

constexpr std::int64_t kSampleStepFx8 = kSubpixelOne / 8;  // 32 fx8 units

}  // namespace

std::uint64_t pixel_sample_mask_scalar(const TriangleSetup& t, int x, int y) {
  TriangleEdges edges(t);
  constexpr std::int64_t kStep = kSubpixelOne / 8;  // 32 fx8 units
  const std::int64_t sx = std::int64_t(x) * kSubpixelOne + kStep / 2;
  const std::int64_t sy = std::int64_t(y) * kSubpixelOne + kStep / 2;
  std::uint64_t mask = 0;
  std::int64_t row[3], dx[3], dy[3];
  for (int e = 0; e < 3; ++e) {
    row[e] = edges.e[e].at(sx, sy);
    dx[e] = edges.e[e].step_x(kStep);
    dy[e] = edges.e[e].step_y(kStep);
  }
  for (int j = 0; j < 8; ++j) {
    std::int64_t e0 = row[0], e1 = row[1], e2 = row[2];
    for (int i = 0; i < 8; ++i) {
      if ((e0 | e1 | e2) >= 0) mask |= std::uint64_t(1) << (j * 8 + i);
      e0 += dx[0];
      e1 += dx[1];
      e2 += dx[2];
    }
    for (int e = 0; e < 3; ++e) row[e] += dy[e];
  }
  return mask;
}

std::uint64_t pixel_sample_mask(const TriangleSetup& t, int x, int y) {
  const TriangleEdges edges(t);
  const std::int64_t sx = std::int64_t(x) * kSubpixelOne + kSampleStepFx8 / 2;
  const std::int64_t sy = std::int64_t(y) * kSubpixelOne + kSampleStepFx8 / 2;
  CrossingEdges crossing;
  crossing.count = 0;
  bool narrow = true;  // every crossing edge fits the int32 lanes
  for (const EdgeFunction& edge : edges.e) {
    // F = floor(E00 / 32): the arithmetic shift rounds towards -infinity.
    const std::int64_t f = edge.at(sx, sy) >> 5;
    const std::int64_t o_min =
        7 * (std::min<std::int64_t>(edge.dx, 0) - std::max<std::int64_t>(edge.dy, 0));
    const std::int64_t o_max =
        7 * (std::max<std::int64_t>(edge.dx, 0) - std::min<std::int64_t>(edge.dy, 0));
    if (f + o_max < 0) return 0;   // all four extreme samples outside this edge
    if (f + o_min >= 0) continue;  // all four inside: so is every sample
    narrow = narrow && std::max(std::abs(edge.dx), std::abs(edge.dy)) <= kMaxLaneEdgeFx8;
    const int k = crossing.count++;
    crossing.f[k] = std::int32_t(std::clamp(f, -kLaneClamp, kLaneClamp));
    crossing.dx[k] = std::int32_t(edge.dx);
    crossing.dy[k] = std::int32_t(edge.dy);
  }
  if (crossing.count == 0) return ~std::uint64_t(0);
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
