// Lighting of lit triangles (docs/shading.md): the light models of covrast::ShadingModel
// evaluated at one point, in double precision. Every raster mode reaches this through
// shade() (core/shading.hpp), so all modes light a point alike; only where they evaluate
// differs (pixel centre clamped into the triangle for coverage and msaa, every sample for
// ssaa and reference).
#include "core/shading.hpp"
#include "core/environment_lighting.hpp"
#include "core/pbr_terms.hpp"
#include "core/shading_inputs.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace covrast::detail {
namespace {

constexpr double kPi = std::numbers::pi;

/// What one punctual light delivers at a point: the unit direction towards it and the
/// irradiance on a surface facing it, E = radiance x attenuation (KHR_lights_punctual).
struct Incident {
  glm::dvec3 l{0.0};
  glm::dvec3 irradiance{0.0};
};

/// Directional: E = color x intensity. Point and spot: E = color x intensity / d^2 x
/// clamp(1 - (d / range)^4, 0, 1) (the extension's recommended range window), spot also x
/// clamp(cos(angle to axis) x scale + offset, 0, 1)^2.
Incident incident(const PunctualLight& light, const glm::dvec3& p) {
  if (light.kind == PunctualLight::Kind::Directional) return {light.to_light, light.radiance};
  const glm::dvec3 d = light.position - p;
  const double distance2 = glm::dot(d, d);
  if (!(distance2 > 0.0)) return {};
  const double distance = std::sqrt(distance2);
  const glm::dvec3 l = d * (1.0 / distance);
  double attenuation = 1.0 / distance2;
  if (light.inv_range > 0.0) {
    const double q = distance * light.inv_range;
    const double q2 = q * q;
    attenuation *= std::clamp(1.0 - q2 * q2, 0.0, 1.0);
  }
  if (light.kind == PunctualLight::Kind::Spot) {
    const double cone =
        std::clamp(-glm::dot(light.spot_axis, l) * light.cone_scale + light.cone_offset, 0.0, 1.0);
    attenuation *= cone * cone;
  }
  return {l, light.radiance * attenuation};
}

/// base x (ambient x occlusion + sum_i E_i max(0, n . l_i)): Lambert without 1/pi, so that a
/// light of intensity 1 facing the surface returns the base colour.
glm::dvec3 diffuse_sum(const ShadingContext& c, double occlusion, const glm::dvec3& base,
                       const glm::dvec3& p, const glm::dvec3& n) {
  glm::dvec3 e = c.ambient * occlusion;
  for (const PunctualLight& light : c.lights) {
    const Incident in = incident(light, p);
    e += in.irradiance * std::max(0.0, glm::dot(n, in.l));
  }
  return base * e;
}

/// The environment's diffuse light for the Lambert and Blinn-Phong models: a Lambertian
/// surface's base x E(n) / pi, x occlusion. (Their punctual lights keep covrast's older
/// convention without 1 / pi, docs/shading.md.)
glm::dvec3 environment_diffuse(const ShadingContext& c, double occlusion, const glm::dvec3& base,
                               const glm::dvec3& n) {
  if (c.environment == nullptr || n == glm::dvec3(0.0)) return glm::dvec3(0.0);
  return base * c.environment->irradiance(n) * (occlusion / kPi);
}

/// The environment's light for the glTF BRDF (core/environment_lighting.hpp):
///   occlusion x (c_diff (1 - f0) (E / pi - E_s) + f0 A + (1 - f0) B).
glm::dvec3 environment_pbr(const SurfaceShading& s, const glm::dvec3& base, const glm::dvec3& n,
                           const glm::dvec3& v) {
  const EnvironmentLighting* environment = s.context->environment;
  if (environment == nullptr || n == glm::dvec3(0.0)) return glm::dvec3(0.0);
  const EnvironmentIntegrals e = environment->integrals(n, v, s.roughness);
  const glm::dvec3 c_diff = base * (1.0 - s.metallic);
  const glm::dvec3 f0 = glm::dvec3(0.04) * (1.0 - s.metallic) + base * s.metallic;
  const glm::dvec3 one_minus_f0 = glm::dvec3(1.0) - f0;
  glm::dvec3 sum =
      s.occlusion * (c_diff * one_minus_f0 * (e.irradiance * (1.0 / kPi) - e.irradiance_schlick) +
                     f0 * e.specular + one_minus_f0 * e.specular_schlick);
  // The suns as the directional lights they are, occluded like the rest of the environment
  // (as the viewers, which do not take suns out, occlude them).
  for (const EnvironmentSun& sun : environment->suns()) {
    const double n_dot_l = glm::dot(n, sun.to_light);
    if (!(n_dot_l > 0.0)) continue;
    sum += pbr_brdf(base, s.metallic, s.roughness, n, v, sun.to_light) * sun.irradiance *
           (n_dot_l * s.occlusion);
  }
  return sum;
}

/// Blinn (1977) highlight: sum_i specular x E_i x max(0, n . h_i)^shininess where n . l_i > 0,
/// h_i = normalize(l_i + v), unnormalised (specular is the peak's fraction of E).
glm::dvec3 blinn_phong_highlights(const SurfaceShading& s, const glm::dvec3& p, const glm::dvec3& n,
                                  const glm::dvec3& v) {
  glm::dvec3 sum(0.0);
  for (const PunctualLight& light : s.context->lights) {
    const Incident in = incident(light, p);
    if (!(glm::dot(n, in.l) > 0.0)) continue;
    const glm::dvec3 h = in.l + v;
    const double h_length = glm::length(h);
    if (!(h_length > 0.0)) continue;
    const double n_dot_h = std::max(0.0, glm::dot(n, h) / h_length);
    sum += s.specular * in.irradiance * std::pow(n_dot_h, s.shininess);
  }
  return sum;
}

/// sum_i f(l_i, v) E_i (n . l_i)+ plus the ambient term ambient x occlusion x ((1 - f0) c_diff
/// + f0)
/// (a uniform environment reflected by the normal-incidence albedo; a convention of
/// covrast, not of the glTF specification, which has no ambient light).
glm::dvec3 pbr_radiance(const SurfaceShading& s, const glm::dvec3& base, const glm::dvec3& p,
                        const glm::dvec3& n, const glm::dvec3& v) {
  const glm::dvec3 c_diff = base * (1.0 - s.metallic);
  const glm::dvec3 f0 = glm::dvec3(0.04) * (1.0 - s.metallic) + base * s.metallic;
  glm::dvec3 sum = s.context->ambient * s.occlusion * ((glm::dvec3(1.0) - f0) * c_diff + f0);
  for (const PunctualLight& light : s.context->lights) {
    const Incident in = incident(light, p);
    const double n_dot_l = glm::dot(n, in.l);
    if (!(n_dot_l > 0.0)) continue;
    sum += pbr_brdf(base, s.metallic, s.roughness, n, v, in.l) * in.irradiance * n_dot_l;
  }
  return sum;
}

}  // namespace

// glTF 2.0 specification, Appendix B.3 (https://registry.khronos.org/glTF/specs/2.0/
// glTF-2.0.html#appendix-b-brdf-implementation), the implementation form of B.3.5:
//   alpha = max(roughness^2, 1e-3), c_diff = lerp(base, 0, metallic), f0 = lerp(0.04, base,
//   metallic) F = f0 + (1 - f0) (1 - |v . h|)^5 D = alpha^2 X+(n . h) / (pi ((n . h)^2 (alpha^2 -
//   1) + 1)^2) V = X+(h . l) / (|n . l| + sqrt(alpha^2 + (1 - alpha^2) (n . l)^2))
//     x X+(h . v) / (|n . v| + sqrt(alpha^2 + (1 - alpha^2) (n . v)^2))
//   f = (1 - F) c_diff / pi + F D V
glm::dvec3 pbr_brdf(const glm::dvec3& base, double metallic, double roughness, const glm::dvec3& n,
                    const glm::dvec3& v, const glm::dvec3& l) {
  const glm::dvec3 c_diff = base * (1.0 - metallic);
  const glm::dvec3 f0 = glm::dvec3(0.04) * (1.0 - metallic) + base * metallic;
  // alpha = 0 (a perfect mirror) makes D = 0/0 where n = h: kept at kMinBrdfAlpha, a highlight
  // one pixel wide that the resolve clamps.
  const double alpha = std::max(roughness * roughness, kMinBrdfAlpha);
  const double alpha2 = alpha * alpha;
  const glm::dvec3 h_sum = l + v;
  const double h_length = glm::length(h_sum);
  const glm::dvec3 h = h_length > 0.0 ? h_sum * (1.0 / h_length) : n;
  const double n_dot_l = std::abs(glm::dot(n, l)), n_dot_v = std::abs(glm::dot(n, v));
  const double n_dot_h = glm::dot(n, h), h_dot_l = glm::dot(h, l), h_dot_v = glm::dot(h, v);
  const glm::dvec3 fresnel = f0 + (glm::dvec3(1.0) - f0) * schlick_weight(std::abs(h_dot_v));
  // D x V in one division: alpha^2 / (pi k^2 g_l g_v), k = (n.h)^2 (alpha^2 - 1) + 1.
  double d_vis = 0.0;
  if (n_dot_h > 0.0 && h_dot_l > 0.0 && h_dot_v > 0.0) {
    const double k = n_dot_h * n_dot_h * (alpha2 - 1.0) + 1.0;
    const double gl = smith_g(n_dot_l, alpha2);
    const double gv = smith_g(n_dot_v, alpha2);
    d_vis = alpha2 / (kPi * k * k * (gl * gv));
  }
  return (glm::dvec3(1.0) - fresnel) * c_diff * (1.0 / kPi) + fresnel * d_vis;
}

glm::dvec3 shade_point(const SurfaceShading& s, const glm::dvec3& base, const glm::dvec3& p,
                       const glm::dvec3& n) {
  const ShadingContext& c = *s.context;
  const glm::dvec3 to_eye = c.eye_world - p;
  const double eye_distance = glm::length(to_eye);
  glm::dvec3 v = eye_distance > 0.0 ? to_eye * (1.0 / eye_distance) : n;
  if (c.orthographic) v = c.to_eye;
  switch (s.model) {
    case LitModel::Unlit:
      return base;
    case LitModel::Lambert:
      return diffuse_sum(c, s.occlusion, base, p, n) +
             environment_diffuse(c, s.occlusion, base, n) + s.emissive;
    case LitModel::BlinnPhong:
      return diffuse_sum(c, s.occlusion, base, p, n) +
             environment_diffuse(c, s.occlusion, base, n) + blinn_phong_highlights(s, p, n, v) +
             s.emissive;
    case LitModel::Pbr:
    default:
      return pbr_radiance(s, base, p, n, v) + environment_pbr(s, base, n, v) + s.emissive;
  }
}

double surface_alpha(const TriangleSetup& t, double mu0, double mu1, double mu2) {
  const ShadingRecord& r = *t.shading;
  // Equal vertex alphas stay exact (the weights need not sum to exactly 1), so that a
  // uniform alpha equal to the cutoff passes.
  const double vertex =
      r.vertex_alpha[0] == r.vertex_alpha[1] && r.vertex_alpha[0] == r.vertex_alpha[2]
          ? r.vertex_alpha[0]
          : mu0 * r.vertex_alpha[0] + mu1 * r.vertex_alpha[1] + mu2 * r.vertex_alpha[2];
  const double texture = base_color_texture_alpha(t, mu0, mu1, mu2);
  return r.surface->base_alpha * vertex * texture;
}

ShadedColor shade_rgba(const TriangleSetup& t, double x_px, double y_px, bool clamp_inside) {
  const glm::vec3 rgb = shade(t, x_px, y_px, clamp_inside);
  if (t.alpha_mode == TriangleAlpha::Opaque) return {rgb, 1.0};
  double mu[3];
  perspective_weights(t, x_px, y_px, clamp_inside, mu);
  return {rgb, surface_alpha(t, mu[0], mu[1], mu[2])};
}

bool mask_keeps(const TriangleSetup& t, double x_px, double y_px, bool clamp_inside) {
  if (t.alpha_mode != TriangleAlpha::Mask) return true;
  double mu[3];
  perspective_weights(t, x_px, y_px, clamp_inside, mu);
  return surface_alpha(t, mu[0], mu[1], mu[2]) >= t.shading->surface->alpha_cutoff;
}

glm::vec3 shade_lit(const TriangleSetup& t, double mu0, double mu1, double mu2) {
  const ShadingRecord& r = *t.shading;
  // The same weighted sums as the unlit colour interpolation in shade().
  const glm::dvec3 base(mu0 * t.color[0].r + mu1 * t.color[1].r + mu2 * t.color[2].r,
                        mu0 * t.color[0].g + mu1 * t.color[1].g + mu2 * t.color[2].g,
                        mu0 * t.color[0].b + mu1 * t.color[1].b + mu2 * t.color[2].b);
  const glm::dvec3 p = mu0 * glm::dvec3(r.position_world[0]) +
                       mu1 * glm::dvec3(r.position_world[1]) +
                       mu2 * glm::dvec3(r.position_world[2]);
  glm::dvec3 n = mu0 * glm::dvec3(r.normal_world[0]) + mu1 * glm::dvec3(r.normal_world[1]) +
                 mu2 * glm::dvec3(r.normal_world[2]);
  const double n_length = glm::length(n);
  n = n_length > 0.0 ? n * (1.0 / n_length) : glm::dvec3(0.0);
  const ToneMapping& mapping = r.surface->context->tone_mapping;
  const auto finish = [&](const glm::dvec3& radiance) {
    return glm::vec3(mapping.is_identity() ? radiance : tone_map(mapping, radiance));
  };
  if (r.textured == nullptr) return finish(shade_point(*r.surface, base, p, n));
  // Textured: the surface with this point's texels (core/texture_shading.cpp).
  const SurfaceSample sample = sample_surface(t, mu0, mu1, mu2, n);
  SurfaceShading s = *r.surface;
  s.metallic = sample.metallic;
  s.roughness = sample.roughness;
  s.occlusion = sample.occlusion;
  s.emissive = sample.emissive;
  return finish(shade_point(s, base * glm::dvec3(sample.base_color), p, sample.normal));
}

}  // namespace covrast::detail
