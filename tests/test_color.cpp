// Tests of the colour helpers of the scene format: the sRGB transfer function (IEC 61966-2-1)
// and the per_triangle debug colour (lowbias32), against values worked out from the formulas.
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using covrast::linear_to_srgb;
using covrast::srgb_to_linear;

TEST_CASE("sRGB round trip is exact on all 256 8-bit codes", "[scene][color]") {
  for (int k = 0; k <= 255; ++k) {
    const float encoded = static_cast<float>(k) / 255.0f;
    const float back = linear_to_srgb(srgb_to_linear(encoded));
    INFO("k = " << k);
    REQUIRE(std::lround(255.0f * back) == k);
  }
}

TEST_CASE("sRGB transfer function matches IEC 61966-2-1", "[scene][color]") {
  REQUIRE(srgb_to_linear(0.0f) == 0.0f);
  REQUIRE(srgb_to_linear(1.0f) == 1.0f);
  REQUIRE(linear_to_srgb(0.0f) == 0.0f);
  REQUIRE(linear_to_srgb(1.0f) == 1.0f);
  // Linear segment below the threshold: c / 12.92.
  REQUIRE(srgb_to_linear(0.04f) == Approx(0.04 / 12.92).epsilon(1e-6));
  REQUIRE(linear_to_srgb(0.003f) == Approx(12.92 * 0.003).epsilon(1e-6));
  // Power segment: ((0.5 + 0.055) / 1.055)^2.4 = 0.214041140...
  REQUIRE(srgb_to_linear(0.5f) == Approx(0.21404114).epsilon(1e-6));
  // 1.055 * 0.5^(1/2.4) - 0.055 = 0.735356983...
  REQUIRE(linear_to_srgb(0.5f) == Approx(0.73535698).epsilon(1e-6));
  // The two pieces meet (continuity at the thresholds).
  REQUIRE(srgb_to_linear(0.04045f) == Approx(0.0031308).epsilon(1e-4));
  REQUIRE(linear_to_srgb(0.0031308f) == Approx(0.04045).epsilon(1e-4));
}

TEST_CASE("sRGB conversions clamp to [0, 1] and map NaN to 0", "[scene][color]") {
  REQUIRE(srgb_to_linear(-0.5f) == 0.0f);
  REQUIRE(srgb_to_linear(2.0f) == 1.0f);
  REQUIRE(linear_to_srgb(-0.5f) == 0.0f);
  REQUIRE(linear_to_srgb(7.0f) == 1.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  REQUIRE(srgb_to_linear(nan) == 0.0f);
  REQUIRE(linear_to_srgb(nan) == 0.0f);
}

TEST_CASE("lowbias32 and the per_triangle colour follow the formula", "[scene][color]") {
  // x = 0: every step keeps 0.
  REQUIRE(covrast::lowbias32(0u) == 0u);
  // x = 1, by hand (uint32 arithmetic):
  //   h ^= h >> 16        -> 0x00000001
  //   h *= 0x7feb352d     -> 0x7feb352d
  //   h ^= h >> 15        -> 0x7feb352d ^ 0x0000ffd6 = 0x7febcafb
  //   h *= 0x846ca68b     -> 0x6889f849 (mod 2^32)
  //   h ^= h >> 16        -> 0x6889f849 ^ 0x00006889 = 0x688990c0
  REQUIRE(covrast::lowbias32(1u) == 0x688990c0u);
  // x = 2: 0x2 -> 0xffd66a5a -> 0xffd795f6 -> 0xd113f092 -> 0xd1132181
  REQUIRE(covrast::lowbias32(2u) == 0xd1132181u);

  // r = h & 255, g = h >> 8 & 255, b = h >> 16 & 255, each / 255: for 0x688990c0 that is
  // r = 0xc0 = 192, g = 0x90 = 144, b = 0x89 = 137.
  const glm::vec3 c1 = covrast::per_triangle_color_srgb(1u);
  REQUIRE(c1.r == 192.0f / 255.0f);
  REQUIRE(c1.g == 144.0f / 255.0f);
  REQUIRE(c1.b == 137.0f / 255.0f);
  const glm::vec3 c0 = covrast::per_triangle_color_srgb(0u);
  REQUIRE(c0 == glm::vec3(0.0f));
}

TEST_CASE("per_triangle colour in linear light is srgb_to_linear of the sRGB one, bit for bit",
          "[scene][color]") {
  for (std::uint32_t i = 0; i < 100000; i += 7) {
    const glm::vec3 s = covrast::per_triangle_color_srgb(i);
    const glm::vec3 l = covrast::per_triangle_color_linear(i);
    INFO("triangle " << i);
    CHECK(l.r == covrast::srgb_to_linear(s.r));
    CHECK(l.g == covrast::srgb_to_linear(s.g));
    CHECK(l.b == covrast::srgb_to_linear(s.b));
  }
}
