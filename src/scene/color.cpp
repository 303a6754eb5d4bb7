// Colour helpers of the scene format: the sRGB transfer function (IEC 61966-2-1) used to turn
// the sRGB display values of scene files into linear light, and the per_triangle debug colour.
#include <covrast/scene.hpp>
#include "color/srgb.hpp"

#include <array>
#include <cmath>

namespace covrast {

float srgb_to_linear(float encoded) {
  // !(x > 0) also maps NaN to 0, so no NaN ever leaves the loader as a colour.
  if (!(encoded > 0.0f)) return 0.0f;
  if (encoded >= 1.0f) return 1.0f;
  const double c = encoded;
  const double linear = detail::srgb_decode(c);
  return static_cast<float>(linear);
}

float linear_to_srgb(float linear) {
  if (!(linear > 0.0f)) return 0.0f;
  if (linear >= 1.0f) return 1.0f;
  const double c = linear;
  const double encoded = detail::srgb_encode(c);
  return static_cast<float>(encoded);
}

std::uint32_t lowbias32(std::uint32_t x) {
  // Chris Wellons' lowbias32 integer hash; all arithmetic is modulo 2^32.
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

glm::vec3 per_triangle_color_srgb(std::uint32_t global_triangle_index) {
  const std::uint32_t h = lowbias32(global_triangle_index);
  return {static_cast<float>(h & 255u) / 255.0f, static_cast<float>((h >> 8) & 255u) / 255.0f,
          static_cast<float>((h >> 16) & 255u) / 255.0f};
}

glm::vec3 per_triangle_color_linear(std::uint32_t global_triangle_index) {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (std::uint32_t k = 0; k < 256; ++k) t[k] = srgb_to_linear(static_cast<float>(k) / 255.0f);
    return t;
  }();
  const std::uint32_t h = lowbias32(global_triangle_index);
  return {table[h & 255u], table[(h >> 8) & 255u], table[(h >> 16) & 255u]};
}

}  // namespace covrast
