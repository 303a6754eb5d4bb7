// covrast public API: comparing two rendered images, for golden-image CI and for the
// quality figures of the benchmark report.
#pragma once

#include <covrast/image.hpp>

#include <optional>
#include <string>

namespace covrast {

/// When either image has an alpha plane (a transparent background), alpha is a fourth channel
/// of every measure (255 for an image without one); RGB images compare as before.
struct CompareResult {
  int width = 0;
  int height = 0;
  double rmse_linear = 0;   ///< root mean square error over all channels, linear light [0, 1]
  double psnr_db = 0;       ///< 20 log10(1 / rmse_linear); +inf when identical
  int max_diff_srgb8 = 0;   ///< largest |a - b| over all channels, 8-bit sRGB units
  double share_over_1 = 0;  ///< share of pixels with any channel off by more than 1/255
  double share_over_8 = 0;  ///< same, more than 8/255
  std::size_t pixels_over_1 = 0;
  std::size_t pixels_over_8 = 0;
};

/// Throws InputError if the sizes differ.
CompareResult compare_images(const Image& a, const Image& b);

/// One-line JSON summary of a comparison (keys as the fields above, in that order);
/// psnr_db is null when the images are identical (PSNR = +infinity).
std::string to_json(const CompareResult& result);

}  // namespace covrast
