// Tests of KHR_materials_transmission and KHR_materials_volume (docs/shading.md,
// "Transmission"): a transmissive sphere over a coloured background, every interior pixel in
// every mode against the extensions' formulas written out here from their specifications and
// the glTF Sample Viewer's thin-walled evaluation (not from covrast's code):
//   L   = ambient ((1 - F0) (1 - t) base + F0)
//       + E (n.l) [(1 - F) (1 - t) base / pi + F D V]                      (n.l > 0)
//       + E |n.l| (1 - F') t base D_T V_T (l', v)                          (n.l < 0)
//   out = alpha (L + filter background) + (1 - alpha) background,
//   filter = t base (1 - (F0 A_1 + (1 - F0) B_1)) attenuation^(thickness / distance)
// with l' = l mirrored through the surface, F' at h' = normalize(l' + v), the transmission
// lobe's alpha_T = alpha clamp(2 ior - 2, 0, 1), and A_1, B_1 the specular's directional
// albedo terms under uniform light, by this file's own quadrature.
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "test_extension_sphere.hpp"
#include "test_meshes.hpp"
#include "test_sphere_scene.hpp"

using covrast::Material;
using covrast::test::ggx_d;
using covrast::test::smith_v;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kSun = 2.0, kSky = 0.1;
const glm::dvec3 kBackground(0.05, 0.3, 0.6);

/// The specular's directional albedo terms at roughness r under uniform light, A_1(mu) =
/// int D V (n.l)+ dl and B_1(mu) = int s D V (n.l)+ dl with s = (1 - v.h)^5: a 1024 x 256
/// grid over the hemisphere (cos theta_l, phi over the half plane, doubled by symmetry) at 65
/// values of mu = n . v, linear between them.
struct SpecularAlbedo {
  explicit SpecularAlbedo(double r) {
    const double alpha = std::max(r * r, 1e-3);
    for (int i = 0; i <= 64; ++i) {
      const double mu = std::max(i / 64.0, 1e-3), sin_v = std::sqrt(1.0 - mu * mu);
      const glm::dvec3 v(sin_v, 0.0, mu);
      double a_sum = 0.0, b_sum = 0.0;
      for (int a = 0; a < 1024; ++a) {
        const double cos_l = (a + 0.5) / 1024.0, sin_l = std::sqrt(1.0 - cos_l * cos_l);
        for (int b = 0; b < 256; ++b) {
          const double phi = kPi * (b + 0.5) / 256.0;
          const glm::dvec3 l(sin_l * std::cos(phi), sin_l * std::sin(phi), cos_l);
          const glm::dvec3 h = glm::normalize(l + v);
          const double dv =
              ggx_d(alpha, h.z) * smith_v(alpha, cos_l, mu, glm::dot(h, l), glm::dot(h, v)) * cos_l;
          a_sum += dv;
          b_sum += dv * std::pow(1.0 - glm::dot(v, h), 5.0);
        }
      }
      const double cell = (1.0 / 1024.0) * (2.0 * kPi / 256.0);
      a1[std::size_t(i)] = a_sum * cell;
      b1[std::size_t(i)] = b_sum * cell;
    }
  }
  double albedo(double f0, double mu) const {
    const double x = std::clamp(mu, 0.0, 1.0) * 64.0;
    const auto i = std::size_t(std::min(int(x), 63));
    const double f = x - double(i);
    const double a = a1[i] + (a1[i + 1] - a1[i]) * f, b = b1[i] + (b1[i + 1] - b1[i]) * f;
    return f0 * a + (1.0 - f0) * b;
  }
  std::array<double, 65> a1{}, b1{};
};

struct Transmissive {
  const char* name;
  Material material;
  glm::dvec3 to_sun;  ///< unit, towards the sun
};

/// The formula of the file's comment for a dielectric (metallic 0) material.
glm::dvec3 expected(const Transmissive& c, const SpecularAlbedo& table, const glm::dvec3& base,
                    const glm::dvec3& n, const glm::dvec3& v) {
  const Material& m = c.material;
  const double t = m.transmission, ior = m.ior;
  const double f0 = ior == 1.5 ? 0.04 : std::pow((ior - 1.0) / (ior + 1.0), 2.0);
  const double alpha = std::max(double(m.roughness) * m.roughness, 1e-3);
  const glm::dvec3& l = c.to_sun;
  const double n_l = glm::dot(n, l), n_v = glm::dot(n, v);
  glm::dvec3 light = kSky * ((1.0 - f0) * (1.0 - t) * base + glm::dvec3(f0));
  if (n_l > 0.0) {
    const glm::dvec3 h = glm::normalize(l + v);
    const double fresnel = f0 + (1.0 - f0) * std::pow(1.0 - glm::dot(h, v), 5.0);
    const double dv =
        ggx_d(alpha, glm::dot(n, h)) * smith_v(alpha, n_l, n_v, glm::dot(h, l), glm::dot(h, v));
    light += kSun * n_l * ((1.0 - fresnel) * (1.0 - t) * base / kPi + glm::dvec3(fresnel * dv));
  } else {
    const glm::dvec3 mirrored = l - 2.0 * n_l * n;
    const glm::dvec3 h = glm::normalize(mirrored + v);
    const double fresnel = f0 + (1.0 - f0) * std::pow(1.0 - glm::dot(h, v), 5.0);
    const double alpha_t = std::max(alpha * std::clamp(2.0 * ior - 2.0, 0.0, 1.0), 1e-3);
    const double dv =
        ggx_d(alpha_t, glm::dot(n, h)) *
        smith_v(alpha_t, glm::dot(n, mirrored), n_v, glm::dot(h, mirrored), glm::dot(h, v));
    light += kSun * -n_l * (1.0 - fresnel) * t * base * dv;
  }
  glm::dvec3 filter = t * base * (1.0 - table.albedo(f0, n_v));
  if (m.attenuation_distance > 0.0f) {
    for (int k = 0; k < 3; ++k) {
      filter[k] *= std::pow(double(m.attenuation_color[k]), m.thickness / m.attenuation_distance);
    }
  }
  const double a = m.alpha_mode == covrast::AlphaMode::Blend ? m.base_alpha : 1.0;
  return a * (light + filter * kBackground) + (1.0 - a) * kBackground;
}

/// The single-sided lit sphere (its far side culled) over kBackground, sun and sky.
/// `rings`: the sphere's tessellation (lit_sphere_scene).
covrast::Scene transmissive_sphere(const glm::dvec3& base, const Transmissive& c, int rings = 96) {
  covrast::Scene scene =
      covrast::test::lit_sphere_scene(glm::vec3(base), c.material, {0.0, 0.0, 3.0}, rings);
  scene.background_linear = glm::vec3(kBackground);
  covrast::test::light_sun_and_sky(scene, -c.to_sun, kSun, kSky);
  return scene;
}

/// A single-sided pbr dielectric of `roughness` with `transmission`.
Material dielectric(float roughness, float transmission) {
  Material m;
  m.model = covrast::ShadingModel::Pbr;
  m.metallic = 0.0f;
  m.roughness = roughness;
  m.transmission = transmission;
  m.double_sided = false;
  return m;
}

}  // namespace

TEST_CASE("a transmissive sphere over a background matches the thin-walled formulas in every mode",
          "[shading][analytic][extensions][transparency]") {
  const glm::dvec3 front = glm::normalize(glm::dvec3(0.3, 0.4, 1.0));
  const glm::dvec3 behind = glm::normalize(glm::dvec3(-0.4, 0.5, -1.0));
  std::vector<Transmissive> cases;
  const auto add = [&](const char* name, const glm::dvec3& to_sun, auto set) {
    Material m = dielectric(0.5f, 0.0f);
    set(m);
    cases.push_back({name, m, to_sun});
  };
  add("transmission 0.8, lit from the front", front, [](Material& m) { m.transmission = 0.8f; });
  add("transmission 1, lit from behind, ior 1.3", behind, [](Material& m) {
    m.transmission = 1.0f;
    m.ior = 1.3f;
  });
  add("transmission 0.6 with a volume", front, [](Material& m) {
    m.transmission = 0.6f;
    m.thickness = 0.5f;
    m.attenuation_distance = 0.25f;
    m.attenuation_color = glm::vec3(0.9f, 0.5f, 0.2f);
  });
  add("transmission 1 in a BLEND material of alpha 0.5, lit from behind", behind, [](Material& m) {
    m.transmission = 1.0f;
    m.alpha_mode = covrast::AlphaMode::Blend;
    m.base_alpha = 0.5;
  });
  const SpecularAlbedo table(0.5);
  const glm::dvec3 base(0.9, 0.6, 0.3);
  for (const Transmissive& c : cases) {
    const covrast::Scene scene = transmissive_sphere(base, c);
    const auto formula = [&](const glm::dvec3& n, const glm::dvec3& v) {
      return expected(c, table, base, n, v);
    };
    for (const char* mode : {"coverage", "aliased", "msaa:4", "ssaa:4"}) {
      INFO(c.name << ", " << mode);
      // Aliased shades at the pixel centre: every interior pixel. The others where the formula
      // is smooth at the pixel's scale (worst_difference).
      const bool aliased = std::string(mode) == "aliased";
      int checked = 0;
      CHECK(covrast::test::worst_difference(covrast::test::render_mode(scene, mode), scene, formula,
                                            !aliased, checked) <= 1);
      CHECK(checked > (aliased ? 3000 : 1500));
    }
  }
}

TEST_CASE("transmission shows what is behind, and a metal transmits nothing",
          "[shading][extensions][transparency]") {
  const glm::dvec3 base(0.9, 0.6, 0.3);
  const Transmissive opaque{"opaque", dielectric(0.5f, 0.0f),
                            glm::normalize(glm::dvec3(0.3, 0.4, 1.0))};
  Transmissive clear = opaque;
  clear.material.transmission = 1.0f;
  Transmissive metal = clear;
  metal.material.metallic = 1.0f;
  Transmissive solid_metal = metal;
  solid_metal.material.transmission = 0.0f;
  const auto centre = [&](const Transmissive& c, const char* mode, const glm::vec3& background) {
    covrast::Scene scene = transmissive_sphere(base, c);
    scene.background_linear = background;
    const std::uint8_t* p = covrast::test::render_mode(scene, mode).pixel(48, 48);
    return std::array<int, 3>{p[0], p[1], p[2]};
  };
  const glm::vec3 dark(0.0f), light(0.0f, 0.5f, 1.0f);
  for (const char* mode : {"coverage", "aliased", "msaa:4"}) {
    INFO(mode);
    // The background shows through the transmissive sphere's middle, tinted by the base
    // colour: a brighter background brightens it; behind the opaque one it changes nothing.
    const std::array<int, 3> through_dark = centre(clear, mode, dark);
    const std::array<int, 3> through_light = centre(clear, mode, light);
    CHECK(through_dark[0] == through_light[0]);
    CHECK(through_light[1] > through_dark[1] + 20);
    CHECK(through_light[2] > through_dark[2] + 20);
    CHECK(centre(opaque, mode, dark) == centre(opaque, mode, light));
    // A metal transmits nothing (transmission replaces the dielectric's diffuse only): though
    // composited as a layer, its middle is the metal's without the extension, and hides the
    // background.
    CHECK(centre(metal, mode, dark) == centre(solid_metal, mode, dark));
    CHECK(centre(metal, mode, dark) == centre(metal, mode, light));
  }
}

TEST_CASE("through a transmissive surface only the opaque scene shows: one wall of a shell",
          "[shading][extensions][transparency]") {
  // The Sample Viewer's transmission: the nearest transmissive surface passes the opaque scene
  // behind it, not the other transparent layers. A double-sided sphere's far wall is behind
  // its near one everywhere, so it draws as the single-sided sphere, whose far wall is culled.
  const glm::dvec3 base(0.7, 0.9, 0.8);
  const Transmissive single{"single", dielectric(0.3f, 1.0f),
                            glm::normalize(glm::dvec3(0.3, 0.4, 1.0))};
  Transmissive shell = single;
  shell.material.double_sided = true;
  // A BLEND shell of the same surface, without transmission, shows both walls.
  Transmissive blend = shell;
  blend.material.transmission = 0.0f;
  blend.material.alpha_mode = covrast::AlphaMode::Blend;
  blend.material.base_alpha = 0.5;
  Transmissive blend_single = blend;
  blend_single.material.double_sided = false;
  for (const char* mode : {"coverage", "aliased", "msaa:4", "ssaa:4", "reference"}) {
    INFO(mode);
    const auto render = [&](const Transmissive& c) {
      // A coarse sphere, and a small image for the exact reference (4096 shaded samples a
      // pixel): the property holds for any closed shell at any size.
      covrast::Scene scene = transmissive_sphere(base, c, 12);
      if (std::string(mode) == "reference") scene.width = scene.height = 16;
      return covrast::test::render_mode(scene, mode);
    };
    CHECK(covrast::test::max_difference(render(shell), render(single)) <= 1);
    CHECK(covrast::test::max_difference(render(blend), render(blend_single)) > 10);
  }
}

TEST_CASE("a skybox shows through a tinted transmissive surface tinted, channel by channel",
          "[shading][extensions][background]") {
  // A uniform environment of radiance K as the skybox shows what the background colour K
  // shows (both light the sphere alike): the skybox is keyed from two renders per channel when
  // a transmissive surface tints what passes.
  const glm::vec3 sky(0.2f, 0.5f, 0.9f);
  auto map = std::make_shared<covrast::EnvironmentMap>();
  map->width = 64;
  map->height = 32;
  map->radiance_linear.assign(std::size_t(64 * 32), sky);
  const Transmissive clear{"clear", dielectric(0.5f, 1.0f),
                           glm::normalize(glm::dvec3(0.3, 0.4, 1.0))};
  covrast::Scene coloured = transmissive_sphere(glm::dvec3(0.9, 0.3, 0.1), clear);
  coloured.environment = covrast::EnvironmentLight{map, 0.0, 1.0};
  coloured.background_linear = sky;
  covrast::Scene skybox = coloured;
  skybox.background_kind = covrast::BackgroundKind::Skybox;
  for (const char* mode : {"coverage", "aliased"}) {
    INFO(mode);
    CHECK(covrast::test::max_difference(covrast::test::render_mode(coloured, mode),
                                        covrast::test::render_mode(skybox, mode)) <= 2);
  }
}
