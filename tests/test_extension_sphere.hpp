// The material tests' formulas and their comparison with a rendered lit sphere
// (test_material_extensions.cpp, test_transmission.cpp): the glTF BRDF's GGX terms written out
// from the specification, and the worst code difference over the sphere's interior.
#pragma once

#include <covrast/image.hpp>
#include <covrast/scene.hpp>

#include "color/srgb8.hpp"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>

namespace covrast::test {

/// GGX D and the height-correlated Smith V of glTF Appendix B.3.5, written out.
inline double ggx_d(double alpha, double n_h) {
  if (!(n_h > 0.0)) return 0.0;
  const double a2 = alpha * alpha;
  return a2 / (std::numbers::pi * std::pow(n_h * n_h * (a2 - 1.0) + 1.0, 2.0));
}
inline double smith_v(double alpha, double n_l, double n_v, double h_l, double h_v) {
  if (!(h_l > 0.0 && h_v > 0.0)) return 0.0;
  const double a2 = alpha * alpha;
  const auto g = [&](double x) { return std::abs(x) + std::sqrt(a2 + (1.0 - a2) * x * x); };
  return 1.0 / (g(n_l) * g(n_v));
}

/// Lights `scene` with a directional sun of `sun` lux travelling along `direction` and an
/// ambient sky of radiance `sky`, replacing its lights.
inline void light_sun_and_sky(covrast::Scene& scene, const glm::dvec3& direction, double sun,
                              double sky) {
  covrast::Light sun_light;
  sun_light.type = covrast::LightType::Directional;
  sun_light.direction = direction;
  sun_light.intensity = sun;
  covrast::Light sky_light;
  sky_light.type = covrast::LightType::Ambient;
  sky_light.intensity = sky;
  scene.lights = {sun_light, sky_light};
}

/// The 8-bit codes of `expected(n, v)` at image point (x, y) of the sphere seen from (0, 0, 3)
/// (as test_sphere_scene.hpp's worst_sphere_difference), or false off the interior.
inline bool formula_codes(
    const covrast::Scene& scene, double x, double y,
    const std::function<glm::dvec3(const glm::dvec3&, const glm::dvec3&)>& expected, int codes[3]) {
  const double t = std::tan(scene.camera.fovy_deg * std::numbers::pi / 360.0);
  const glm::dvec3 d = glm::normalize(
      glm::dvec3((2.0 * x / scene.width - 1.0) * t, (1.0 - 2.0 * y / scene.height) * t, -1.0));
  const glm::dvec3 o = scene.camera.eye;
  const double b = glm::dot(o, d), disc = b * b - (glm::dot(o, o) - 1.0);
  if (disc <= 0.0) return false;
  const glm::dvec3 n = o + (-b - std::sqrt(disc)) * d;
  if (glm::dot(n, -d) < 0.3) return false;
  const glm::dvec3 value = expected(n, -d);
  for (int c = 0; c < 3; ++c) codes[c] = covrast::detail::encode_srgb8(float(value[c]));
  return true;
}

/// The largest difference between `image` and the formula at the pixel centres of the interior.
/// With `smooth_only`, only over the pixels where the formula changes by at most one code
/// within 0.75 pixel of the centre: coverage and msaa shade each triangle of a pixel at the
/// centre clamped into it, up to 0.7 pixel away, so where the formula is steeper (a sharp
/// highlight) they differ from the centre's value by what the formula changes over that
/// distance, not by an error of the material.
inline int worst_difference(
    const covrast::Image& image, const covrast::Scene& scene,
    const std::function<glm::dvec3(const glm::dvec3&, const glm::dvec3&)>& expected,
    bool smooth_only, int& checked) {
  int worst = 0;
  checked = 0;
  for (int y = 0; y < scene.height; ++y) {
    for (int x = 0; x < scene.width; ++x) {
      int centre[3];
      if (!formula_codes(scene, x + 0.5, y + 0.5, expected, centre)) continue;
      bool smooth = true;
      for (int k = 0; smooth_only && smooth && k < 4; ++k) {
        int near[3];
        smooth = formula_codes(scene, x + 0.5 + (k & 1 ? 0.75 : -0.75),
                               y + 0.5 + (k & 2 ? 0.75 : -0.75), expected, near);
        for (int c = 0; smooth && c < 3; ++c) smooth = std::abs(near[c] - centre[c]) <= 1;
      }
      if (!smooth) continue;
      const std::uint8_t* p = image.pixel(x, y);
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int(p[c]) - centre[c]));
      ++checked;
    }
  }
  return worst;
}

}  // namespace covrast::test
