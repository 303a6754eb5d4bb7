// Analytic checks of blinn-phong and pbr (docs/shading.md) on a finely tessellated unit sphere
// with exact vertex normals, seen from (0, 0, 3): every interior pixel against the formula
// evaluated on the exact sphere at the pixel centre's ray.
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include "color/srgb8.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <vector>

#include "test_sphere_scene.hpp"

using covrast::Light;
using covrast::LightType;
using covrast::Material;
using covrast::Scene;
using covrast::ShadingModel;

namespace {

/// The sphere of test_sphere_scene.hpp lit by `lights`, seen from (0, 0, 3).
Scene sphere_scene(const glm::vec3& base, const Material& material, std::vector<Light> lights) {
  Scene scene = covrast::test::lit_sphere_scene(base, material);
  scene.lights = std::move(lights);
  return scene;
}

/// worst_sphere_difference of the scene rendered in `mode` on 2 threads.
int worst_difference(
    const Scene& scene, const char* mode,
    const std::function<glm::dvec3(const glm::dvec3&, const glm::dvec3&)>& expected, int& checked) {
  covrast::RenderOptions options;
  options.mode = covrast::parse_render_mode(mode);
  options.threads = 2;
  return covrast::test::worst_sphere_difference(covrast::render(scene, options).color, scene,
                                                expected, checked);
}

}  // namespace

TEST_CASE("blinn-phong on a sphere matches its formula at every interior pixel",
          "[shading][analytic]") {
  Material m;
  m.model = ShadingModel::BlinnPhong;
  m.shininess = 12.0f;
  m.specular_linear = glm::vec3(0.4f, 0.3f, 0.2f);
  m.emissive_linear = glm::vec3(0.02f, 0.0f, 0.0f);
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = glm::normalize(glm::dvec3(-0.3, -0.4, -1.0));
  sun.intensity = 0.9;
  Light sky;
  sky.type = LightType::Ambient;
  sky.intensity = 0.1;
  const glm::dvec3 base(0.6, 0.4, 0.3);
  const Scene scene = sphere_scene(glm::vec3(base), m, {sun, sky});
  const glm::dvec3 l = -sun.direction;
  // docs/shading.md: L = base (A + E (n.l)+) + [n.l > 0] specular E ((n.h)+)^s + emissive,
  // h = normalize(l + v).
  const auto formula = [&](const glm::dvec3& n, const glm::dvec3& v) {
    const double n_l = glm::dot(n, l);
    glm::dvec3 value = base * (0.1 + 0.9 * std::max(0.0, n_l)) + glm::dvec3(0.02, 0.0, 0.0);
    if (n_l > 0.0) {
      const glm::dvec3 h = glm::normalize(l + v);
      value += glm::dvec3(0.4, 0.3, 0.2) * 0.9 * std::pow(std::max(0.0, glm::dot(n, h)), 12.0);
    }
    return value;
  };
  for (const char* mode : {"coverage", "aliased", "msaa:4"}) {
    INFO(mode);
    int checked = 0;
    CHECK(worst_difference(scene, mode, formula, checked) <= 1);
    CHECK(checked > 3000);
  }
}

TEST_CASE("pbr under an ambient light alone is A ((1 - f0) c_diff + f0) everywhere",
          "[shading][analytic]") {
  Light sky;
  sky.type = LightType::Ambient;
  sky.color_linear = glm::vec3(1.0f, 0.9f, 0.8f);
  sky.intensity = 0.7;
  const glm::dvec3 base(0.8, 0.5, 0.2);
  for (const float metallic : {0.0f, 0.3f, 1.0f}) {
    Material m;
    m.model = ShadingModel::Pbr;
    m.metallic = metallic;
    m.roughness = 0.4f;
    m.emissive_linear = glm::vec3(0.0f, 0.0f, 0.05f);
    const Scene scene = sphere_scene(glm::vec3(base), m, {sky});
    // c_diff = base (1 - metallic), f0 = 0.04 (1 - metallic) + base metallic: no dependence on
    // n or v, so every pixel has the same code.
    const double md = metallic;
    const glm::dvec3 a = glm::dvec3(1.0, 0.9, 0.8) * 0.7;
    const glm::dvec3 c_diff = base * (1.0 - md);
    const glm::dvec3 f0 = glm::dvec3(0.04 * (1.0 - md)) + base * md;
    const glm::dvec3 value =
        a * ((glm::dvec3(1.0) - f0) * c_diff + f0) + glm::dvec3(0.0, 0.0, 0.05);
    for (const char* mode : {"coverage", "aliased"}) {
      INFO(mode << " metallic " << metallic);
      int checked = 0;
      CHECK(worst_difference(
                scene, mode, [&](const glm::dvec3&, const glm::dvec3&) { return value; },
                checked) == 0);
      CHECK(checked > 3000);
    }
  }
}
