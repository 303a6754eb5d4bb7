// Resolve stage, coverage mode: the 8x8 sub-pixel sample mask of a triangle in one pixel,
// used by the A-buffer (abuffer.cpp) where surfaces meet.
//
// Sample (i, j), i, j in [0, 8), lies at ((i + 0.5) / 8, (j + 0.5) / 8) inside pixel (x, y)
// and is bit j * 8 + i of the mask; it is set when the triangle owns the sample under the
// top-left rule of raster/edge_function.hpp (E + bias >= 0 for all three edges).
//
// pixel_sample_mask_scalar is the reference: int64 edge functions stepped over the grid.
// pixel_sample_mask gives the same bits faster (sample_mask.cpp explains why exactly):
// cheap early-outs on the four extreme samples of each edge, then the edges that cross
// the sample grid on int32 SIMD lanes (Highway dynamic dispatch).
#pragma once

#include "geometry/triangle_setup.hpp"

#include <cstdint>

namespace covrast::detail {

/// Samples of the 8x8 grid of pixel (x, y) that `t` owns, bit j * 8 + i: the best SIMD
/// target of this CPU (or the forced one). Bit-identical to pixel_sample_mask_scalar for
/// every input whose int64 edge functions do not overflow (any vertices and pixels within
/// 2^24 fx8 units, far beyond the guard band).
std::uint64_t pixel_sample_mask(const TriangleSetup& t, int x, int y);

/// The scalar reference: 3 int64 edge functions at each of the 64 samples.
std::uint64_t pixel_sample_mask_scalar(const TriangleSetup& t, int x, int y);

/// Highway targets compiled into this file (HWY_* bit flags); forcing one (0 = back to the
/// best supported) changes the choice for every Highway kernel of the process, as
/// force_coverage_kernel_target does.
std::int64_t sample_mask_targets();
void force_sample_mask_target(std::int64_t target);
const char* sample_mask_target_name();

}  // namespace covrast::detail
