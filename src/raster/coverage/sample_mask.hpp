// Coverage mode: the 256-sample sub-pixel mask of a triangle in one pixel, used by the
// A-buffer (abuffer_visibility.cpp, abuffer_samples.cpp) where surfaces meet.
//
// The samples form a rank-1 lattice (Korobov): sample k, k in [0, 256), lies at
//
//   ((2k + 1) / 512, (2 (71 k mod 256) + 1) / 512)
//
// inside pixel (x, y), i.e. at half-integer positions of the 24.8 fixed-point grid. It is an
// n-rooks pattern: one sample in each of the 256 columns and the 256 rows of width 1/256
// pixel, so an edge close to horizontal or vertical moves 1/256 of the samples per 1/256 pixel
// it moves (the 16x16 ordered grid moved 16 samples at once, every 1/16 pixel: CAD models and
// pleated sheets, whose creases run along rows, showed it). Generator 71 maximises the
// shortest lattice vector among all generators (16.55 / 256 pixel; the ordered grid has 16 /
// 256 but along both axes): over straight edges of every angle and offset the RMS error of
// the sample count is 0.0042 (grid 0.0040) and the largest 0.028 (grid 0.031); within 3
// degrees of an axis it is 0.0026 (grid 0.0117). docs/coverage.md gives the scene figures.
//
// A sample is owned under the top-left rule of core/edge_function.hpp (E + bias >= 0 for all
// three edges), with the edge functions evaluated exactly at the doubled coordinates (units
// of 1/512 pixel, int64). As vertices lie on the 1/256 grid and samples halfway between its
// points, an axis-aligned edge never passes through a sample; a slanted one can, and then
// the rule gives the sample to exactly one of two triangles that share the edge.
//
// pixel_sample_mask_scalar is the reference: the edge functions at each of the 256 samples.
// pixel_sample_mask gives the same bits faster (sample_mask.cpp explains why exactly): cheap
// early-outs on the extreme values of each edge over the lattice, then the edges that cross
// the pixel on int32 SIMD lanes (Highway dynamic dispatch).
#pragma once

#include "core/triangle_setup.hpp"

#include <array>
#include <bit>
#include <cstdint>

namespace covrast::detail {

/// Samples per pixel.
inline constexpr int kMaskSamples = 256;
/// The lattice's generator: sample k lies in fine row 71 k mod 256.
inline constexpr int kMaskGenerator = 71;
/// Sample positions are in units of 1/512 pixel ("fx9": 24.8 fixed point doubled).
inline constexpr int kMaskUnitsPerPixel = 512;

/// Sample k's offset from the pixel's top-left corner [fx9]: x = 2k + 1, y = 2 (71 k mod 256) + 1.
inline constexpr std::array<std::int32_t, kMaskSamples> kMaskSampleX_fx9 = [] {
  std::array<std::int32_t, kMaskSamples> x{};
  for (int k = 0; k < kMaskSamples; ++k) x[std::size_t(k)] = 2 * k + 1;
  return x;
}();
inline constexpr std::array<std::int32_t, kMaskSamples> kMaskSampleY_fx9 = [] {
  std::array<std::int32_t, kMaskSamples> y{};
  for (int k = 0; k < kMaskSamples; ++k) y[std::size_t(k)] = 2 * (kMaskGenerator * k % 256) + 1;
  return y;
}();

/// Sample offsets from the pixel's corner [pixels], exact in double.
inline constexpr auto kSampleOffsetX = [] {
  std::array<double, kMaskSamples> offset{};
  for (int k = 0; k < kMaskSamples; ++k) {
    offset[std::size_t(k)] = double(kMaskSampleX_fx9[std::size_t(k)]) / kMaskUnitsPerPixel;
  }
  return offset;
}();
inline constexpr auto kSampleOffsetY = [] {
  std::array<double, kMaskSamples> offset{};
  for (int k = 0; k < kMaskSamples; ++k) {
    offset[std::size_t(k)] = double(kMaskSampleY_fx9[std::size_t(k)]) / kMaskUnitsPerPixel;
  }
  return offset;
}();

/// Set bits of `v`, branch-free (SWAR; Hacker's Delight 5-1). std::popcount compiles to a
/// libgcc call (__popcountdi2) on the x86-64 baseline, which has no POPCNT instruction; this
/// is a dozen ALU operations on every target, inlined into the A-buffer's loops.
constexpr int popcount64(std::uint64_t v) {
  v = v - ((v >> 1) & 0x5555555555555555ull);
  v = (v & 0x3333333333333333ull) + ((v >> 2) & 0x3333333333333333ull);
  v = (v + (v >> 4)) & 0x0f0f0f0f0f0f0f0full;
  return int((v * 0x0101010101010101ull) >> 56);
}

/// 256 sample bits: sample k is bit k % 64 of word k / 64.
struct SampleMask {
  std::uint64_t word[kMaskSamples / 64];

  static constexpr SampleMask none() { return SampleMask{{0, 0, 0, 0}}; }
  static constexpr SampleMask all() { return SampleMask{{~0ull, ~0ull, ~0ull, ~0ull}}; }
  bool has(int k) const { return (word[k >> 6] >> (k & 63)) & 1u; }
  int count() const {
    return popcount64(word[0]) + popcount64(word[1]) + popcount64(word[2]) + popcount64(word[3]);
  }
  SampleMask& operator|=(const SampleMask& o) {
    for (int w = 0; w < 4; ++w) word[w] |= o.word[w];
    return *this;
  }
  SampleMask operator&(const SampleMask& o) const {
    return SampleMask{
        {word[0] & o.word[0], word[1] & o.word[1], word[2] & o.word[2], word[3] & o.word[3]}};
  }
  /// The samples of this mask that `o` does not have.
  SampleMask without(const SampleMask& o) const {
    return SampleMask{
        {word[0] & ~o.word[0], word[1] & ~o.word[1], word[2] & ~o.word[2], word[3] & ~o.word[3]}};
  }
  SampleMask operator|(const SampleMask& o) const {
    SampleMask m = *this;
    return m |= o;
  }
  bool operator==(const SampleMask&) const = default;
};

/// Calls f(k) for every sample k set in `mask`, in increasing order.
template <class F>
inline void for_each_sample(const SampleMask& mask, F f) {
  for (int w = 0; w < 4; ++w) {
    for (std::uint64_t bits = mask.word[w]; bits != 0; bits &= bits - 1) {
      f(w * 64 + std::countr_zero(bits));
    }
  }
}

/// Samples of pixel (x, y) that `t` owns: the best SIMD target of this CPU (or the forced
/// one). Bit-identical to pixel_sample_mask_scalar for every input whose int64 edge functions
/// do not overflow (any vertices and pixels within 2^24 fx8 units, far beyond the guard band).
SampleMask pixel_sample_mask(const TriangleSetup& t, int x, int y);

/// The scalar reference: 3 int64 edge functions at each of the 256 samples.
SampleMask pixel_sample_mask_scalar(const TriangleSetup& t, int x, int y);

}  // namespace covrast::detail
