// Tests of the glTF material extensions covrast honours (docs/shading.md, "Material
// extensions"): KHR_materials_ior, _specular, _clearcoat, _sheen, _iridescence and _anisotropy.
// - On the lit sphere of test_sphere_scene.hpp, every interior pixel in three modes against the
//   extensions' formulas written out here from their specifications (not from covrast's code).
// - The coat under the environment, the suns and the ambient light: the layering identity.
// - The glTF reader: the fields and textures, neutral values drawing the bytes of a file
//   without the extensions, and each wrong value an error naming its JSON path.
#include <covrast/error.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include "shading/environment_lighting.hpp"
#include "shading/shading_inputs.hpp"
#include "shading/sheen.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "test_extension_sphere.hpp"
#include "test_gltf_files.hpp"
#include "test_sphere_scene.hpp"
#include "test_tempdir.hpp"

using Catch::Matchers::Contains;
using covrast::Light;
using covrast::LightType;
using covrast::Material;
using covrast::ShadingModel;
using covrast::test::ggx_d;
using covrast::test::smith_v;
using covrast::test::worst_difference;

namespace {

constexpr double kPi = std::numbers::pi;

/// KHR_materials_sheen's lobe D V, written out from the extension's implementation notes
/// ("Charlie" distribution and visibility, Conty Estevez and Kulla 2017).
double charlie_lobe(double r, double n_l, double n_v, double n_h) {
  if (!(n_l > 0.0 && n_v > 0.0)) return 0.0;
  const double alpha = std::max(r * r, 1e-3);
  const double d = (2.0 + 1.0 / alpha) * std::pow(1.0 - n_h * n_h, 0.5 / alpha) / (2.0 * kPi);
  const double t = (1.0 - alpha) * (1.0 - alpha);
  const auto l = [&](double x) {
    const double a = 21.5473 + (25.3245 - 21.5473) * t, b = 3.82987 + (3.32435 - 3.82987) * t;
    const double c = 0.19823 + (0.16801 - 0.19823) * t, dd = -1.97760 + (-1.27393 + 1.97760) * t;
    const double e = -4.32054 + (-4.85967 + 4.32054) * t;
    return a / (1.0 + b * std::pow(x, c)) + dd * x + e;
  };
  const auto lambda = [&](double x) {
    return x < 0.5 ? std::exp(l(x)) : std::exp(2.0 * l(0.5) - l(1.0 - x));
  };
  return d / ((1.0 + lambda(n_v) + lambda(n_l)) * (4.0 * n_v * n_l));
}

/// The sheen's directional albedo E(mu) = int D V (n.l)+ dl at roughness r, by its own
/// quadrature (256 x 128 cells of the hemisphere) at 129 values of mu, linear between them.
struct SheenAlbedo {
  explicit SheenAlbedo(double r) : roughness(r) {
    for (int i = 0; i <= 128; ++i) {
      const double mu = std::max(i / 128.0, 1e-4), sin_v = std::sqrt(1.0 - mu * mu);
      double sum = 0.0;
      for (int a = 0; a < 256; ++a) {
        const double cos_l = (a + 0.5) / 256.0, sin_l = std::sqrt(1.0 - cos_l * cos_l);
        for (int b = 0; b < 128; ++b) {
          const double phi = kPi * (b + 0.5) / 128.0;
          const glm::dvec3 l(sin_l * std::cos(phi), sin_l * std::sin(phi), cos_l);
          const glm::dvec3 h = glm::normalize(l + glm::dvec3(sin_v, 0.0, mu));
          sum += charlie_lobe(r, cos_l, mu, h.z) * cos_l;
        }
      }
      table[std::size_t(i)] = sum * (1.0 / 256.0) * (2.0 * kPi / 128.0);
    }
  }
  double operator()(double mu) const {
    const double x = std::clamp(mu, 0.0, 1.0) * 128.0;
    const int i = std::min(int(x), 127);
    return table[std::size_t(i)] + (table[std::size_t(i) + 1] - table[std::size_t(i)]) * (x - i);
  }
  double roughness;
  std::array<double, 129> table{};
};

/// KHR_materials_iridescence's thin-film Fresnel term, written out from the extension's
/// implementation notes (Belcour and Barla 2017; OPD with cos theta2, as the extension's
/// current text and the Khronos viewers have it).
glm::dvec3 thin_film(double film_ior, const glm::dvec3& base_f0, double thickness, double cos1) {
  const auto f0_of = [](double t, double i) { return std::pow((t - i) / (t + i), 2.0); };
  const auto schlick = [](double f0, double c) { return f0 + (1.0 - f0) * std::pow(1.0 - c, 5.0); };
  const double sin2 = std::pow(1.0 / film_ior, 2.0) * (1.0 - cos1 * cos1);
  if (1.0 - sin2 < 0.0) return glm::dvec3(1.0);
  const double cos2 = std::sqrt(1.0 - sin2);
  const double r12 = schlick(f0_of(film_ior, 1.0), cos1), t121 = 1.0 - r12;
  const double phi21 = kPi - (film_ior < 1.0 ? kPi : 0.0);
  const double opd = 2.0 * film_ior * thickness * cos2;
  glm::dvec3 out;
  for (int c = 0; c < 3; ++c) {
    const double sq = std::sqrt(std::clamp(base_f0[c], 0.0, 0.9999));
    const double base_ior = (1.0 + sq) / (1.0 - sq);
    const double r23 = schlick(f0_of(base_ior, film_ior), cos2);
    const double phi = phi21 + (base_ior < film_ior ? kPi : 0.0);
    const double r123 = std::clamp(r12 * r23, 1e-5, 0.9999);
    const double rs = t121 * t121 * r23 / (1.0 - r123);
    double value = r12 + rs, cm = rs - t121;
    for (int m = 1; m <= 2; ++m) {
      cm *= std::sqrt(r123);
      // The sensitivity in XYZ (Gaussian fits), then its row of XYZ -> linear Rec. 709.
      const double ph = 2.0 * kPi * (m * opd) * 1e-9, shift = m * phi;
      const double val[3] = {5.4856e-13, 4.4201e-13, 5.2481e-13};
      const double pos[3] = {1.6810e+06, 1.7953e+06, 2.2084e+06};
      const double var[3] = {4.3278e+09, 9.3046e+09, 6.6121e+09};
      double xyz[3];
      for (int k = 0; k < 3; ++k) {
        xyz[k] = val[k] * std::sqrt(2.0 * kPi * var[k]) * std::cos(pos[k] * ph + shift) *
                 std::exp(-ph * ph * var[k]);
      }
      xyz[0] += 9.7470e-14 * std::sqrt(2.0 * kPi * 4.5282e+09) * std::cos(2.2399e+06 * ph + shift) *
                std::exp(-4.5282e+09 * ph * ph);
      for (double& x : xyz) x /= 1.0685e-7;
      const double rows[3][3] = {{3.2404542, -1.5371385, -0.4985314},
                                 {-0.9692660, 1.8760108, 0.0415560},
                                 {0.0556434, -0.2040259, 1.0572252}};
      const double rgb = rows[c][0] * xyz[0] + rows[c][1] * xyz[1] + rows[c][2] * xyz[2];
      value += cm * 2.0 * rgb;
    }
    out[c] = std::max(value, 0.0);
  }
  return out;
}

/// KHR_materials_anisotropy's D V, from the extension's D_GGX_anisotropic and
/// V_GGX_anisotropic: the direction t is the sphere's tangent T = normalize(Y x n)
/// (sphere_tangents) turned by the rotation towards B = n x T, b = n x t,
///   alpha_t = mix(alpha, 1, strength^2), alpha_b = alpha, a = alpha_t alpha_b,
///   D = a (a / |f|^2)^2 / pi,  f = (alpha_b t.h, alpha_t b.h, a n.h),
///   V = min(0.5 / (n.l |(alpha_t t.v, alpha_b b.v, n.v)| + n.v |(alpha_t t.l, alpha_b b.l,
///       n.l)|), 1).
double anisotropic_dv(const Material& m, const glm::dvec3& n, const glm::dvec3& v,
                      const glm::dvec3& l, const glm::dvec3& h) {
  const glm::dvec3 tangent = glm::normalize(glm::cross(glm::dvec3(0.0, 1.0, 0.0), n));
  const glm::dvec3 bitangent = glm::cross(n, tangent);
  const double rotation = m.anisotropy_rotation;
  const glm::dvec3 t = tangent * std::cos(rotation) + bitangent * std::sin(rotation);
  const glm::dvec3 b = glm::cross(n, t);
  const double alpha = std::max(double(m.roughness) * m.roughness, 1e-3);
  const double strength2 = double(m.anisotropy) * m.anisotropy;
  const double at = alpha * (1.0 - strength2) + strength2, ab = alpha, a = at * ab;
  const glm::dvec3 f(ab * glm::dot(t, h), at * glm::dot(b, h), a * glm::dot(n, h));
  const double w2 = a / glm::dot(f, f);
  const double d = a * w2 * w2 / kPi;
  const double n_l = glm::dot(n, l), n_v = glm::dot(n, v);
  const double ggx_v = n_l * glm::length(glm::dvec3(at * glm::dot(t, v), ab * glm::dot(b, v), n_v));
  const double ggx_l = n_v * glm::length(glm::dvec3(at * glm::dot(t, l), ab * glm::dot(b, l), n_l));
  return d * std::min(0.5 / (ggx_v + ggx_l), 1.0);
}

/// The lit sphere's sun and sky.
const glm::dvec3 kSunDirection = glm::normalize(glm::dvec3(-0.3, -0.4, -1.0));
constexpr double kSun = 2.0, kSky = 0.1;

/// The material of `m` (metallic 0 or 1) with base colour `base`, under kSun from
/// -kSunDirection and the ambient kSky, at normal n and view v, from the specifications:
///   KHR_materials_ior       f0 = ((ior - 1) / (ior + 1))^2
///   KHR_materials_specular  F0_d = min(f0 x specularColor, 1) x specular, F90_d = specular,
///                           dielectric = (1 - max(F_d)) base / pi + F_d D V,
///                           F_d = F0_d + (F90_d - F0_d) (1 - |v.h|)^5
///   core                    f = (1 - metallic) dielectric + metallic (base + (1 - base) s) D V
///   KHR_materials_clearcoat L = L_base (1 - clearcoat Fc) + clearcoat Fc L_coat,
///                           Fc = 0.04 + 0.96 (1 - |n.v|)^5, L_coat with the coat's D V
/// with covrast's ambient convention (ambient x the normal-incidence albedo; 1 for the coat's
/// lobe) and the emission under the coat.
glm::dvec3 extended_pbr(const Material& m, const glm::dvec3& base, const glm::dvec3& n,
                        const glm::dvec3& v) {
  const glm::dvec3 l = -kSunDirection;
  const glm::dvec3 h = glm::normalize(l + v);
  const double n_l = glm::dot(n, l), n_v = glm::dot(n, v), n_h = glm::dot(n, h);
  const double h_l = glm::dot(h, l), h_v = glm::dot(h, v);
  const double s = std::pow(1.0 - std::abs(h_v), 5.0);
  const double ior = m.ior;
  const double f0 = ior == 1.5 ? 0.04 : std::pow((ior - 1.0) / (ior + 1.0), 2.0);
  const double spec = m.specular_factor, metallic = m.metallic;
  glm::dvec3 f0_d, f_d;
  for (int c = 0; c < 3; ++c) {
    f0_d[c] = std::min(f0 * m.specular_color_factor[c], 1.0) * spec;
    f_d[c] = f0_d[c] + (spec - f0_d[c]) * s;
  }
  const double max_f0_d = std::max({f0_d.r, f0_d.g, f0_d.b});
  const double alpha = std::max(double(m.roughness) * m.roughness, 1e-3);
  const double dv = m.anisotropy > 0.0f && n_l > 0.0
                        ? anisotropic_dv(m, n, v, l, h)
                        : ggx_d(alpha, n_h) * smith_v(alpha, n_l, n_v, h_l, h_v);
  // KHR_materials_iridescence: dielectric = rgb_mix(diffuse, specular, mix(F_d, Ir_d, k)),
  // metal = specular x mix(F_m, Ir_m, k), Ir at n . v over F0_d and over the base.
  const double k = m.iridescence;
  const glm::dvec3 ir_d =
      k > 0.0 ? thin_film(m.iridescence_ior, f0_d, m.iridescence_thickness_max_nm, std::abs(n_v))
              : glm::dvec3(0.0);
  const glm::dvec3 ir_m =
      k > 0.0 ? thin_film(m.iridescence_ior, base, m.iridescence_thickness_max_nm, std::abs(n_v))
              : glm::dvec3(0.0);
  glm::dvec3 mix_d, mix_m;
  for (int c = 0; c < 3; ++c) {
    mix_d[c] = f_d[c] * (1.0 - k) + ir_d[c] * k;
    mix_m[c] = (base[c] + (1.0 - base[c]) * s) * (1.0 - k) + ir_m[c] * k;
  }
  const double max_mix_d = std::max({mix_d.r, mix_d.g, mix_d.b});
  const double max_ir_d = std::max({ir_d.r, ir_d.g, ir_d.b});
  glm::dvec3 out;
  for (int c = 0; c < 3; ++c) {
    const double dielectric = (1.0 - max_mix_d) * base[c] / kPi + mix_d[c] * dv;
    const double metal = mix_m[c] * dv;
    const double f = (1.0 - metallic) * dielectric + metallic * metal;
    // The ambient light: the normal-incidence albedo, with the film's term at n . v.
    const double f0_c = (f0_d[c] * (1.0 - k) + ir_d[c] * k) * (1.0 - metallic) +
                        (base[c] * (1.0 - k) + ir_m[c] * k) * metallic;
    const double diffuse_weight = 1.0 - (max_f0_d * (1.0 - k) + max_ir_d * k);
    const double ambient = kSky * (diffuse_weight * base[c] * (1.0 - metallic) + f0_c);
    out[c] = ambient + kSun * std::max(0.0, n_l) * f + m.emissive_linear[c];
  }
  if (m.sheen_color_factor != glm::vec3(0.0f)) {
    // KHR_materials_sheen: f = f_sheen + f_base (1 - max(sheenColor) E(n.v)), the ambient
    // light and the base alike; the emission is not under the sheen.
    static std::vector<SheenAlbedo> albedos;
    auto it = std::find_if(albedos.begin(), albedos.end(), [&](const SheenAlbedo& a) {
      return a.roughness == double(m.sheen_roughness);
    });
    if (it == albedos.end()) it = albedos.insert(albedos.end(), SheenAlbedo(m.sheen_roughness));
    const double albedo = (*it)(n_v);
    const glm::dvec3 sheen(m.sheen_color_factor);
    const double scaling = 1.0 - std::max({sheen.r, sheen.g, sheen.b}) * albedo;
    const glm::dvec3 emissive(m.emissive_linear);
    const double lobe = charlie_lobe(m.sheen_roughness, n_l, n_v, n_h);
    out = (out - emissive) * scaling + sheen * (kSky * albedo + kSun * std::max(0.0, n_l) * lobe) +
          emissive;
  }
  if (m.clearcoat > 0.0f) {
    const double fc = 0.04 + 0.96 * std::pow(1.0 - std::abs(n_v), 5.0);
    const double coat_alpha = std::max(double(m.clearcoat_roughness) * m.clearcoat_roughness, 1e-3);
    const double coat_dv = ggx_d(coat_alpha, n_h) * smith_v(coat_alpha, n_l, n_v, h_l, h_v);
    const double coat = kSky + kSun * std::max(0.0, n_l) * coat_dv;
    const double w = m.clearcoat * fc;
    out = out * (1.0 - w) + glm::dvec3(coat * w);
  }
  return out;
}

/// The sphere's tangents at its corners, T = normalize(Y x p) (along the parallels, w = 1;
/// (1, 0, 0) at the poles, which no interior pixel sees).
void sphere_tangents(covrast::Scene& scene) {
  auto mesh = std::make_shared<covrast::MeshData>(*scene.meshes.at(0).mesh);
  mesh->corner_tangents.clear();
  for (const std::uint32_t i : mesh->indices) {
    const glm::dvec3 p(mesh->positions[i]);
    const glm::dvec3 t = glm::cross(glm::dvec3(0.0, 1.0, 0.0), p);
    const double length = glm::length(t);
    mesh->corner_tangents.push_back(length > 1e-9 ? glm::vec4(glm::vec3(t / length), 1.0f)
                                                  : glm::vec4(1, 0, 0, 1));
  }
  scene.meshes[0].mesh = mesh;
}

/// The lit sphere with `m`, sun and sky, and tangents.
covrast::Scene extension_sphere(const glm::dvec3& base, const Material& m) {
  covrast::Scene scene = covrast::test::lit_sphere_scene(glm::vec3(base), m);
  sphere_tangents(scene);
  covrast::test::light_sun_and_sky(scene, kSunDirection, kSun, kSky);
  return scene;
}

}  // namespace

TEST_CASE("ior specular clearcoat sheen iridescence anisotropy on a lit sphere match formulas",
          "[shading][analytic][extensions]") {
  struct Case {
    const char* name;
    Material material;
  };
  std::vector<Case> cases;
  const auto add = [&](const char* name, auto set) {
    Material m;
    m.model = covrast::ShadingModel::Pbr;
    m.metallic = 0.0f;
    m.roughness = 0.5f;
    set(m);
    cases.push_back({name, m});
  };
  add("ior 1.8", [](Material& m) { m.ior = 1.8f; });
  add("ior 0 (f0 = 1)", [](Material& m) { m.ior = 0.0f; });
  add("specular 0.4, coloured", [](Material& m) {
    m.specular_factor = 0.4f;
    m.specular_color_factor = glm::vec3(1.0f, 0.5f, 2.0f);
  });
  add("specular colour clamped, ior 3", [](Material& m) {
    m.ior = 3.0f;
    m.specular_color_factor = glm::vec3(8.0f, 1.0f, 0.0f);
  });
  add("metal: specular changes nothing", [](Material& m) {
    m.metallic = 1.0f;
    m.specular_factor = 0.3f;
    m.specular_color_factor = glm::vec3(2.0f, 1.0f, 0.5f);
  });
  add("clearcoat 1, smooth coat", [](Material& m) {
    m.roughness = 0.6f;
    m.clearcoat = 1.0f;
    m.clearcoat_roughness = 0.1f;
  });
  add("clearcoat 0.5 over ior, specular and emission", [](Material& m) {
    m.clearcoat = 0.5f;
    m.clearcoat_roughness = 0.3f;
    m.ior = 1.4f;
    m.specular_factor = 0.7f;
    m.emissive_linear = glm::vec3(0.05f, 0.0f, 0.02f);
  });
  add("clearcoat over a metal", [](Material& m) {
    m.metallic = 1.0f;
    m.roughness = 0.35f;
    m.clearcoat = 0.8f;
    m.clearcoat_roughness = 0.05f;
  });
  add("sheen, fabric-like", [](Material& m) {
    m.roughness = 0.8f;
    m.sheen_color_factor = glm::vec3(0.9f, 0.6f, 0.3f);
    m.sheen_roughness = 0.6f;
  });
  add("sheen under a clear coat, with emission", [](Material& m) {
    m.sheen_color_factor = glm::vec3(0.3f, 0.3f, 1.0f);
    m.sheen_roughness = 0.2f;
    m.clearcoat = 0.6f;
    m.clearcoat_roughness = 0.25f;
    m.emissive_linear = glm::vec3(0.0f, 0.03f, 0.0f);
  });
  add("iridescence over a dielectric", [](Material& m) {
    m.iridescence = 1.0f;
    m.iridescence_thickness_max_nm = 380.0f;
  });
  add("iridescence 0.6 over a metal, film ior 1.8", [](Material& m) {
    m.metallic = 1.0f;
    m.roughness = 0.4f;
    m.iridescence = 0.6f;
    m.iridescence_ior = 1.8f;
    m.iridescence_thickness_max_nm = 250.0f;
  });
  add("anisotropy 0.8 along the tangent", [](Material& m) {
    m.roughness = 0.45f;
    m.anisotropy = 0.8f;
  });
  add("anisotropy 0.5 over a metal, turned by 1 radian", [](Material& m) {
    m.metallic = 1.0f;
    m.roughness = 0.35f;
    m.anisotropy = 0.5f;
    m.anisotropy_rotation = 1.0f;
  });
  add("anisotropy 1 turned a quarter turn, under a clear coat", [](Material& m) {
    m.roughness = 0.3f;
    m.anisotropy = 1.0f;
    m.anisotropy_rotation = float(kPi / 2.0);
    m.clearcoat = 0.5f;
    m.clearcoat_roughness = 0.2f;
  });
  const glm::dvec3 base(0.6, 0.3, 0.2);
  for (const Case& c : cases) {
    const covrast::Scene scene = extension_sphere(base, c.material);
    const auto formula = [&](const glm::dvec3& n, const glm::dvec3& v) {
      return extended_pbr(c.material, base, n, v);
    };
    for (const char* mode : {"coverage", "aliased", "msaa:4"}) {
      INFO(c.name << ", " << mode);
      // Aliased shades at the pixel centre: every interior pixel. The others: where the
      // formula is smooth at the pixel's scale (worst_difference).
      const bool aliased = std::string(mode) == "aliased";
      int checked = 0;
      CHECK(worst_difference(covrast::test::render_mode(scene, mode), scene, formula, !aliased,
                             checked) <= 1);
      CHECK(checked > (aliased ? 3000 : 1500));
    }
  }
}

TEST_CASE("the clear coat under the environment with its suns and the ambient light",
          "[shading][extensions][environment]") {
  // fresnel_coat: coated = base x (1 - c Fc) + c Fc x coat, and the coat's lobe alone (D V, no
  // Fresnel, albedo 1 under the ambient light) is what a white metal (F = 1) of the coat's
  // roughness reflects: so the coated material is the two uncoated ones mixed, at every normal,
  // view and coat normal, under every kind of light at once.
  using namespace covrast::detail;
  // The studio environment with one texel bright enough to be lit as a sun.
  auto map = std::make_shared<covrast::EnvironmentMap>(*covrast::studio_environment());
  map->radiance_linear[std::size_t(map->height / 4) * map->width + map->width / 3] =
      glm::vec3(5000.0f);
  const covrast::EnvironmentLight light{map, 30.0, 1.0};
  const EnvironmentLighting lighting(light);
  REQUIRE_FALSE(lighting.suns().empty());
  ShadingContext context;
  context.environment = &lighting;
  context.ambient = glm::dvec3(0.05, 0.04, 0.03);
  PunctualLight sun;
  sun.to_light = glm::normalize(glm::dvec3(0.2, 0.9, 0.4));
  sun.radiance = glm::dvec3(1.5);
  context.lights = {sun};
  SurfaceShading coated;
  coated.model = ShadingModel::Pbr;
  coated.metallic = 0.2;
  coated.roughness = 0.55;
  coated.occlusion = 0.8;
  coated.emissive = glm::dvec3(0.02, 0.01, 0.0);
  coated.context = &context;
  coated.clearcoat = 0.7;
  coated.clearcoat_roughness = 0.15;
  SurfaceShading uncoated = coated;
  uncoated.clearcoat = 0.0;
  SurfaceShading lobe = coated;
  lobe.clearcoat = 0.0;
  lobe.metallic = 1.0;
  lobe.roughness = coated.clearcoat_roughness;
  lobe.emissive = glm::dvec3(0.0);
  const glm::dvec3 base(0.7, 0.2, 0.1), white(1.0);
  int compared = 0, coat_shows = 0;
  for (int k = 0; k < 24; ++k) {
    const double z = 1.0 - (k + 0.5) / 12.0, phi = 2.399963 * k;
    const glm::dvec3 n(std::sqrt(1.0 - z * z) * std::cos(phi), z,
                       std::sqrt(1.0 - z * z) * std::sin(phi));
    const glm::dvec3 v = glm::normalize(n + glm::dvec3(0.3 * std::sin(k), 0.2, 0.3 * std::cos(k)));
    const glm::dvec3 coat_normal = glm::normalize(n + glm::dvec3(0.1, -0.05, 0.08) * double(k % 3));
    context.eye_world = v * 4.0;
    const double fc = 0.04 + 0.96 * std::pow(1.0 - std::abs(glm::dot(coat_normal, v)), 5.0);
    const double w = coated.clearcoat * fc;
    const glm::dvec3 want =
        shade_point(uncoated, base, glm::dvec3(0.0), n, coat_normal) * (1.0 - w) +
        shade_point(lobe, white, glm::dvec3(0.0), coat_normal) * w;
    const glm::dvec3 got = shade_point(coated, base, glm::dvec3(0.0), n, coat_normal);
    INFO("normal " << k);
    for (int c = 0; c < 3; ++c) CHECK(got[c] == Approx(want[c]).epsilon(1e-12));
    // The coat is there: it changes the colour by more than rounding (not where the view
    // meets the coat's light at no angle worth a reflection: a few of the 24).
    const glm::dvec3 bare = shade_point(uncoated, base, glm::dvec3(0.0), n, coat_normal);
    coat_shows += std::abs(got.r - bare.r) > 1e-3;
    ++compared;
  }
  CHECK(compared == 24);
  CHECK(coat_shows >= 18);
}

namespace {

/// A unit sphere (24 x 48 quads) as a glTF file with exact normals, UVs and one material whose
/// "extensions" are `extensions` (null: none), plus one 2x2 PNG texture the extensions may use.
std::string sphere_gltf(const nlohmann::json& extensions) {
  const auto sphere = covrast::test::uv_sphere(24, 48);
  std::vector<float> positions, uvs;
  for (const glm::vec3& p : sphere->positions) {
    positions.insert(positions.end(), {p.x, p.y, p.z});
    uvs.insert(uvs.end(), {0.5f + 0.5f * p.x, 0.5f - 0.5f * p.y});
  }
  std::vector<std::uint16_t> indices(sphere->indices.begin(), sphere->indices.end());
  REQUIRE(sphere->positions.size() < 65536);
  covrast::test::GltfBuilder b;
  const int pos = b.add_floats(positions, "VEC3");
  const int normal = b.add_floats(positions, "VEC3");
  const int uv = b.add_floats(uvs, "VEC2");
  const int index = b.add_u16(indices, "SCALAR");
  b.single_mesh({{{"attributes", {{"POSITION", pos}, {"NORMAL", normal}, {"TEXCOORD_0", uv}}},
                  {"indices", index},
                  {"material", 0}}});
  nlohmann::json material = {{"pbrMetallicRoughness",
                              {{"baseColorFactor", {0.6, 0.3, 0.2, 1.0}},
                               {"metallicFactor", 0.0},
                               {"roughnessFactor", 0.5}}}};
  if (!extensions.is_null()) material["extensions"] = extensions;
  b.gltf["materials"] = nlohmann::json::array({material});
  covrast::Image texel;
  texel.width = texel.height = 2;
  texel.rgb = {200, 100, 50, 200, 100, 50, 200, 100, 50, 200, 100, 50};
  const std::vector<std::uint8_t> png = covrast::encode_png(texel);
  const int view = b.add_view(std::string(png.begin(), png.end()));
  b.gltf["images"] = {{{"bufferView", view}, {"mimeType", "image/png"}}};
  b.gltf["textures"] = {{{"source", 0}}};
  return b.glb();
}

/// The file lit by a sun, the sky and the studio environment, seen from (0, 0, 3), 64 x 64.
covrast::Image render_lit(const std::filesystem::path& file, const char* mode) {
  covrast::Scene scene = covrast::load_mesh_scene(file, 64, 64);
  scene.camera.eye = {0.0, 0.0, 3.0};
  scene.camera.target = {0.0, 0.0, 0.0};
  scene.camera.up = {0.0, 1.0, 0.0};
  scene.camera.fovy_deg = 40.0;
  scene.camera.near = 0.5;
  scene.camera.far = 10.0;
  scene.lit = true;
  Light sun;
  sun.direction = kSunDirection;
  sun.intensity = kSun;
  scene.lights = {sun};
  scene.environment = covrast::EnvironmentLight{covrast::studio_environment(), 0.0, 0.5};
  return covrast::test::render_mode(scene, mode);
}

}  // namespace

TEST_CASE("glTF material extensions at their neutral values draw today's bytes",
          "[gltf][extensions]") {
  covrast::test::TempDir dir("covrast-material-extensions");
  std::ofstream(dir / "plain.glb", std::ios::binary) << sphere_gltf(nullptr);
  const nlohmann::json neutral = {
      {"KHR_materials_ior", {{"ior", 1.5}}},
      {"KHR_materials_specular", {{"specularFactor", 1.0}, {"specularColorFactor", {1, 1, 1}}}},
      {"KHR_materials_clearcoat", {{"clearcoatFactor", 0.0}, {"clearcoatRoughnessFactor", 0.4}}},
      {"KHR_materials_sheen", {{"sheenColorFactor", {0, 0, 0}}, {"sheenRoughnessFactor", 0.5}}},
      {"KHR_materials_iridescence", {{"iridescenceFactor", 0.0}, {"iridescenceIor", 1.6}}},
      {"KHR_materials_anisotropy", {{"anisotropyStrength", 0.0}, {"anisotropyRotation", 0.7}}},
      {"KHR_materials_transmission", {{"transmissionFactor", 0.0}}},
      {"KHR_materials_volume",
       {{"thicknessFactor", 0.5}, {"attenuationDistance", 0.2}, {"attenuationColor", {1, 0, 0}}}},
      {"KHR_materials_dispersion", {{"dispersion", 0.3}}}};
  std::ofstream(dir / "neutral.glb", std::ios::binary) << sphere_gltf(neutral);
  nlohmann::json coated = neutral;
  coated["KHR_materials_clearcoat"]["clearcoatFactor"] = 1.0;
  std::ofstream(dir / "coated.glb", std::ios::binary) << sphere_gltf(coated);
  nlohmann::json clear = neutral;
  clear["KHR_materials_transmission"]["transmissionFactor"] = 1.0;
  std::ofstream(dir / "clear.glb", std::ios::binary) << sphere_gltf(clear);
  for (const char* mode : {"coverage", "aliased", "msaa:4"}) {
    INFO(mode);
    const covrast::Image plain = render_lit(dir / "plain.glb", mode);
    CHECK((render_lit(dir / "neutral.glb", mode).rgb == plain.rgb));
    CHECK((render_lit(dir / "coated.glb", mode).rgb != plain.rgb));
    CHECK((render_lit(dir / "clear.glb", mode).rgb != plain.rgb));
  }
}

TEST_CASE("glTF material extensions: fields and textures read and wrong values named by path",
          "[gltf][extensions]") {
  covrast::test::TempDir dir("covrast-material-extensions");
  const nlohmann::json all = {
      {"KHR_materials_ior", {{"ior", 1.33}}},
      {"KHR_materials_specular",
       {{"specularFactor", 0.25},
        {"specularColorFactor", {2.0, 1.0, 0.5}},
        {"specularTexture", {{"index", 0}}},
        {"specularColorTexture", {{"index", 0}, {"texCoord", 0}}}}},
      {"KHR_materials_clearcoat",
       {{"clearcoatFactor", 0.75},
        {"clearcoatRoughnessFactor", 0.125},
        {"clearcoatTexture", {{"index", 0}}},
        {"clearcoatRoughnessTexture", {{"index", 0}}},
        {"clearcoatNormalTexture", {{"index", 0}, {"scale", 0.5}}}}},
      {"KHR_materials_sheen",
       {{"sheenColorFactor", {0.5, 0.25, 1.0}},
        {"sheenRoughnessFactor", 0.75},
        {"sheenColorTexture", {{"index", 0}}},
        {"sheenRoughnessTexture", {{"index", 0}}}}},
      {"KHR_materials_iridescence",
       {{"iridescenceFactor", 0.5},
        {"iridescenceIor", 1.75},
        {"iridescenceThicknessMinimum", 150.0},
        {"iridescenceThicknessMaximum", 650.0},
        {"iridescenceTexture", {{"index", 0}}},
        {"iridescenceThicknessTexture", {{"index", 0}}}}},
      {"KHR_materials_anisotropy",
       {{"anisotropyStrength", 0.625},
        {"anisotropyRotation", -2.5},
        {"anisotropyTexture", {{"index", 0}}}}},
      {"KHR_materials_transmission",
       {{"transmissionFactor", 0.375}, {"transmissionTexture", {{"index", 0}}}}},
      {"KHR_materials_volume",
       {{"thicknessFactor", 2.5},
        {"thicknessTexture", {{"index", 0}}},
        {"attenuationDistance", 0.75},
        {"attenuationColor", {0.5, 0.25, 1.0}}}},
      {"KHR_materials_dispersion", {{"dispersion", 0.125}}}};
  std::ofstream(dir / "all.glb", std::ios::binary) << sphere_gltf(all);
  const covrast::Scene scene = covrast::load_mesh_scene(dir / "all.glb", 32, 32);
  for (const std::string& warning : scene.warnings)
    CHECK(warning.find("KHR_materials") == std::string::npos);
  const Material& m = scene.meshes.at(0).mesh->materials.at(0);
  CHECK(m.ior == 1.33f);
  CHECK(m.specular_factor == 0.25f);
  CHECK(m.specular_color_factor == glm::vec3(2.0f, 1.0f, 0.5f));
  CHECK(m.clearcoat == 0.75f);
  CHECK(m.clearcoat_roughness == 0.125f);
  REQUIRE(m.specular_texture.texture);
  CHECK_FALSE(m.specular_texture.texture->srgb);
  REQUIRE(m.specular_color_texture.texture);
  CHECK(m.specular_color_texture.texture->srgb);  // specularColorTexture is sRGB
  REQUIRE(m.clearcoat_texture.texture);
  REQUIRE(m.clearcoat_roughness_texture.texture);
  REQUIRE(m.clearcoat_normal_texture.texture);
  CHECK(m.clearcoat_normal_texture.scale == 0.5f);
  CHECK(m.sheen_color_factor == glm::vec3(0.5f, 0.25f, 1.0f));
  CHECK(m.sheen_roughness == 0.75f);
  REQUIRE(m.sheen_color_texture.texture);
  CHECK(m.sheen_color_texture.texture->srgb);  // sheenColorTexture is sRGB
  REQUIRE(m.sheen_roughness_texture.texture);
  CHECK(m.iridescence == 0.5f);
  CHECK(m.iridescence_ior == 1.75f);
  CHECK(m.iridescence_thickness_min_nm == 150.0f);
  CHECK(m.iridescence_thickness_max_nm == 650.0f);
  REQUIRE(m.iridescence_texture.texture);
  REQUIRE(m.iridescence_thickness_texture.texture);
  CHECK(m.anisotropy == 0.625f);
  CHECK(m.anisotropy_rotation == -2.5f);
  REQUIRE(m.anisotropy_texture.texture);
  CHECK_FALSE(m.anisotropy_texture.texture->srgb);
  CHECK(m.transmission == 0.375f);
  REQUIRE(m.transmission_texture.texture);
  CHECK_FALSE(m.transmission_texture.texture->srgb);
  CHECK(m.thickness == 2.5f);
  REQUIRE(m.thickness_texture.texture);
  CHECK(m.attenuation_distance == 0.75f);
  CHECK(m.attenuation_color == glm::vec3(0.5f, 0.25f, 1.0f));
  CHECK(m.dispersion == 0.125f);
  // The textured coat draws: the coat texture's R (200/255) scales clearcoatFactor, so it
  // differs from the same file without the coat texture.
  nlohmann::json untextured = all;
  untextured["KHR_materials_clearcoat"].erase("clearcoatTexture");
  std::ofstream(dir / "untextured.glb", std::ios::binary) << sphere_gltf(untextured);
  CHECK((render_lit(dir / "all.glb", "aliased").rgb !=
         render_lit(dir / "untextured.glb", "aliased").rgb));

  struct Bad {
    nlohmann::json extensions;
    std::string message;
  };
  const std::string path = "materials[0].extensions.";
  const std::vector<Bad> bad = {
      {{{"KHR_materials_clearcoat", {{"clearcoatFactor", "1"}}}},
       path + "KHR_materials_clearcoat.clearcoatFactor: expected a number in 0..1"},
      {{{"KHR_materials_clearcoat", {{"clearcoatRoughnessFactor", 1.5}}}},
       path + "KHR_materials_clearcoat.clearcoatRoughnessFactor: expected a number in 0..1"},
      {{{"KHR_materials_clearcoat", {{"clearcoatTexture", {{"index", 7}}}}}},
       path + "KHR_materials_clearcoat.clearcoatTexture.index: expected the index of one of the "
              "file's 1 textures"},
      {{{"KHR_materials_clearcoat", {{"clearcoatNormalTexture", {{"index", 0}, {"texCoord", 3}}}}}},
       path + "KHR_materials_clearcoat.clearcoatNormalTexture.texCoord: expected 0 or 1"},
      {{{"KHR_materials_clearcoat", {{"clearcoatNormalTexture", {{"index", 0}, {"scale", "x"}}}}}},
       path + "KHR_materials_clearcoat.clearcoatNormalTexture.scale: expected a number"},
      {{{"KHR_materials_clearcoat", {{"clearcoatTexture", -1}}}},
       path + "KHR_materials_clearcoat.clearcoatTexture: expected a textureInfo object"},
      {{{"KHR_materials_clearcoat", 1}},
       path + "KHR_materials_clearcoat: expected an object, got 1"},
      {{{"KHR_materials_sheen", {{"sheenColorFactor", {1, 2, 0}}}}},
       path + "KHR_materials_sheen.sheenColorFactor: expected an array of 3 numbers in 0..1"},
      {{{"KHR_materials_sheen", {{"sheenRoughnessFactor", "rough"}}}},
       path + "KHR_materials_sheen.sheenRoughnessFactor: expected a number in 0..1"},
      {{{"KHR_materials_iridescence", {{"iridescenceIor", 0.5}}}},
       path + "KHR_materials_iridescence.iridescenceIor: expected a number in 1.."},
      {{{"KHR_materials_iridescence", {{"iridescenceThicknessMaximum", -1}}}},
       path + "KHR_materials_iridescence.iridescenceThicknessMaximum: expected a number in 0.."},
      {{{"KHR_materials_iridescence", {{"iridescenceFactor", {1}}}}},
       path + "KHR_materials_iridescence.iridescenceFactor: expected a number in 0..1"},
      {{{"KHR_materials_anisotropy", {{"anisotropyStrength", 1.5}}}},
       path + "KHR_materials_anisotropy.anisotropyStrength: expected a number in 0..1"},
      {{{"KHR_materials_anisotropy", {{"anisotropyRotation", "1"}}}},
       path + "KHR_materials_anisotropy.anisotropyRotation: expected a number in"},
      {{{"KHR_materials_anisotropy", {{"anisotropyTexture", -1}}}},
       path + "KHR_materials_anisotropy.anisotropyTexture: expected a textureInfo object"},
      {{{"KHR_materials_transmission", {{"transmissionFactor", 1.5}}}},
       path + "KHR_materials_transmission.transmissionFactor: expected a number in 0..1"},
      {{{"KHR_materials_transmission", {{"transmissionTexture", -1}}}},
       path + "KHR_materials_transmission.transmissionTexture: expected a textureInfo object"},
      {{{"KHR_materials_volume", {{"thicknessFactor", -1}}}},
       path + "KHR_materials_volume.thicknessFactor: expected a number in 0.."},
      {{{"KHR_materials_volume", {{"attenuationDistance", 0}}}},
       path + "KHR_materials_volume.attenuationDistance: expected a number > 0"},
      {{{"KHR_materials_volume", {{"attenuationColor", {1, 1}}}}},
       path + "KHR_materials_volume.attenuationColor: expected an array of 3 numbers in 0..1"},
      {{{"KHR_materials_dispersion", {{"dispersion", "lots"}}}},
       path + "KHR_materials_dispersion.dispersion: expected a number in 0.."},
      {{{"KHR_materials_ior", {{"ior", 0.5}}}},
       path + "KHR_materials_ior.ior: expected 0 or a number >= 1"},
      {{{"KHR_materials_ior", {{"ior", "1.5"}}}},
       path + "KHR_materials_ior.ior: expected 0 or a number >= 1"},
      {{{"KHR_materials_specular", {{"specularFactor", -0.1}}}},
       path + "KHR_materials_specular.specularFactor: expected a number in 0..1"},
      {{{"KHR_materials_specular", {{"specularColorFactor", {1, 2}}}}},
       path + "KHR_materials_specular.specularColorFactor: expected an array of 3 numbers >= 0"},
      {{{"KHR_materials_specular", {{"specularColorFactor", {1, -2, 0}}}}},
       path + "KHR_materials_specular.specularColorFactor: expected an array of 3 numbers >= 0"},
  };
  for (const Bad& b : bad) {
    INFO(b.extensions.dump());
    std::ofstream(dir / "bad.glb", std::ios::binary) << sphere_gltf(b.extensions);
    CHECK_THROWS_AS(covrast::load_mesh(dir / "bad.glb"), covrast::InputError);
    CHECK_THROWS_WITH(covrast::load_mesh(dir / "bad.glb"), Contains(b.message));
  }
}

TEST_CASE("a scene's material keys set the extensions' fields on any mesh", "[scene][extensions]") {
  covrast::test::TempDir dir("covrast-material-keys");
  std::ofstream(dir / "t.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(dir / "s.json") << R"({"width": 8, "height": 8,
      "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fovy_deg": 40,
                 "near": 0.1, "far": 10},
      "lights": [{"type": "ambient"}],
      "meshes": [{"obj": "t.obj", "material": {"model": "pbr", "ior": 0, "specular_factor": 0.5,
                  "clearcoat": 1, "clearcoat_roughness": 0.25, "sheen_color": [1, 0.5, 0],
                  "sheen_roughness": 0.5, "iridescence": 0.25, "iridescence_ior": 1.5,
                  "iridescence_thickness_nm": 500, "anisotropy": 0.75,
                  "anisotropy_rotation_deg": -90, "transmission": 0.5, "thickness": 0.25,
                  "attenuation_color": [1, 0.5, 0], "attenuation_distance": 2}}]})";
  const covrast::Scene scene = covrast::load_scene(dir / "s.json");
  const Material& m = scene.meshes.at(0).materials.at(0);
  CHECK(m.ior == 0.0f);
  CHECK(m.specular_factor == 0.5f);
  CHECK(m.clearcoat == 1.0f);
  CHECK(m.clearcoat_roughness == 0.25f);
  CHECK(m.sheen_color_factor.r == 1.0f);  // sRGB, as every colour of a scene file
  CHECK(m.sheen_color_factor.g == Approx(0.214).epsilon(0.01));
  CHECK(m.sheen_roughness == 0.5f);
  CHECK(m.iridescence == 0.25f);
  CHECK(m.iridescence_ior == 1.5f);
  CHECK(m.iridescence_thickness_max_nm == 500.0f);
  CHECK(m.anisotropy == 0.75f);
  CHECK(m.anisotropy_rotation == float(-kPi / 2.0));
  CHECK(m.transmission == 0.5f);
  CHECK(m.thickness == 0.25f);
  CHECK(m.attenuation_color.g == Approx(0.214).epsilon(0.01));  // sRGB
  CHECK(m.attenuation_distance == 2.0f);
  // The OBJ has neither tangents nor UVs: no tangent frame, said once.
  REQUIRE(scene.warnings.size() == 1);
  CHECK_THAT(scene.warnings[0], Contains("meshes[0]: anisotropy needs a tangent frame"));
}

TEST_CASE("the sheen under the studio environment against quadrature over its texels",
          "[shading][extensions][environment]") {
  // covrast lights the sheen by the environment's cosine-weighted mean radiance E(n) / pi times
  // the lobe's albedo (docs/shading.md): exact for a uniform environment, an approximation of
  // int D V L (n.l) dl elsewhere. Measured here against the sum over the map's texels, on the
  // studio environment (its bright panels make the lobe's shape matter), the sheen part alone
  // (the render with the sheen minus the scaled render without it).
  using namespace covrast::detail;
  const covrast::EnvironmentLight light{covrast::studio_environment(), 30.0, 1.0};
  const EnvironmentLighting lighting(light);
  ShadingContext context;
  context.environment = &lighting;
  SurfaceShading with;
  with.model = ShadingModel::Pbr;
  with.metallic = 0.0;
  with.roughness = 0.7;
  with.context = &context;
  with.sheen_color = glm::dvec3(1.0);
  SurfaceShading without = with;
  without.sheen_color = glm::dvec3(0.0);
  const glm::dvec3 base(0.2, 0.3, 0.4);
  double worst = 0.0, sum_squares = 0.0, sum_want = 0.0, sum_want_squares = 0.0;
  int count = 0;
  for (const double r : {0.3, 0.6, 1.0}) {
    with.sheen_roughness = r;
    for (int k = 0; k < 24; ++k) {
      const double z = 1.0 - (k + 0.5) / 12.0, phi = 2.399963 * k;
      const glm::dvec3 n(std::sqrt(1.0 - z * z) * std::cos(phi), z,
                         std::sqrt(1.0 - z * z) * std::sin(phi));
      const glm::dvec3 v =
          glm::normalize(n + glm::dvec3(0.4 * std::sin(k), 0.3, 0.4 * std::cos(k)) * double(k % 3));
      context.eye_world = v * 4.0;
      const double scaling = 1.0 - sheen_albedo(glm::dot(n, v), r);
      const glm::dvec3 got = shade_point(with, base, glm::dvec3(0.0), n) -
                             shade_point(without, base, glm::dvec3(0.0), n) * scaling;
      const double c = std::cos(kPi / 6.0), s = std::sin(kPi / 6.0);
      glm::dvec3 want(0.0);
      covrast::test::for_each_texel(
          *light.map, [&](const glm::dvec3& d, double omega, const glm::dvec3& radiance) {
            const glm::dvec3 l(d.x * c + d.z * s, d.y, -d.x * s + d.z * c);
            const double n_l = glm::dot(n, l);
            if (!(n_l > 0.0)) return;
            want += radiance * (sheen_lobe(n, v, l, r) * n_l * omega);
          });
      INFO("normal " << k << ", sheen roughness " << r);
      REQUIRE(std::isfinite(got.r + got.g + got.b + want.r + want.g + want.b));
      for (int ch = 0; ch < 3; ++ch) {
        worst = std::max(worst, std::abs(got[ch] - want[ch]));
        sum_squares += (got[ch] - want[ch]) * (got[ch] - want[ch]);
        sum_want += want[ch];
        sum_want_squares += want[ch] * want[ch];
        ++count;
      }
    }
  }
  const double rms = std::sqrt(sum_squares / count), mean = sum_want / count;
  // Drawing no sheen at all (the extension ignored) would be off by the sheen itself.
  const double rms_without = std::sqrt(sum_want_squares / count);
  INFO("sheen under the studio: worst " << worst << ", rms " << rms << ", mean sheen " << mean
                                        << ", rms of the sheen " << rms_without);
  // Measured (2026-12-04): worst 0.072, rms 0.019, the sheen's own rms 0.127.
  CHECK(worst < 0.09);
  CHECK(rms < 0.025);
  CHECK(rms < 0.25 * rms_without);
}

TEST_CASE("anisotropy's texture gives its direction and strength in the tangent frame",
          "[gltf][extensions]") {
  // sphere_gltf's texture holds (200, 100, 50) (linear): direction (2 x 200/255 - 1,
  // 2 x 100/255 - 1) in the frame the UVs give (no TANGENT), strength x 50/255. The same file
  // without the texture, with that direction as its rotation and that strength as its factor,
  // draws the same pixels; turned back to the tangent it does not.
  covrast::test::TempDir dir("covrast-anisotropy-texture");
  const double dx = 2.0 * 200.0 / 255.0 - 1.0, dy = 2.0 * 100.0 / 255.0 - 1.0;
  const auto file = [&](const char* name, double strength, double rotation, bool textured) {
    nlohmann::json e = {{"anisotropyStrength", strength}, {"anisotropyRotation", rotation}};
    if (textured) e["anisotropyTexture"] = {{"index", 0}};
    std::ofstream(dir / name, std::ios::binary) << sphere_gltf({{"KHR_materials_anisotropy", e}});
    return dir / name;
  };
  const auto textured = file("textured.glb", 0.9, 0.0, true);
  const auto turned = file("turned.glb", 0.9 * 50.0 / 255.0, std::atan2(dy, dx), false);
  const auto along_tangent = file("tangent.glb", 0.9 * 50.0 / 255.0, 0.0, false);
  for (const char* mode : {"aliased", "coverage"}) {
    INFO(mode);
    const covrast::Image a = render_lit(textured, mode), b = render_lit(turned, mode);
    REQUIRE(a.rgb.size() == b.rgb.size());
    int worst = 0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i)
      worst = std::max(worst, std::abs(a.rgb[i] - b.rgb[i]));
    CHECK(worst <= 1);
    CHECK((render_lit(along_tangent, mode).rgb != a.rgb));
  }
}

TEST_CASE("anisotropy under the environment reads it about the bent normal",
          "[shading][extensions][environment]") {
  // The environment's specular part with the prefiltered radiance read about the bent normal
  // of the glTF Sample Viewer and Filament, written out here: with b = n x t,
  //   n_a = (b x v) x b,  bend = (1 - strength (1 - roughness))^4,
  //   n_bent = normalize(mix(n_a, n, bend)),
  // and for a metal (c_diff = 0, F0 = base) L = F0 A + (1 - F0) B with A, B read there.
  using namespace covrast::detail;
  const covrast::EnvironmentLight light{covrast::studio_environment(), 20.0, 1.0};
  const EnvironmentLighting lighting(light);
  REQUIRE(lighting.suns().empty());
  ShadingContext context;
  context.environment = &lighting;
  SurfaceShading s;
  s.model = ShadingModel::Pbr;
  s.metallic = 1.0;  // a metal: F0 = base, no diffuse, so the specular is all there is
  s.roughness = 0.3;
  s.context = &context;
  s.anisotropy = 0.7;
  SurfaceShading isotropic = s;
  isotropic.anisotropy = 0.0;
  const glm::dvec3 base(0.9, 0.7, 0.5);
  int bent_shows = 0;
  for (int k = 0; k < 24; ++k) {
    const double z = 1.0 - (k + 0.5) / 12.0, phi = 2.399963 * k;
    const glm::dvec3 n(std::sqrt(1.0 - z * z) * std::cos(phi), z,
                       std::sqrt(1.0 - z * z) * std::sin(phi));
    const glm::dvec3 v = glm::normalize(n + glm::dvec3(0.4 * std::sin(k), 0.3, 0.4 * std::cos(k)));
    const glm::dvec3 t = glm::normalize(glm::cross(glm::dvec3(0.3, 1.0, 0.2), n));
    context.eye_world = v * 4.0;
    const glm::dvec3 b = glm::cross(n, t);
    const glm::dvec3 n_a = glm::cross(glm::cross(b, v), b);
    const double bend = std::pow(1.0 - s.anisotropy * (1.0 - s.roughness), 4.0);
    const glm::dvec3 bent = glm::normalize(n_a * (1.0 - bend) + n * bend);
    const EnvironmentIntegrals e = lighting.integrals(n, v, s.roughness, bent);
    const glm::dvec3 want = base * e.specular + (glm::dvec3(1.0) - base) * e.specular_schlick;
    const glm::dvec3 got = shade_point(s, base, glm::dvec3(0.0), n, n, t);
    INFO("normal " << k);
    for (int c = 0; c < 3; ++c) CHECK(got[c] == Approx(want[c]).epsilon(1e-9));
    const glm::dvec3 plain = shade_point(isotropic, base, glm::dvec3(0.0), n, n, t);
    bent_shows += glm::length(got - plain) > 1e-3;
  }
  CHECK(bent_shows >= 18);
}
