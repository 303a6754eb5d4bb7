// Post: transparent and skybox backgrounds (formulas in post/background.hpp).
#include "post/background.hpp"

#include "core/srgb.hpp"
#include "core/srgb8.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace covrast::detail {
namespace {

/// The linear value of each 8-bit code (the encoder's inverse at the code itself).
const std::array<double, 256>& decode_table() {
  static const std::array<double, 256> table = [] {
    std::array<double, 256> t{};
    for (int c = 0; c < 256; ++c) t[std::size_t(c)] = srgb_decode(c / 255.0);
    return t;
  }();
  return table;
}

/// The background's share w of one pixel from its codes over black and over white.
double background_share(const std::uint8_t* black, const std::uint8_t* white) {
  if (black[0] == white[0] && black[1] == white[1] && black[2] == white[2]) return 0.0;
  if (black[0] == 0 && black[1] == 0 && black[2] == 0 && white[0] == 255 && white[1] == 255 &&
      white[2] == 255) {
    return 1.0;
  }
  const std::array<double, 256>& dec = decode_table();
  double sum = 0.0;
  for (int c = 0; c < 3; ++c) sum += dec[white[c]] - dec[black[c]];
  return std::clamp(sum / 3.0, 0.0, 1.0);
}

std::uint8_t unit_code(double x) {
  return std::uint8_t(std::lround(std::clamp(x, 0.0, 1.0) * 255.0));
}

}  // namespace

void key_transparent(const Image& over_black, const Image& over_white, Image& out) {
  const std::array<double, 256>& dec = decode_table();
  out.width = over_black.width;
  out.height = over_black.height;
  out.rgb.assign(over_black.rgb.size(), 0);
  out.alpha.assign(std::size_t(out.width) * std::size_t(out.height), 0);
  for (std::size_t i = 0; i < out.alpha.size(); ++i) {
    const std::uint8_t* black = &over_black.rgb[3 * i];
    const double alpha = 1.0 - background_share(black, &over_white.rgb[3 * i]);
    out.alpha[i] = unit_code(alpha);
    if (out.alpha[i] == 0) continue;  // colour 0 where nothing shows
    for (int c = 0; c < 3; ++c) {
      out.rgb[3 * i + std::size_t(c)] =
          alpha >= 1.0 ? black[c] : encode_srgb8(float(std::min(1.0, dec[black[c]] / alpha)));
    }
  }
}

void key_skybox(const Image& over_black, const Image& over_white,
                const std::function<glm::dvec3(int, int)>& sky, Image& out) {
  const std::array<double, 256>& dec = decode_table();
  out.width = over_black.width;
  out.height = over_black.height;
  out.rgb.assign(over_black.rgb.size(), 0);
  out.alpha.clear();
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(out.width) + std::size_t(x);
      const std::uint8_t* black = &over_black.rgb[3 * i];
      const double w = background_share(black, &over_white.rgb[3 * i]);
      std::uint8_t* dst = &out.rgb[3 * i];
      if (w == 0.0) {
        std::copy(black, black + 3, dst);
        continue;
      }
      const glm::dvec3 k = sky(x, y);
      for (int c = 0; c < 3; ++c) dst[c] = encode_srgb8(float(dec[black[c]] + w * k[c]));
    }
  }
}

}  // namespace covrast::detail
