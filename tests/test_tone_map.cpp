// Tone mapping and exposure (color/tone_map.hpp, docs/shading.md): each operator against its
// published formula written out again here, known values, and what it does to a frame.
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include "color/srgb8.hpp"
#include "color/tone_map.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "test_meshes.hpp"

using covrast::ToneMap;
using covrast::detail::tone_map;
using covrast::detail::ToneMapping;

namespace {

/// Khronos PBR Neutral, from KhronosGroup/ToneMapping PBR_Neutral's GLSL, per colour.
glm::dvec3 neutral_reference(glm::dvec3 color) {
  const double start = 0.8 - 0.04, desaturation = 0.15;
  const double x = std::min(color.r, std::min(color.g, color.b));
  const double offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
  color -= glm::dvec3(offset);
  const double peak = std::max(color.r, std::max(color.g, color.b));
  if (peak < start) return color;
  const double d = 1.0 - start;
  const double new_peak = 1.0 - d * d / (peak + d - start);
  color *= new_peak / peak;
  const double g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
  return glm::mix(color, glm::dvec3(new_peak), g);
}

/// Hill's ACES fit (BakingLab ACES.hlsl): ACESInputMat, RRTAndODTFit, ACESOutputMat, saturate.
glm::dvec3 hill_reference(const glm::dvec3& c) {
  const double in[3][3] = {
      {0.59719, 0.35458, 0.04823}, {0.07600, 0.90834, 0.01566}, {0.02840, 0.13383, 0.83777}};
  const double out[3][3] = {
      {1.60475, -0.53108, -0.07367}, {-0.10208, 1.10813, -0.00605}, {-0.00327, -0.07276, 1.07602}};
  double v[3], f[3];
  for (int r = 0; r < 3; ++r) v[r] = in[r][0] * c.r + in[r][1] * c.g + in[r][2] * c.b;
  for (int r = 0; r < 3; ++r) {
    const double a = v[r] * (v[r] + 0.0245786) - 0.000090537;
    const double b = v[r] * (0.983729 * v[r] + 0.4329510) + 0.238081;
    f[r] = a / b;
  }
  glm::dvec3 result;
  for (int r = 0; r < 3; ++r) {
    result[r] = std::clamp(out[r][0] * f[0] + out[r][1] * f[1] + out[r][2] * f[2], 0.0, 1.0);
  }
  return result;
}

double narkowicz_reference(double x) {
  const double a = 2.51, b = 0.03, c = 2.43, d = 0.59, e = 0.14;
  return std::clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.0, 1.0);
}

}  // namespace

TEST_CASE("tone map: every operator follows its published formula on a ramp", "[tonemap]") {
  for (int i = 0; i <= 320; ++i) {
    const double x = i / 20.0;  // 0 .. 16
    // Coloured too: channels at different levels.
    const glm::dvec3 c(x, 0.5 * x, 0.1 + 0.25 * x);
    for (const double exposure : {1.0, 0.5, 2.0}) {
      INFO("x " << x << ", exposure " << exposure);
      const glm::dvec3 e = c * exposure;
      const glm::dvec3 neutral = tone_map({ToneMap::KhronosPbrNeutral, exposure}, c);
      const glm::dvec3 hill = tone_map({ToneMap::AcesHill, exposure}, c);
      const glm::dvec3 nark = tone_map({ToneMap::AcesNarkowicz, exposure}, c);
      const glm::dvec3 none = tone_map({ToneMap::None, exposure}, c);
      for (int k = 0; k < 3; ++k) {
        CHECK(neutral[k] == Approx(neutral_reference(e)[k]).margin(1e-12));
        CHECK(hill[k] == Approx(hill_reference(e)[k]).margin(1e-12));
        CHECK(nark[k] == Approx(narkowicz_reference(e[k])).margin(1e-12));
        CHECK(none[k] == e[k]);
      }
    }
  }
}

TEST_CASE("tone map: known values", "[tonemap]") {
  const ToneMapping neutral{ToneMap::KhronosPbrNeutral, 1.0};
  CHECK(tone_map(neutral, glm::dvec3(0.0)) == glm::dvec3(0.0));
  // Grey 0.5: only the 0.04 offset (below the compression start).
  CHECK(tone_map(neutral, glm::dvec3(0.5)).r == Approx(0.46).margin(1e-15));
  // Grey 1: peak 0.96 -> 1 - 0.24^2 / 0.44, then no desaturation of a grey.
  CHECK(tone_map(neutral, glm::dvec3(1.0)).r == Approx(1.0 - 0.0576 / 0.44).margin(1e-12));
  // Never reaches 1, however bright.
  CHECK(tone_map(neutral, glm::dvec3(1e6)).r < 1.0);
  const ToneMapping nark{ToneMap::AcesNarkowicz, 1.0};
  CHECK(tone_map(nark, glm::dvec3(1.0)).r == Approx(2.54 / 3.16).margin(1e-15));
  CHECK(tone_map(nark, glm::dvec3(100.0)).r == 1.0);
  CHECK(tone_map({ToneMap::AcesHill, 1.0}, glm::dvec3(0.0)) == glm::dvec3(0.0));
  CHECK(ToneMapping{}.is_identity());
  CHECK_FALSE((ToneMapping{ToneMap::None, 2.0}.is_identity()));
}

TEST_CASE("tone map: names", "[tonemap]") {
  for (const covrast::ToneMap t : {covrast::ToneMap::None, covrast::ToneMap::KhronosPbrNeutral,
                                   covrast::ToneMap::AcesHill, covrast::ToneMap::AcesNarkowicz}) {
    CHECK(covrast::parse_tone_map(covrast::to_string(t)) == t);
  }
  CHECK_THROWS_WITH(covrast::parse_tone_map("filmic"),
                    Catch::Matchers::Contains("unknown tone map 'filmic' (expected none, "));
}

namespace {

/// A 32 x 32 scene of one square filling the middle, colour `color` (unlit) or lit by a
/// directional light of `intensity` facing it.
covrast::Scene square_scene(const glm::vec3& color, bool lit, double intensity) {
  covrast::Scene scene;
  scene.width = scene.height = 32;
  scene.background_linear = glm::vec3(0.2f, 0.3f, 0.4f);
  auto mesh = covrast::make_mesh(
      {.positions = {{-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0}},
       .indices = {0, 1, 2, 0, 2, 3}});
  covrast::test::add_instance(scene, mesh, color);
  if (lit) {
    covrast::Light sun;
    sun.direction = {0.0, 0.0, -1.0};
    sun.intensity = intensity;
    covrast::Material m;
    m.model = covrast::ShadingModel::Lambert;
    scene.meshes[0].materials = {m};
    scene.lit = true;
    scene.lights = {sun};
  }
  return scene;
}

covrast::Image render(const covrast::Scene& scene) {
  covrast::RenderOptions options;
  options.threads = 2;
  return covrast::render(scene, options).color;
}

int code(double linear) { return covrast::detail::encode_srgb8(float(linear)); }

}  // namespace

TEST_CASE("tone map: frames", "[tonemap]") {
  // None at exposure 1 is the frame of before, byte for byte.
  covrast::Scene plain = square_scene(glm::vec3(0.3f, 0.6f, 0.9f), false, 1.0);
  covrast::Scene none = plain;
  none.tone_map = covrast::ToneMap::None;
  CHECK(render(none).rgb == render(plain).rgb);
  // Exposure scales unlit colours, not the background (a display colour, as a clear colour).
  covrast::Scene doubled = plain;
  doubled.exposure = 2.0;
  const covrast::Image image = render(doubled);
  CHECK(int(image.pixel(16, 16)[0]) == code(0.6f));
  CHECK(int(image.pixel(0, 0)[2]) == code(0.4f));
  // A lit square at 3x the light clips without a tone map and not with khronos-pbr-neutral:
  // its pixel is the operator of the lambert radiance 3 x base.
  covrast::Scene bright = square_scene(glm::vec3(0.8f, 0.5f, 0.3f), true, 3.0);
  CHECK(int(render(bright).pixel(16, 16)[0]) == 255);
  bright.tone_map = covrast::ToneMap::KhronosPbrNeutral;
  const covrast::Image mapped = render(bright);
  const glm::dvec3 want = neutral_reference(3.0 * glm::dvec3(glm::vec3(0.8f, 0.5f, 0.3f)));
  for (int c = 0; c < 3; ++c) {
    CHECK(std::abs(int(mapped.pixel(16, 16)[c]) - code(want[c])) <= 1);
    CHECK(int(mapped.pixel(16, 16)[c]) < 255);
  }
  CHECK(int(mapped.pixel(0, 0)[1]) == code(0.3f));
}
