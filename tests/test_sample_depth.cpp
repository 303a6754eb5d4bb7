// Tests of the coverage mode's per-sample depth test (src/raster/coverage/sample_depth.hpp):
// the formula on hand-made cases (nearer wins, a level plane keeps the earlier triangle, only
// owned samples change), and on every Highway target compiled and supported here the SIMD
// kernel gives the scalar twin's depths, primitives and won mask bit for bit, over random
// planes, masks and previous winners, with many samples exactly level with the plane.
#include "raster/coverage/sample_depth.hpp"

#include <catch2/catch.hpp>

#include "test_targets.hpp"

#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

namespace {

using covrast::detail::depth_test_samples;
using covrast::detail::depth_test_samples_scalar;
using covrast::detail::depth_test_samples_simd;
using covrast::detail::kMaskSamples;
using covrast::detail::kSampleOffsetX;
using covrast::detail::kSampleOffsetY;
using covrast::detail::PixelPlane;
using covrast::detail::SampleMask;

/// The plane's depth at sample s, as the contract writes it.
double plane_at(const PixelPlane& p, int s) {
  return p.z0 + p.dzdx * kSampleOffsetX[std::size_t(s)] + p.dzdy * kSampleOffsetY[std::size_t(s)];
}

struct SampleState {
  double z[kMaskSamples];
  std::uint64_t primitive[kMaskSamples];
};

/// Random previous winners; some samples hold exactly the plane's own depth (ties), some the
/// background (+inf, primitive 0).
SampleState random_state(std::mt19937& rng, const PixelPlane& plane) {
  std::uniform_real_distribution<double> depth(0.0, 1.0);
  std::uniform_int_distribution<int> kind(0, 5);
  std::uniform_int_distribution<std::uint64_t> id(0, 40);
  SampleState state;
  for (int s = 0; s < kMaskSamples; ++s) {
    const int k = kind(rng);
    state.z[s] = k == 0   ? std::numeric_limits<double>::infinity()
                 : k <= 2 ? plane_at(plane, s)
                          : depth(rng);
    state.primitive[s] = k == 0 ? 0 : id(rng);
  }
  return state;
}

SampleMask random_mask(std::mt19937& rng) {
  std::uniform_int_distribution<int> kind(0, 3);
  SampleMask mask;
  for (auto& word : mask.word) {
    // Empty, full, dense random, or a few samples (a sub-pixel triangle's sparse mask).
    const int k = kind(rng);
    const std::uint64_t random = (std::uint64_t(rng()) << 32) ^ rng();
    word = k == 0   ? 0
           : k == 1 ? ~std::uint64_t(0)
           : k == 2 ? random
                    : random & (random >> 7) & (random >> 13);
  }
  return mask;
}

}  // namespace

TEST_CASE("per-sample depth test: nearer wins, a level plane keeps the earlier triangle",
          "[sample_depth]") {
  // A flat plane at 0.5 against samples at 0.25 (nearer, kept), 0.75 (farther, taken) and
  // 0.5 with a later (taken) or an earlier (kept) primitive; only owned samples may change.
  const PixelPlane plane{0.5, 0.0, 0.0};
  SampleState state;
  for (int s = 0; s < kMaskSamples; ++s) {
    state.z[s] = s % 4 == 0 ? 0.25 : s % 4 == 1 ? 0.75 : 0.5;
    state.primitive[s] = s % 4 == 2 ? 9 : 3;
  }
  SampleMask owned = SampleMask::all();
  owned.word[3] = 0;  // samples 192..255 are not the triangle's
  const std::uint64_t primitive = 5;
  SampleState simd = state;
  const SampleMask won = depth_test_samples(plane, owned, primitive, simd.z, simd.primitive);
  for (int s = 0; s < kMaskSamples; ++s) {
    INFO("sample " << s);
    const bool expect = s < 192 && (s % 4 == 1 || s % 4 == 2);
    CHECK(won.has(s) == expect);
    CHECK(simd.z[s] == (expect ? 0.5 : state.z[s]));
    CHECK(simd.primitive[s] == (expect ? primitive : state.primitive[s]));
  }
}

TEST_CASE("per-sample depth test: every SIMD target matches the scalar twin bit for bit",
          "[sample_depth][simd]") {
  covrast::test::for_each_target([](std::int64_t) {
    std::mt19937 rng(20261202);
    std::uniform_real_distribution<double> depth(-0.1, 1.1), slope(-0.5, 0.5);
    std::uniform_int_distribution<std::uint64_t> id(0, 40);
    for (int round = 0; round < 20000; ++round) {
      const PixelPlane plane{depth(rng), round % 7 == 0 ? 0.0 : slope(rng), slope(rng)};
      const SampleMask owned = random_mask(rng);
      const std::uint64_t primitive = id(rng);
      SampleState scalar = random_state(rng, plane);
      SampleState simd = scalar, chosen = scalar;
      const SampleMask won_scalar =
          depth_test_samples_scalar(plane, owned, primitive, scalar.z, scalar.primitive);
      const SampleMask won_simd =
          depth_test_samples_simd(plane, owned, primitive, simd.z, simd.primitive);
      const SampleMask won_chosen =
          depth_test_samples(plane, owned, primitive, chosen.z, chosen.primitive);
      INFO("round " << round << ", " << owned.count() << " samples owned");
      REQUIRE(won_simd == won_scalar);
      REQUIRE(std::memcmp(simd.z, scalar.z, sizeof(simd.z)) == 0);
      REQUIRE(std::memcmp(simd.primitive, scalar.primitive, sizeof(simd.primitive)) == 0);
      REQUIRE(won_chosen == won_scalar);
      REQUIRE(std::memcmp(chosen.z, scalar.z, sizeof(chosen.z)) == 0);
    }
  });
}
