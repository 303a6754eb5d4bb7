// The exact texture mean over a fragment (texture/texture_sampling.hpp, area_average) on
// texels of noise, against a brute-force integration of the LINEAR filter (test_textures.cpp
// checks it on ramps and single texels, where most of its terms are zero and skipped).
#include <covrast/scene.hpp>

#include "texture/texture_sampling.hpp"

#include <catch2/catch.hpp>

#include <cstdint>
#include <vector>

namespace {

using covrast::detail::ConvexPolygon;

/// A `size` x `size` texture of pseudo-random linear codes (a fixed sequence).
std::shared_ptr<const covrast::Texture> noise_texture(int size, std::uint32_t seed) {
  std::vector<std::uint8_t> rgba(std::size_t(size * size * 4));
  std::uint32_t state = seed;
  for (std::uint8_t& code : rgba) {
    state = state * 1664525u + 1013904223u;
    code = std::uint8_t(state >> 24);
  }
  return covrast::make_texture("noise", size, size, rgba, false);
}

/// The parallelogram at `corner` (UV) with sides `a` and `b`.
ConvexPolygon parallelogram(glm::dvec2 corner, glm::dvec2 a, glm::dvec2 b) {
  ConvexPolygon p;
  p.add(corner.x, corner.y);
  p.add(corner.x + a.x, corner.y + a.y);
  p.add(corner.x + a.x + b.x, corner.y + a.y + b.y);
  p.add(corner.x + b.x, corner.y + b.y);
  return p;
}

}  // namespace

TEST_CASE("textures: area_average of LINEAR noise against a fine midpoint rule", "[textures]") {
  // The bilinear filter is continuous and piecewise bilinear: a 400 x 400 midpoint rule over a
  // parallelogram spanning a few texels is within 1e-4 of its exact mean.
  const auto texture = noise_texture(16, 7);
  covrast::TextureSampler sampler;
  sampler.mip = covrast::MipFilter::None;
  const glm::dvec2 corner(0.27, 0.61), a(0.11, 0.03), b(-0.02, 0.13);
  const auto mean =
      covrast::detail::area_average(*texture, sampler, parallelogram(corner, a, b), -1.0);
  REQUIRE(mean.has_value());
  constexpr int kSteps = 400;
  glm::dvec4 sum(0.0);
  for (int j = 0; j < kSteps; ++j) {
    for (int i = 0; i < kSteps; ++i) {
      const glm::dvec2 uv = corner + a * ((i + 0.5) / kSteps) + b * ((j + 0.5) / kSteps);
      sum += covrast::detail::sample_texture(*texture, sampler, uv, -1.0);
    }
  }
  sum /= double(kSteps * kSteps);
  for (int c = 0; c < 4; ++c) CHECK(std::abs((*mean)[c] - sum[c]) < 1e-4);
  // Not a constant: the check would hold for any mean of a flat texture.
  CHECK(std::abs((*mean).r - covrast::detail::sample_texture(*texture, sampler, corner, -1.0).r) >
        1e-3);
}
