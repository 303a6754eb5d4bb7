// Colour: the sRGB transfer functions of IEC 61966-2-1, in double. The one home of both
// formulas: every table and conversion of covrast (colour parsing, texture decoding, the
// 8-bit encoder's thresholds, the blends of the aliased mode and FXAA, image comparison) is
// built from these, so that they agree bit for bit.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

namespace covrast::detail {

/// Linear light of an encoded value c in [0, 1]:
///   c / 12.92                      for c <= 0.04045
///   ((c + 0.055) / 1.055) ^ 2.4    otherwise
inline double srgb_decode(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

/// The encoded value of linear light l in [0, 1]:
///   12.92 l                        for l <= 0.0031308
///   1.055 l ^ (1 / 2.4) - 0.055    otherwise
inline double srgb_encode(double l) {
  return l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
}

/// srgb_decode(c / 255) of every 8-bit code c, computed once per process (thread-safe): what
/// an 8-bit sRGB byte means in linear light, for everything that reads one back.
inline const std::array<double, 256>& srgb8_decode_table() {
  static const std::array<double, 256> table = [] {
    std::array<double, 256> t{};
    for (int code = 0; code < 256; ++code) t[std::size_t(code)] = srgb_decode(code / 255.0);
    return t;
  }();
  return table;
}

}  // namespace covrast::detail
