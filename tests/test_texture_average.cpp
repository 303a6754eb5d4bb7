// The exact texture mean over a fragment (texture/texture_sampling.hpp, area_average) on
// texels of noise, against a brute-force integration of the LINEAR filter (test_textures.cpp
// checks it on ramps and single texels, where most of its terms are zero and skipped).
#include <covrast/scene.hpp>

#include "texture/level_cuts.hpp"
#include "texture/texture_sampling.hpp"

#include <catch2/catch.hpp>

#include <cstdint>
#include <cstring>
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

TEST_CASE("textures: shared level cuts give each texture the bits of its own", "[textures]") {
  // Textures of one size share the polygon's cuts on each level (texture/level_cuts.hpp); the
  // texels decide which pieces each needs, so a later texture asks for pieces an earlier one
  // skipped. Every mean must equal, bit for bit, the one cut for that texture alone.
  std::vector<std::uint8_t> banded(32 * 32 * 4);  // constant columns of 4: many zero terms
  for (std::size_t k = 0; k < banded.size(); ++k) banded[k] = std::uint8_t((k / 16 % 8) * 30);
  const std::vector<std::shared_ptr<const covrast::Texture>> textures = {
      covrast::make_texture("banded", 32, 32, banded, false), noise_texture(32, 1),
      noise_texture(32, 2), noise_texture(16, 3)};
  covrast::TextureSampler linear, nearest;
  linear.mip = covrast::MipFilter::Linear;
  nearest.min = nearest.mag = covrast::TextureFilter::Nearest;
  nearest.mip = covrast::MipFilter::Linear;
  std::vector<ConvexPolygon> polygons;
  std::uint32_t state = 11;
  const auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / double(1 << 24);
  };
  for (int k = 0; k < 40; ++k) {
    const glm::dvec2 corner(next(), next());
    const glm::dvec2 a(0.02 + 0.06 * next(), 0.03 * (next() - 0.5));
    const glm::dvec2 b(0.03 * (next() - 0.5), 0.02 + 0.06 * next());
    ConvexPolygon p = parallelogram(corner, a, b);
    if (k % 2 == 1) p.n = 3;  // a triangle: the parallelogram's first three corners
    polygons.push_back(p);
  }
  covrast::detail::LevelCutsMemo memo;
  int compared = 0;
  // Every polygon twice, the second time long after its cuts were dropped.
  for (int pass = 0; pass < 2; ++pass) {
    for (const ConvexPolygon& p : polygons) {
      for (const auto* sampler : {&linear, &nearest}) {
        for (const auto& texture : textures) {
          const double lod = 0.6;  // levels 0 and 1, blended
          const auto alone = covrast::detail::area_average(*texture, *sampler, p, lod);
          const auto shared = covrast::detail::area_average(*texture, *sampler, p, lod, &memo);
          REQUIRE(alone.has_value() == shared.has_value());
          if (!alone) continue;
          for (int c = 0; c < 4; ++c) {
            const double x = (*alone)[c], y = (*shared)[c];
            REQUIRE(std::memcmp(&x, &y, sizeof x) == 0);
          }
          ++compared;
        }
      }
    }
  }
  CHECK(compared == 2 * 40 * 2 * 4);
  // Per polygon and filter: the 32 x 32 textures' levels (32 and 16 texels wide) are cut by
  // the first and found by the next two; the 16 x 16 texture finds its level 0 (16 wide) and
  // cuts its level 1 (8 wide). Forty polygons later each pass starts anew.
  CHECK(memo.misses() == 2 * 40 * 2 * 3);
  CHECK(memo.hits() == 2 * 40 * 2 * (2 + 2 + 1));
}
