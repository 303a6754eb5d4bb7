// Resolve stage: linear light to 8-bit sRGB, exactly round(255 * srgb(x)), and the
// copy-out of a finished tile into the frame.
#pragma once

#include "core/tile_raster.hpp"
#include "core/triangle_setup.hpp"

#include <cstdint>
#include <span>

namespace covrast::detail {

/// round(255 * linear_to_srgb(x)) for x in [0, 1] (clamped), from the 255 linear values where
/// the 8-bit code changes (a bucket table gives the start, a few threshold steps the code):
/// exact, and identical on every path.
std::uint8_t encode_srgb8(float linear);

/// encode_srgb8's tables, for SIMD encoders that must give its codes exactly: for x in (0, 1),
/// code = start[int(x * kSrgb8Buckets)], then ++code while threshold[code] <= x; x <= 0 (or
/// NaN) gives 0, x >= 1 gives 255.
inline constexpr int kSrgb8Buckets = 4096;
struct Srgb8EncodeTables {
  const float* threshold;     ///< 256 values: the linear value of code k + 0.5; [255] = +inf
  const std::int32_t* start;  ///< kSrgb8Buckets + 1 codes: the code of float(i) / kSrgb8Buckets
};
Srgb8EncodeTables srgb8_encode_tables();

/// A window depth as the depth outputs store it, in [0, 1]: a plane evaluated at a pixel
/// centre outside its triangle (a sliver's, steep) can leave the range; NaN becomes 1.
inline float clamp_window_depth(float z) {
  return z >= 0.0f ? (z < 1.0f ? z : 1.0f) : (z < 0.0f ? 0.0f : 1.0f);
}

/// Writes a tile's linear colours (row stride `stride` pixels) as 8-bit sRGB, and, when the
/// target wants depth, its window depths, into the frame.
void write_tile(const FrameTarget& target, const PixelRect& rect, const glm::vec3* linear,
                const float* depth, int stride);

}  // namespace covrast::detail
