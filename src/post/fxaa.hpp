// Post-process stage: FXAA 3.11, the "quality" variant (Timothy Lottes, NVIDIA, 2011: the FXAA
// white paper and the description in the FXAA 3.11 header), run on the finished 8-bit sRGB
// frame. Only the pipeline calls it, after the tile pass; it includes nothing of the stages
// before it. Every output pixel depends only on the input frame (never on another output), so
// any split of the rows over threads gives the same bytes. The steps per pixel, with luma L
// in [0, 1] (docs/fxaa.md has the derivations):
//   1. contrast test on the cross M, N, S, W, E: skip unless
//      max - min >= max(edge_threshold_min, edge_threshold * max)
//   2. edge direction from second differences over the 3x3 block: horizontal or vertical
//   3. sub-pixel aliasing: c = |lowpass(3x3) - M| / range, weight (c^2 (3 - 2c))^2 * subpix
//   4. search along the edge, half a pixel towards the steeper side, in the preset's steps,
//      until the luma leaves the edge's mean by a quarter of its gradient: the nearer end
//      gives the weight 0.5 - distance / span length
//   5. blend with the neighbour across the edge: out = (1 - w) in(M) + w in(neighbour),
//      w = max(step 4, step 3), in linear light
// The per-row work runs in the kernels of fxaa_kernel.hpp (SIMD, with a scalar twin that
// gives the same bits); this file is the stage's interface.
#pragma once

#include "post/fxaa_kernel.hpp"

#include <covrast/image.hpp>
#include <covrast/options.hpp>

#include <span>
#include <vector>

namespace covrast::detail {

/// The distances of the successive search steps along an edge of a quality preset [pixels]
/// (FXAA_QUALITY__P0, P1, ...); empty for a preset FXAA 3.11 does not define.
std::span<const float> fxaa_search_steps(int quality_preset);

/// The kernels' view of `options` (a preset FXAA 3.11 defines).
FxaaParams fxaa_params(const FxaaOptions& options);

/// A frame's luma, row-major, width * height values.
struct LumaPlane {
  int width = 0;
  int height = 0;
  std::vector<float> luma;
};

/// Writes rows [y_begin, y_end) of `plane` (already sized for `image`): the luma FXAA works
/// on, (299 r + 587 g + 114 b) / 255000 of the sRGB-encoded bytes, in [0, 1] (ITU-R BT.601
/// weights, as the FXAA 3.11 header computes it on non-linear colour).
void fxaa_luma_rows(const Image& image, LumaPlane& plane, int y_begin, int y_end,
                    const FxaaKernels& kernels = fxaa_kernels_simd());

/// Steps 1 to 4 for pixel (x, y), one pixel at a time (the scalar reference).
/// `steps` = fxaa_search_steps(options.quality_preset).
FxaaBlend fxaa_pixel_blend(const LumaPlane& plane, int x, int y, const FxaaOptions& options,
                           std::span<const float> steps);

/// Filters rows [y_begin, y_end) of `output`, which holds the bytes of `input` in those rows
/// (a copy of it): only the pixels FXAA changes are rewritten, from `input` and its luma.
void fxaa_rows(const Image& input, const LumaPlane& plane, const FxaaOptions& options,
               Image& output, int y_begin, int y_end,
               const FxaaKernels& kernels = fxaa_kernels_simd());

/// The whole frame on the calling thread (tests, tools), with the SIMD kernels or the scalar
/// twins (the same bytes). Throws InputError on a bad preset or a side outside
/// 1..kMaxImageSide.
Image fxaa(const Image& input, const FxaaOptions& options,
           const FxaaKernels& kernels = fxaa_kernels_simd());

}  // namespace covrast::detail
