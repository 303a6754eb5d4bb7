// Image comparison for golden-image CI and the quality figures of the benchmark report:
// error metrics in linear light, a colour-coded difference heat map and a one-line JSON
// summary. Single-threaded and in a fixed order so that the numbers are bit-for-bit
// reproducible.
#include <covrast/compare.hpp>
#include <covrast/error.hpp>
#include <covrast/tools.hpp>
#include "color/srgb.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string>

namespace covrast {
namespace {

// Differences of this many 8-bit units or more saturate the heat map at red.
constexpr int kHeatmapSaturationSrgb8 = 32;
// The ramp black -> blue -> green -> yellow -> red has four equal segments.
constexpr int kHeatmapSegmentSrgb8 = kHeatmapSaturationSrgb8 / 4;

std::string size_text(const Image& image) {
  return std::to_string(image.width) + "x" + std::to_string(image.height);
}

// Both images must have the same size and a buffer that matches it (a mismatched buffer
// would otherwise be read out of bounds).
void check_comparable(const Image& a, const Image& b) {
  for (const Image* image : {&a, &b}) {
    const std::size_t pixels = std::size_t(image->width) * std::size_t(image->height);
    if (image->width < 0 || image->height < 0 || image->rgb.size() != pixels * 3 ||
        (!image->alpha.empty() && image->alpha.size() != pixels)) {
      throw InputError("image buffer of " + std::to_string(image->rgb.size()) +
                       " bytes does not match its size " + size_text(*image));
    }
  }
  if (a.width != b.width || a.height != b.height) {
    throw InputError("image sizes differ: " + size_text(a) + " vs " + size_text(b));
  }
}

// A pixel's alpha: 255 (opaque) for an image without an alpha plane.
int alpha_at(const Image& image, std::size_t pixel) {
  return image.alpha.empty() ? 255 : int(image.alpha[pixel]);
}

// Largest channel difference of pixel index `pixel`, in 8-bit units; alpha counts as a fourth
// channel when either image has it.
int max_channel_diff(const Image& a, const Image& b, std::size_t pixel) {
  int max_diff = 0;
  for (std::size_t channel = 0; channel < 3; ++channel) {
    const std::size_t i = pixel * 3 + channel;
    max_diff = std::max(max_diff, std::abs(int(a.rgb[i]) - int(b.rgb[i])));
  }
  if (!a.alpha.empty() || !b.alpha.empty()) {
    max_diff = std::max(max_diff, std::abs(alpha_at(a, pixel) - alpha_at(b, pixel)));
  }
  return max_diff;
}

// Rounded 255 * t / segment for t in [0, segment], in integers so the ramp is exact.
std::uint8_t ramp_up(int t) {
  return std::uint8_t((255 * t + kHeatmapSegmentSrgb8 / 2) / kHeatmapSegmentSrgb8);
}

}  // namespace

CompareResult compare_images(const Image& a, const Image& b) {
  check_comparable(a, b);
  const std::array<double, 256>& linear = detail::srgb8_decode_table();

  CompareResult result;
  result.width = a.width;
  result.height = a.height;
  const std::size_t pixel_count = std::size_t(a.width) * std::size_t(a.height);

  // Sum of squared linear-light differences, in row-major then channel order; alpha (linear
  // already) is a fourth channel when either image has it.
  const bool with_alpha = !a.alpha.empty() || !b.alpha.empty();
  double sum_squared = 0;
  for (std::size_t pixel = 0; pixel < pixel_count; ++pixel) {
    for (std::size_t channel = 0; channel < 3; ++channel) {
      const std::size_t i = pixel * 3 + channel;
      const double diff = linear[a.rgb[i]] - linear[b.rgb[i]];
      sum_squared += diff * diff;
    }
    if (with_alpha) {
      const double diff = (alpha_at(a, pixel) - alpha_at(b, pixel)) / 255.0;
      sum_squared += diff * diff;
    }
    const int max_diff = max_channel_diff(a, b, pixel);
    result.max_diff_srgb8 = std::max(result.max_diff_srgb8, max_diff);
    // "More than 1/255" and "more than 8/255" in whole 8-bit units.
    if (max_diff > 1) ++result.pixels_over_1;
    if (max_diff > 8) ++result.pixels_over_8;
  }

  if (pixel_count > 0) {
    result.rmse_linear = std::sqrt(sum_squared / double(pixel_count * (with_alpha ? 4 : 3)));
    result.share_over_1 = double(result.pixels_over_1) / double(pixel_count);
    result.share_over_8 = double(result.pixels_over_8) / double(pixel_count);
  }
  result.psnr_db = result.rmse_linear == 0 ? std::numeric_limits<double>::infinity()
                                           : 20.0 * std::log10(1.0 / result.rmse_linear);
  return result;
}

Image difference_heatmap(const Image& a, const Image& b) {
  check_comparable(a, b);
  Image heatmap;
  heatmap.width = a.width;
  heatmap.height = a.height;
  heatmap.rgb.resize(a.rgb.size());

  // Piecewise-linear ramp over d = max channel |a - b| with stops every 8 units:
  // d = 0 black (0,0,0), 8 blue (0,0,255), 16 green (0,255,0), 24 yellow (255,255,0),
  // >= 32 red (255,0,0).
  const std::size_t pixel_count = a.rgb.size() / 3;
  for (std::size_t pixel = 0; pixel < pixel_count; ++pixel) {
    const int d = std::min(max_channel_diff(a, b, pixel), kHeatmapSaturationSrgb8);
    const int segment = std::min(d / kHeatmapSegmentSrgb8, 3);
    const int t = d - segment * kHeatmapSegmentSrgb8;  // position in the segment, [0, 8]
    std::uint8_t r = 0;
    std::uint8_t g = 0;
    std::uint8_t bl = 0;
    switch (segment) {
      case 0:  // black -> blue
        bl = ramp_up(t);
        break;
      case 1:  // blue -> green
        g = ramp_up(t);
        bl = ramp_up(kHeatmapSegmentSrgb8 - t);
        break;
      case 2:  // green -> yellow
        r = ramp_up(t);
        g = 255;
        break;
      default:  // yellow -> red
        r = 255;
        g = ramp_up(kHeatmapSegmentSrgb8 - t);
        break;
    }
    std::uint8_t* out = &heatmap.rgb[pixel * 3];
    out[0] = r;
    out[1] = g;
    out[2] = bl;
  }
  return heatmap;
}

std::string to_json(const CompareResult& result) {
  // ordered_json keeps the keys in the documented order. psnr_db is null when the images
  // are identical (PSNR = +infinity, which JSON cannot represent).
  nlohmann::ordered_json json;
  json["width"] = result.width;
  json["height"] = result.height;
  json["rmse_linear"] = result.rmse_linear;
  if (std::isinf(result.psnr_db)) {
    json["psnr_db"] = nullptr;
  } else {
    json["psnr_db"] = result.psnr_db;
  }
  json["max_diff_srgb8"] = result.max_diff_srgb8;
  json["share_over_1"] = result.share_over_1;
  json["share_over_8"] = result.share_over_8;
  json["pixels_over_1"] = result.pixels_over_1;
  json["pixels_over_8"] = result.pixels_over_8;
  return json.dump();
}

}  // namespace covrast
