// Resolve stage, coverage mode: the 16x16 sub-pixel sample mask of a triangle in one pixel,
// used by the A-buffer (abuffer.cpp) where surfaces meet.
//
// Sample (i, j), i, j in [0, 16), lies at ((i + 0.5) / 16, (j + 0.5) / 16) inside pixel
// (x, y), an integer position in 24.8 fixed point (16 i + 8 fx8 units from the pixel's
// corner), and is sample s = j * 16 + i of the mask; it is set when the triangle owns the
// sample under the top-left rule of raster/edge_function.hpp (E + bias >= 0 for all three
// edges). 256 samples rather than 64: a sliver of 1-3% of a pixel at a grazing silhouette
// owns 2-8 of them instead of 0-2, which decides its visible share among several layers.
//
// pixel_sample_mask_scalar is the reference: int64 edge functions stepped over the grid.
// pixel_sample_mask gives the same bits faster (sample_mask.cpp explains why exactly):
// cheap early-outs on the four extreme samples of each edge, then the edges that cross
// the sample grid on int32 SIMD lanes (Highway dynamic dispatch).
#pragma once

#include "core/triangle_setup.hpp"

#include <bit>
#include <cstdint>

namespace covrast::detail {

/// Samples per side of a pixel's mask grid, and in all.
inline constexpr int kMaskGridSide = 16;
inline constexpr int kMaskSamples = kMaskGridSide * kMaskGridSide;

/// 256 sample bits: sample s is bit s % 64 of word s / 64 (four rows of samples per word).
struct SampleMask {
  std::uint64_t word[kMaskSamples / 64];

  static constexpr SampleMask none() { return SampleMask{{0, 0, 0, 0}}; }
  static constexpr SampleMask all() { return SampleMask{{~0ull, ~0ull, ~0ull, ~0ull}}; }
  /// The 16 samples of row j, sample (i, j) as bit i.
  std::uint32_t row(int j) const { return std::uint32_t(word[j >> 2] >> (16 * (j & 3))) & 0xffffu; }
  int count() const {
    return std::popcount(word[0]) + std::popcount(word[1]) + std::popcount(word[2]) +
           std::popcount(word[3]);
  }
  SampleMask& operator|=(const SampleMask& o) {
    for (int w = 0; w < 4; ++w) word[w] |= o.word[w];
    return *this;
  }
  SampleMask operator&(const SampleMask& o) const {
    return SampleMask{
        {word[0] & o.word[0], word[1] & o.word[1], word[2] & o.word[2], word[3] & o.word[3]}};
  }
  SampleMask operator|(const SampleMask& o) const {
    SampleMask m = *this;
    return m |= o;
  }
  bool operator==(const SampleMask&) const = default;
};

/// Samples of the 16x16 grid of pixel (x, y) that `t` owns: the best SIMD target of this
/// CPU (or the forced one). Bit-identical to pixel_sample_mask_scalar for every input whose
/// int64 edge functions do not overflow (any vertices and pixels within 2^24 fx8 units, far
/// beyond the guard band).
SampleMask pixel_sample_mask(const TriangleSetup& t, int x, int y);

/// The scalar reference: 3 int64 edge functions at each of the 256 samples.
SampleMask pixel_sample_mask_scalar(const TriangleSetup& t, int x, int y);

/// Highway targets compiled into this file (HWY_* bit flags); forcing one (0 = back to the
/// best supported) changes the choice for every Highway kernel of the process, as
/// force_coverage_kernel_target does.
std::int64_t sample_mask_targets();
void force_sample_mask_target(std::int64_t target);
const char* sample_mask_target_name();

}  // namespace covrast::detail
