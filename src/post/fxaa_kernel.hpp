// Post-process stage, FXAA: the per-row kernels. Two per target, for one frame of width W and
// height H (each 1..kMaxImageSide, so every pixel index fits int32):
//
//   luma row:   L = float(299 r + 587 g + 114 b) / 255000, one IEEE division per pixel of
//               the sRGB bytes (the integer sum is exact, and so is its conversion).
//   filter rows: for each pixel of row y, with the luma of its cross clamped to the frame,
//                 max = max(max(max(m, n), max(s, w)), e), min likewise, range = max - min,
//                 candidate <=> range > 0 and range >= max(edge_threshold_min,
//                                                         max * edge_threshold);
//               each candidate then goes through steps 2 to 5 of fxaa.hpp with exactly the
//               IEEE operations, in the order, of the scalar twin's fxaa_blend_scalar and
//               blend_pixel (fxaa_kernel_scalar.cpp): 3x3 second differences, the sub-pixel
//               weight, both searches along the edge (bilinear fetches at clamped pixels,
//               one step per iteration, each direction stopping on its own), the nearer end's
//               span weight, w = max(span, subpix), then per channel
//               out = encode_srgb8((1 - w) linear(centre) + w linear(partner)).
//
// max(a, b) and min(a, b) are std::max and std::min (a < b ? b : a, b < a ? b : a), not the
// IEEE maxNum or x86 max instructions, which differ on signed zeros. No FMA anywhere (the
// project compiles with -ffp-contract=off and the kernels never call MulAdd).
//
// Contract: the SIMD kernels (fxaa_kernel.cpp, one source for every Highway target) give the
// scalar twin's (fxaa_kernel_scalar.cpp) luma bits and output bytes exactly, on every target;
// tests/test_fxaa_kernel.cpp checks it per target. The filter writes only the pixels it
// changes: `out` must hold a copy of the input's rows. Each output pixel depends only on the
// input frame and its luma, so any split of the rows over threads gives the same bytes.
#pragma once

#include <cstdint>

namespace covrast::detail {

/// The options of one FXAA pass, as the kernels read them.
struct FxaaParams {
  float edge_threshold = 0;      ///< FxaaOptions::edge_threshold
  float edge_threshold_min = 0;  ///< FxaaOptions::edge_threshold_min
  float subpix = 0;              ///< FxaaOptions::subpix
  const float* steps = nullptr;  ///< fxaa_search_steps(quality_preset)
  int step_count = 0;            ///< >= 1
};

/// The frame a filter reads: the input bytes and their luma, both row-major and packed.
struct FxaaFrame {
  const std::uint8_t* rgb = nullptr;  ///< 3 * width * height bytes
  const float* luma = nullptr;        ///< width * height values
  int width = 0;
  int height = 0;
};

/// What FXAA does with one pixel: out = (1 - weight) in(x, y) + weight in(x + dx, y + dy),
/// with (dx, dy) a 4-neighbour; weight 0 leaves the pixel as it is.
struct FxaaBlend {
  int dx = 0;
  int dy = 0;
  float weight = 0;  ///< in [0, max(0.5, subpix)]
};

/// Steps 1 to 4 of fxaa.hpp for pixel (x, y) of `frame` (only its luma is read), one pixel at
/// a time: the scalar twin's arithmetic, and the reference of every lane.
FxaaBlend fxaa_blend_scalar(const FxaaFrame& frame, const FxaaParams& params, int x, int y);

/// luma[i] = the luma of pixel i of `rgb` (3 bytes each), for i < width.
using FxaaLumaRowFn = void (*)(const std::uint8_t* rgb, int width, float* luma);

/// Rows [y_begin, y_end) of the filtered frame into `out` (the output frame, 3 * width *
/// height bytes, holding the input's bytes in those rows): the candidates FXAA blends with
/// a weight other than 0 are rewritten, the others left alone.
using FxaaFilterRowsFn = void (*)(const FxaaFrame& frame, const FxaaParams& params, int y_begin,
                                  int y_end, std::uint8_t* out);

struct FxaaKernels {
  FxaaLumaRowFn luma_row;
  FxaaFilterRowsFn filter_rows;
};

/// The SIMD kernels of the target Highway dispatches to now (best supported, or forced with
/// testing::force_simd_target), looked up once per call: a pass keeps the pointers.
FxaaKernels fxaa_kernels_simd();
/// The scalar twins and reference: pixel by pixel, the arithmetic each SIMD lane does.
FxaaKernels fxaa_kernels_scalar();

/// sRGB byte -> linear light (IEC 61966-2-1, computed in double, rounded to float): the
/// blend's inputs, 256 values.
const float* fxaa_srgb8_linear();

}  // namespace covrast::detail
