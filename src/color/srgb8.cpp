// Resolve stage: sRGB encoding and tile copy-out; see srgb8.hpp.
#include "color/srgb8.hpp"
#include "color/srgb.hpp"

#include <array>
#include <cmath>
#include <limits>

namespace covrast::detail {
namespace {

/// thresholds[k] = the linear value whose sRGB code is exactly k + 0.5: codes at or above
/// it round to k + 1 or more. Computed in double from the IEC 61966-2-1 inverse.
std::array<float, 255> make_thresholds() {
  std::array<float, 255> t{};
  for (int k = 0; k < 255; ++k) {
    double e = (k + 0.5) / 255.0;
    double lin = srgb_decode(e);
    t[k] = float(lin);
  }
  return t;
}

/// Buckets of the linear range: start[i] is the code of the smallest value of bucket i, so
/// encoding is a table look-up plus at most a few threshold steps (the sRGB curve is
/// steepest near 0, at 12.92 * 255 codes per unit: under one code per bucket).
constexpr int kBuckets = kSrgb8Buckets;

struct Encoder {
  std::array<float, 256> threshold;  ///< threshold[255] = +inf as a sentinel
  std::array<std::uint8_t, kBuckets + 1> start;
  std::array<std::int32_t, kBuckets + 1> start32;  ///< start, for 32-bit SIMD gathers
  Encoder() {
    auto t = make_thresholds();
    for (int k = 0; k < 255; ++k) threshold[k] = t[k];
    threshold[255] = std::numeric_limits<float>::infinity();
    for (int i = 0; i <= kBuckets; ++i) {
      float lo = float(i) / kBuckets;
      int code = 0;
      while (threshold[code] <= lo) ++code;
      start[i] = std::uint8_t(code);
      start32[i] = code;
    }
  }
};

/// Built once at start-up (no guard on every call, as a function-local static would need);
/// nothing encodes during static initialisation.
const Encoder g_encoder;

/// encode_srgb8's body, inlined into the tile copy-out, which runs it for every pixel.
inline std::uint8_t encode(float linear) {
  // The result is the number of thresholds <= linear, i.e. round(255 * srgb(linear)).
  if (!(linear > 0.0f)) return 0;
  if (linear >= 1.0f) return 255;
  // float(i) / kBuckets <= linear for i = floor(linear * kBuckets): exact power-of-2 scaling.
  int code = g_encoder.start[int(linear * kBuckets)];
  while (g_encoder.threshold[code] <= linear) ++code;
  return std::uint8_t(code);
}

}  // namespace

std::uint8_t encode_srgb8(float linear) { return encode(linear); }

Srgb8EncodeTables srgb8_encode_tables() {
  return {g_encoder.threshold.data(), g_encoder.start32.data()};
}

void write_tile(const FrameTarget& target, const PixelRect& rect, const glm::vec3* linear,
                const float* depth, int stride) {
  for (int y = rect.y0; y < rect.y1; ++y) {
    const glm::vec3* src = linear + std::size_t(y - rect.y0) * stride;
    std::uint8_t* dst = target.color->pixel(rect.x0, y);
    // Flat-shaded scenes repeat colours along a row: reuse the last encoding.
    glm::vec3 last(-1.0f);
    std::uint8_t code[3] = {0, 0, 0};
    for (int x = rect.x0; x < rect.x1; ++x, ++src, dst += 3) {
      if (*src != last) {
        last = *src;
        code[0] = encode(src->r);
        code[1] = encode(src->g);
        code[2] = encode(src->b);
      }
      dst[0] = code[0];
      dst[1] = code[1];
      dst[2] = code[2];
    }
    if (target.depth != nullptr && depth != nullptr) {
      const float* dsrc = depth + std::size_t(y - rect.y0) * stride;
      float* ddst = &target.depth->depth[std::size_t(y) * target.depth->width + rect.x0];
      for (int x = rect.x0; x < rect.x1; ++x) *ddst++ = clamp_window_depth(*dsrc++);
    }
  }
}

}  // namespace covrast::detail
