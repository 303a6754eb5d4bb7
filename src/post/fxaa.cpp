// Post-process stage: FXAA 3.11, quality variant; the steps and their formulas are in
// fxaa.hpp and docs/fxaa.md, the per-row kernels in fxaa_kernel*.cpp. Written from the
// published description of the algorithm.
#include "post/fxaa.hpp"

#include <covrast/scene.hpp>

#include <array>
#include <cstddef>
#include <string>

namespace covrast::detail {
namespace {

/// FXAA 3.11's quality presets: the search steps along an edge [pixels]. The last, long step
/// is where the search assumes the edge ends when it has not found the end by then.
struct Preset {
  int id;
  std::array<float, 12> steps;
  int step_count;
};
constexpr std::array<Preset, 17> kPresets{{
    {10, {1.5f, 3.0f, 12.0f}, 3},
    {11, {1.0f, 1.5f, 3.0f, 12.0f}, 4},
    {12, {1.0f, 1.5f, 2.0f, 4.0f, 12.0f}, 5},
    {13, {1.0f, 1.5f, 2.0f, 2.0f, 4.0f, 12.0f}, 6},
    {14, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 4.0f, 12.0f}, 7},
    {15, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 12.0f}, 8},
    {20, {1.5f, 2.0f, 8.0f}, 3},
    {21, {1.0f, 1.5f, 2.0f, 8.0f}, 4},
    {22, {1.0f, 1.5f, 2.0f, 2.0f, 8.0f}, 5},
    {23, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 8.0f}, 6},
    {24, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 3.0f, 8.0f}, 7},
    {25, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f}, 8},
    {26, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f}, 9},
    {27, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f}, 10},
    {28, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f}, 11},
    {29, {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f}, 12},
    {39, {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f}, 12},
}};

}  // namespace

std::span<const float> fxaa_search_steps(int quality_preset) {
  for (const Preset& p : kPresets) {
    if (p.id == quality_preset) return {p.steps.data(), std::size_t(p.step_count)};
  }
  return {};
}

FxaaParams fxaa_params(const FxaaOptions& options) {
  const std::span<const float> steps = fxaa_search_steps(options.quality_preset);
  return {options.edge_threshold, options.edge_threshold_min, options.subpix, steps.data(),
          int(steps.size())};
}

void fxaa_luma_rows(const Image& image, LumaPlane& plane, int y_begin, int y_end,
                    const FxaaKernels& kernels) {
  for (int y = y_begin; y < y_end; ++y) {
    kernels.luma_row(image.pixel(0, y), image.width, &plane.luma[std::size_t(y) * image.width]);
  }
}

FxaaBlend fxaa_pixel_blend(const LumaPlane& plane, int x, int y, const FxaaOptions& options,
                           std::span<const float> steps) {
  const FxaaFrame frame{nullptr, plane.luma.data(), plane.width, plane.height};
  FxaaParams params = fxaa_params(options);
  params.steps = steps.data();
  params.step_count = int(steps.size());
  return fxaa_blend_scalar(frame, params, x, y);
}

void fxaa_rows(const Image& input, const LumaPlane& plane, const FxaaOptions& options,
               Image& output, int y_begin, int y_end, const FxaaKernels& kernels) {
  const FxaaFrame frame{input.rgb.data(), plane.luma.data(), input.width, input.height};
  const FxaaParams params = fxaa_params(options);
  if (y_begin < y_end) kernels.filter_rows(frame, params, y_begin, y_end, output.rgb.data());
}

Image fxaa(const Image& input, const FxaaOptions& options, const FxaaKernels& kernels) {
  if (fxaa_search_steps(options.quality_preset).empty()) {
    throw InputError("unknown FXAA quality preset " + std::to_string(options.quality_preset));
  }
  // The kernels index pixels with int32.
  if (input.width < 1 || input.width > kMaxImageSide || input.height < 1 ||
      input.height > kMaxImageSide) {
    throw InputError("FXAA: image size " + std::to_string(input.width) + "x" +
                     std::to_string(input.height) + " out of range");
  }
  LumaPlane plane{input.width, input.height, std::vector<float>(input.rgb.size() / 3)};
  fxaa_luma_rows(input, plane, 0, input.height, kernels);
  Image output = input;
  fxaa_rows(input, plane, options, output, 0, input.height, kernels);
  return output;
}

}  // namespace covrast::detail
