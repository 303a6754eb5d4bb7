// Resolve stage: sRGB encoding and tile copy-out; see srgb8.hpp.
#include "resolve/srgb8.hpp"

#include <covrast/scene.hpp>

#include <array>
#include <cmath>

namespace covrast::detail {
namespace {

/// thresholds[k] = the linear value whose sRGB code is exactly k + 0.5: codes at or above
/// it round to k + 1 or more. Computed in double from the IEC 61966-2-1 inverse.
std::array<float, 255> make_thresholds() {
  std::array<float, 255> t{};
  for (int k = 0; k < 255; ++k) {
    double e = (k + 0.5) / 255.0;
    double lin = e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
    t[k] = float(lin);
  }
  return t;
}

const std::array<float, 255>& thresholds() {
  static const std::array<float, 255> t = make_thresholds();
  return t;
}

}  // namespace

std::uint8_t encode_srgb8(float linear) {
  const auto& t = thresholds();
  // Count thresholds <= linear: 8 halving steps over 255 entries.
  int lo = 0, hi = 255;
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    if (t[mid] <= linear) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return std::uint8_t(lo);
}

void write_tile(const FrameTarget& target, const PixelRect& rect, const glm::vec3* linear,
                const float* depth, int stride) {
  for (int y = rect.y0; y < rect.y1; ++y) {
    const glm::vec3* src = linear + std::size_t(y - rect.y0) * stride;
    std::uint8_t* dst = target.color->pixel(rect.x0, y);
    for (int x = rect.x0; x < rect.x1; ++x, ++src, dst += 3) {
      dst[0] = encode_srgb8(src->r);
      dst[1] = encode_srgb8(src->g);
      dst[2] = encode_srgb8(src->b);
    }
    if (target.depth != nullptr && depth != nullptr) {
      const float* dsrc = depth + std::size_t(y - rect.y0) * stride;
      float* ddst = &target.depth->depth[std::size_t(y) * target.depth->width + rect.x0];
      for (int x = rect.x0; x < rect.x1; ++x) *ddst++ = std::min(*dsrc++, 1.0f);
    }
  }
}

}  // namespace covrast::detail
