// Lighting of lit triangles (docs/shading.md): the light models of covrast::ShadingModel
// evaluated at one point, in double precision. Every raster mode reaches this through
// shade() (shading/shading.hpp), so all modes light a point alike; only where they evaluate
// differs (pixel centre clamped into the triangle for coverage and msaa, every sample for
// ssaa and reference).
#include "shading/shading.hpp"
#include "shading/environment_lighting.hpp"
#include "shading/iridescence.hpp"
#include "shading/pbr_terms.hpp"
#include "shading/shading_inputs.hpp"
#include "shading/sheen.hpp"

#include <algorithm>
#include <array>
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

/// The normal the environment's prefiltered radiance is reflected about: n, or for
/// KHR_materials_anisotropy the bent normal of the glTF Sample Viewer and Filament (the
/// stretched lobe reflects light from along b): with a = b x v, n_a = a x b and
///   bend = (1 - anisotropy (1 - roughness))^4,   n_bent = normalize(mix(n_a, n, bend)).
glm::dvec3 mirror_normal(const PbrPoint& m, const glm::dvec3& n, const glm::dvec3& v) {
  if (!(m.anisotropy > 0.0)) return n;
  const glm::dvec3 across = glm::cross(m.anisotropy_b, v);
  const glm::dvec3 n_a = glm::cross(across, m.anisotropy_b);
  const double f = 1.0 - m.anisotropy * (1.0 - m.roughness);
  const double bend = (f * f) * (f * f);
  const glm::dvec3 bent = n_a * (1.0 - bend) + n * bend;
  const double bent_length = glm::length(bent);
  return bent_length > 0.0 ? bent / bent_length : n;
}

/// The environment's light for the glTF BRDF (shading/environment_lighting.hpp), with
/// F = F0 + (F90 - F0) s:
///   occlusion x (c_diff ((1 - F0_d) E / pi - (F90 - F0_d) E_s) + F0 A + (F90 - F0) B),
/// which for F90 = 1 and F0_d = F0 (the core material) is computed as
///   occlusion x (c_diff (1 - F0) (E / pi - E_s) + F0 A + (1 - F0) B).
glm::dvec3 environment_pbr(const SurfaceShading& s, const PbrPoint& m, const glm::dvec3& n,
                           const glm::dvec3& v) {
  const EnvironmentLighting* environment = s.context->environment;
  if (environment == nullptr || n == glm::dvec3(0.0)) return glm::dvec3(0.0);
  const EnvironmentIntegrals e = environment->integrals(n, v, m.roughness, mirror_normal(m, n, v));
  const glm::dvec3 gap = m.f90 - m.f0;
  const glm::dvec3 diffuse =
      m.f90 == glm::dvec3(1.0) && m.f0_diffuse == m.f0
          ? m.c_diff * gap * (e.irradiance * (1.0 / kPi) - e.irradiance_schlick)
          : m.c_diff * ((glm::dvec3(1.0) - m.f0_diffuse) * (e.irradiance * (1.0 / kPi)) -
                        (m.f90 - m.f0_diffuse) * e.irradiance_schlick);
  glm::dvec3 sum = s.occlusion * (diffuse + m.f0 * e.specular + gap * e.specular_schlick);
  if (m.iridescence > 0.0) {
    // F = mix(F, Ir, iridescence) with Ir constant over the lobe: Ir A, and the diffuse
    // weighted by 1 - Ir_d.
    const glm::dvec3 film =
        m.c_diff * (glm::dvec3(1.0) - m.iridescent_diffuse) * (e.irradiance * (1.0 / kPi)) +
        m.iridescent * e.specular;
    sum = sum * (1.0 - m.iridescence) + s.occlusion * film * m.iridescence;
  }
  // The suns as the directional lights they are, occluded like the rest of the environment
  // (as the viewers, which do not take suns out, occlude them).
  for (const EnvironmentSun& sun : environment->suns()) {
    const double n_dot_l = glm::dot(n, sun.to_light);
    if (!(n_dot_l > 0.0)) continue;
    sum += pbr_brdf(m, n, v, sun.to_light) * sun.irradiance * (n_dot_l * s.occlusion);
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

/// sum_i f(l_i, v) E_i (n . l_i)+ plus the ambient term ambient x occlusion x ((1 - F0_d)
/// c_diff + F0) (a uniform environment reflected by the normal-incidence albedo; a convention
/// of covrast, not of the glTF specification, which has no ambient light).
glm::dvec3 pbr_radiance(const SurfaceShading& s, const PbrPoint& m, const glm::dvec3& p,
                        const glm::dvec3& n, const glm::dvec3& v) {
  glm::dvec3 sum =
      s.context->ambient * s.occlusion * ((glm::dvec3(1.0) - m.f0_diffuse) * m.c_diff + m.f0);
  if (m.iridescence > 0.0) {
    const glm::dvec3 film = s.context->ambient * s.occlusion *
                            ((glm::dvec3(1.0) - m.iridescent_diffuse) * m.c_diff + m.iridescent);
    sum = sum * (1.0 - m.iridescence) + film * m.iridescence;
  }
  for (const PunctualLight& light : s.context->lights) {
    const Incident in = incident(light, p);
    const double n_dot_l = glm::dot(n, in.l);
    if (n_dot_l > 0.0) {
      sum += pbr_brdf(m, n, v, in.l) * in.irradiance * n_dot_l;
    } else if (n_dot_l < 0.0 && m.transmits()) {
      sum += transmission_btdf(m, n, v, in.l) * in.irradiance * -n_dot_l;
    }
  }
  return sum;
}

/// KHR_materials_transmission's share of the light behind the surface that passes towards the
/// viewer (the layer's filter over what lies behind it):
///   c_trans (1 - (F0_d A_1 + (F90 - F0_d) B_1)),
/// the transmitted diffuse less the specular's directional albedo under uniform light at
/// (n . v, roughness) (the split-sum tables, environment_lighting.hpp: the glTF Sample Viewer's
/// 1 - (f0 brdf.x + f90 brdf.y)). Thin-walled, without refraction: straight through, unblurred.
glm::dvec3 transmitted_share(const PbrPoint& m, const glm::dvec3& n, const glm::dvec3& v) {
  if (!m.transmits()) return glm::dvec3(0.0);
  if (n == glm::dvec3(0.0)) return m.c_trans;
  const std::array<double, 3> uniform =
      uniform_environment_integrals(std::abs(glm::dot(n, v)), m.roughness);
  const glm::dvec3 albedo = m.f0_diffuse * uniform[1] + (m.f90 - m.f0_diffuse) * uniform[2];
  return m.c_trans * (glm::dvec3(1.0) - albedo);
}

/// KHR_materials_clearcoat's layer alone, without its weight clearcoat x Fc: the coat's GGX
/// lobe D V (its roughness, its normal n_c, f0 0.04 in Fc outside) under the punctual lights,
/// the environment (its A integral, and the suns) and the ambient light (the lobe's albedo
/// taken as 1, as the core's ambient term takes the specular's as F0), occlusion on all but
/// the punctual lights as for the base.
glm::dvec3 clearcoat_radiance(const SurfaceShading& s, const PbrPoint& m, const glm::dvec3& p,
                              const glm::dvec3& v) {
  const glm::dvec3& n = m.coat_normal;
  if (n == glm::dvec3(0.0)) return glm::dvec3(0.0);
  const double alpha = std::max(m.coat_roughness * m.coat_roughness, kMinBrdfAlpha);
  const double alpha2 = alpha * alpha;
  glm::dvec3 sum = s.context->ambient * s.occlusion;
  for (const PunctualLight& light : s.context->lights) {
    const Incident in = incident(light, p);
    const double n_dot_l = glm::dot(n, in.l);
    if (!(n_dot_l > 0.0)) continue;
    sum += in.irradiance * (ggx_lobe(n, v, in.l, alpha2).d_vis * n_dot_l);
  }
  if (const EnvironmentLighting* environment = s.context->environment) {
    sum += s.occlusion * environment->integrals(n, v, m.coat_roughness).specular;
    for (const EnvironmentSun& sun : environment->suns()) {
      const double n_dot_l = glm::dot(n, sun.to_light);
      if (!(n_dot_l > 0.0)) continue;
      sum += sun.irradiance * (ggx_lobe(n, v, sun.to_light, alpha2).d_vis * n_dot_l * s.occlusion);
    }
  }
  return sum;
}

/// KHR_materials_sheen's layer (shading/sheen.hpp): sheenColor x (sum_i D V E_i (n . l_i)+ plus
/// the ambient light and the environment (without its suns, lit as the directional lights they
/// are) each times the sheen's albedo E(n . v) and occlusion): the environment's cosine-
/// weighted mean radiance E_env(n) / pi stands for the radiance the broad sheen lobe gathers,
/// exact for a uniform environment (docs/shading.md gives the error against quadrature);
/// `albedo` is E(n . v), which the base's scaling uses too.
glm::dvec3 sheen_radiance(const SurfaceShading& s, const PbrPoint& m, double albedo,
                          const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& v) {
  glm::dvec3 sum = s.context->ambient * (s.occlusion * albedo);
  for (const PunctualLight& light : s.context->lights) {
    const Incident in = incident(light, p);
    const double n_dot_l = glm::dot(n, in.l);
    if (!(n_dot_l > 0.0)) continue;
    sum += in.irradiance * (sheen_lobe(n, v, in.l, m.sheen_roughness) * n_dot_l);
  }
  if (const EnvironmentLighting* environment = s.context->environment) {
    sum += environment->irradiance_without_suns(n) * (s.occlusion * albedo / kPi);
    for (const EnvironmentSun& sun : environment->suns()) {
      const double n_dot_l = glm::dot(n, sun.to_light);
      if (!(n_dot_l > 0.0)) continue;
      sum += sun.irradiance *
             (sheen_lobe(n, v, sun.to_light, m.sheen_roughness) * n_dot_l * s.occlusion);
    }
  }
  return m.sheen_color * sum;
}

/// The glTF material at a point, with its sheen (KHR_materials_sheen, albedo scaling):
///   L = L_sheen + L_base (1 - max(sheenColor) E(n . v)) + emission,
/// coated (KHR_materials_clearcoat, "fresnel_coat"):
///   L = L_base (1 - clearcoat Fc) + clearcoat Fc L_coat,  Fc = 0.04 + 0.96 (1 - |n_c . v|)^5,
/// L_base with the emission (the coat darkens it too).
/// The layers over the base dim what it transmits as they dim its light: `filter`, when given,
/// is transmitted_share x the sheen's scaling x (1 - clearcoat Fc).
glm::dvec3 pbr_shade(const SurfaceShading& s, PbrPoint m, const glm::dvec3& p, const glm::dvec3& n,
                     const glm::dvec3& v, glm::dvec3* filter) {
  if (s.iridescence > 0.0 && n != glm::dvec3(0.0)) m.set_iridescence(s, glm::dot(n, v));
  if (filter != nullptr) *filter = transmitted_share(m, n, v);
  glm::dvec3 base;
  if (m.sheen_color == glm::dvec3(0.0) || n == glm::dvec3(0.0)) {
    base = pbr_radiance(s, m, p, n, v) + environment_pbr(s, m, n, v) + s.emissive;
  } else {
    const double strongest = std::max({m.sheen_color.r, m.sheen_color.g, m.sheen_color.b});
    const double albedo = sheen_albedo(glm::dot(n, v), m.sheen_roughness);
    const double scaling = 1.0 - strongest * albedo;
    base = (pbr_radiance(s, m, p, n, v) + environment_pbr(s, m, n, v)) * scaling +
           sheen_radiance(s, m, albedo, p, n, v) + s.emissive;
    if (filter != nullptr) *filter *= scaling;
  }
  if (!(m.clearcoat > 0.0)) return base;
  const double coat = m.clearcoat * clearcoat_fresnel(m.coat_normal, v);
  if (filter != nullptr) *filter *= 1.0 - coat;
  return base * (1.0 - coat) + clearcoat_radiance(s, m, p, v) * coat;
}

}  // namespace

// glTF 2.0 specification, Appendix B.3 (https://registry.khronos.org/glTF/specs/2.0/
// glTF-2.0.html#appendix-b-brdf-implementation), the implementation form of B.3.5, with
// KHR_materials_ior and KHR_materials_specular's F0 and F90 (PbrPoint):
//   alpha = max(roughness^2, 1e-3), F = F0 + (F90 - F0) (1 - |v . h|)^5
//   D = alpha^2 X+(n . h) / (pi ((n . h)^2 (alpha^2 - 1) + 1)^2)
//   V = X+(h . l) / (|n . l| + sqrt(alpha^2 + (1 - alpha^2) (n . l)^2))
//     x X+(h . v) / (|n . v| + sqrt(alpha^2 + (1 - alpha^2) (n . v)^2))
//   f = (1 - F_d) c_diff / pi + F D V
// F_d is F with the dielectric F0 colour reduced to its largest channel (KHR_materials_specular:
// the diffuse keeps what the strongest channel leaves); without the extension F_d = F.
// KHR_materials_anisotropy replaces D V by its anisotropic lobe (pbr_terms.hpp,
// anisotropic_ggx_lobe) with alpha_t = mix(alpha, 1, anisotropy^2) along t, alpha_b = alpha.
glm::dvec3 pbr_brdf(const PbrPoint& m, const glm::dvec3& n, const glm::dvec3& v,
                    const glm::dvec3& l) {
  const double alpha = std::max(m.roughness * m.roughness, kMinBrdfAlpha);
  const GgxLobe lobe =
      m.anisotropy > 0.0
          ? anisotropic_ggx_lobe(n, m.anisotropy_t, m.anisotropy_b, v, l,
                                 alpha + (1.0 - alpha) * (m.anisotropy * m.anisotropy), alpha)
          : ggx_lobe(n, v, l, alpha * alpha);
  const double weight = schlick_weight(std::abs(lobe.h_dot_v));
  glm::dvec3 fresnel = m.f0 + (m.f90 - m.f0) * weight;
  glm::dvec3 fresnel_diffuse =
      m.f0_diffuse == m.f0 ? fresnel : m.f0_diffuse + (m.f90 - m.f0_diffuse) * weight;
  if (m.iridescence > 0.0) {
    // KHR_materials_iridescence: over the dielectric and over the metal, F = mix(F, Ir, k)
    // with the film's term Ir at n . v; the diffuse keeps what the dielectric's largest
    // channel leaves (the extension's rgb_mix).
    const double k = m.iridescence;
    const glm::dvec3 dielectric =
        (m.dielectric_f0 + (glm::dvec3(m.dielectric_f90) - m.dielectric_f0) * weight) * (1.0 - k) +
        m.iridescent_dielectric * k;
    const glm::dvec3 metal =
        (m.base + (glm::dvec3(1.0) - m.base) * weight) * (1.0 - k) + m.iridescent_metal * k;
    fresnel = dielectric * (1.0 - m.metallic) + metal * m.metallic;
    const double strongest = std::max({dielectric.r, dielectric.g, dielectric.b});
    fresnel_diffuse = glm::dvec3(strongest) * (1.0 - m.metallic) + metal * m.metallic;
  }
  return (glm::dvec3(1.0) - fresnel_diffuse) * m.c_diff * (1.0 / kPi) + fresnel * lobe.d_vis;
}

// KHR_materials_transmission's BTDF for a thin wall (the extension's specular_btdf, as the glTF
// Sample Viewer's getPunctualRadianceTransmission evaluates it): the GGX lobe of the light
// mirrored through the surface, l' = l - 2 (n . l) n, at the transmission roughness, weighted
// as the diffuse it replaces is:
//   f_t = (1 - F_d) c_trans D V (l', v),  F_d at h' = normalize(l' + v).
glm::dvec3 transmission_btdf(const PbrPoint& m, const glm::dvec3& n, const glm::dvec3& v,
                             const glm::dvec3& l) {
  const glm::dvec3 mirrored = l - n * (2.0 * glm::dot(n, l));
  const GgxLobe lobe = ggx_lobe(n, v, mirrored, m.transmission_alpha2);
  const double weight = schlick_weight(std::abs(lobe.h_dot_v));
  const glm::dvec3 fresnel_diffuse = m.f0_diffuse + (m.f90 - m.f0_diffuse) * weight;
  return (glm::dvec3(1.0) - fresnel_diffuse) * m.c_trans * lobe.d_vis;
}

glm::dvec3 pbr_brdf(const glm::dvec3& base, double metallic, double roughness, const glm::dvec3& n,
                    const glm::dvec3& v, const glm::dvec3& l) {
  SurfaceShading core;
  core.metallic = metallic;
  core.roughness = roughness;
  return pbr_brdf(PbrPoint(core, base, glm::dvec3(0.0)), n, v, l);
}

PbrPoint::PbrPoint(const SurfaceShading& s, const glm::dvec3& base_color,
                   const glm::dvec3& clearcoat_normal)
    : base(base_color),
      metallic(s.metallic),
      roughness(s.roughness),
      clearcoat(s.clearcoat),
      coat_roughness(s.clearcoat_roughness),
      coat_normal(clearcoat_normal),
      sheen_color(s.sheen_color),
      sheen_roughness(s.sheen_roughness) {
  // Dielectric F0 = min(f0(ior) x specular colour, 1) x specular, F90 = specular; each then
  // lerped towards the metal's (base, 1) by metallic. At the defaults (f0 0.04, colour 1,
  // specular 1) this is the core material's F0 = lerp(0.04, base, metallic), F90 = 1, bit for bit.
  const glm::dvec3 dielectric_f0 =
      glm::min(s.ior_f0 * s.specular_color, glm::dvec3(1.0)) * s.specular_weight;
  this->dielectric_f0 = dielectric_f0;
  dielectric_f90 = s.specular_weight;
  c_diff = base * (1.0 - metallic);
  f0 = dielectric_f0 * (1.0 - metallic) + base * metallic;
  f90 = glm::dvec3(s.specular_weight + (1.0 - s.specular_weight) * metallic);
  const double strongest = std::max({dielectric_f0.r, dielectric_f0.g, dielectric_f0.b});
  f0_diffuse = dielectric_f0 == glm::dvec3(strongest)
                   ? f0
                   : glm::dvec3(strongest) * (1.0 - metallic) + base * metallic;
}

void PbrPoint::set_iridescence(const SurfaceShading& s, double n_dot_v) {
  // KHR_materials_iridescence: the film over the dielectric (its F0 with the specular
  // extension's colour and weight) and over the metal (F0 = base), seen at n . v, mixed by
  // metallic as F0 is; the diffuse keeps what the dielectric film's largest channel leaves.
  iridescence = s.iridescence;
  const double cos_theta1 = std::min(std::abs(n_dot_v), 1.0);
  const glm::dvec3 over_dielectric = iridescent_fresnel(1.0, s.iridescence_ior, dielectric_f0,
                                                        s.iridescence_thickness_nm, cos_theta1);
  const glm::dvec3 over_metal =
      iridescent_fresnel(1.0, s.iridescence_ior, base, s.iridescence_thickness_nm, cos_theta1);
  iridescent_dielectric = over_dielectric;
  iridescent_metal = over_metal;
  iridescent = over_dielectric * (1.0 - metallic) + over_metal * metallic;
  const double strongest = std::max({over_dielectric.r, over_dielectric.g, over_dielectric.b});
  iridescent_diffuse = glm::dvec3(strongest) * (1.0 - metallic) + over_metal * metallic;
}

void PbrPoint::set_transmission(const SurfaceShading& s, double transmission, double thickness) {
  c_trans = c_diff * transmission;
  c_diff = c_diff * (1.0 - transmission);
  if (s.attenuation_distance > 0.0 && thickness > 0.0) {
    const double e = thickness / s.attenuation_distance;
    c_trans *= glm::dvec3(std::pow(s.attenuation_color.r, e), std::pow(s.attenuation_color.g, e),
                          std::pow(s.attenuation_color.b, e));
  }
  const double alpha = roughness * roughness * std::clamp(2.0 * s.ior - 2.0, 0.0, 1.0);
  const double clamped = std::max(alpha, kMinBrdfAlpha);
  transmission_alpha2 = clamped * clamped;
}

void PbrPoint::set_anisotropy(double strength, const glm::dvec3& direction, const glm::dvec3& n) {
  // The stretched direction made orthogonal to the shading normal, so that t, b, n is the
  // orthonormal frame the anisotropic D assumes (the extension takes T from the interpolated
  // normal's frame and b = normalize(n_geometric x T); without a normal map they agree).
  const glm::dvec3 t = direction - n * glm::dot(n, direction);
  const double t_length = glm::length(t);
  if (!(t_length > 1e-12)) return;
  anisotropy = strength;
  anisotropy_t = t / t_length;
  anisotropy_b = glm::cross(n, anisotropy_t);
}

glm::dvec3 shade_point(const SurfaceShading& s, const glm::dvec3& base, const glm::dvec3& p,
                       const glm::dvec3& n, const glm::dvec3& clearcoat_normal,
                       const glm::dvec3& anisotropy_direction, glm::dvec3* filter) {
  if (filter != nullptr) *filter = glm::dvec3(0.0);
  const ShadingContext& c = *s.context;
  const glm::dvec3 to_eye = c.eye_world - p;
  const double eye_distance = glm::length(to_eye);
  glm::dvec3 v = eye_distance > 0.0 ? to_eye * (1.0 / eye_distance) : n;
  if (c.orthographic) v = c.to_eye;
  switch (s.model) {
    case ShadingModel::Unlit:
      return base;
    case ShadingModel::Lambert:
      return diffuse_sum(c, s.occlusion, base, p, n) +
             environment_diffuse(c, s.occlusion, base, n) + s.emissive;
    case ShadingModel::BlinnPhong:
      return diffuse_sum(c, s.occlusion, base, p, n) +
             environment_diffuse(c, s.occlusion, base, n) + blinn_phong_highlights(s, p, n, v) +
             s.emissive;
    case ShadingModel::Pbr:
    default: {
      PbrPoint m(s, base, clearcoat_normal);
      if (s.anisotropy > 0.0) m.set_anisotropy(s.anisotropy, anisotropy_direction, n);
      if (s.transmission > 0.0) m.set_transmission(s, s.transmission, s.thickness);
      return pbr_shade(s, m, p, n, v, filter);
    }
  }
}

double surface_alpha(const TriangleSetup& t, double mu0, double mu1, double mu2) {
  return surface_alpha_with(t, mu0, mu1, mu2, base_color_texture_alpha(t, mu0, mu1, mu2));
}

double surface_alpha_with(const TriangleSetup& t, double mu0, double mu1, double mu2,
                          double texture_alpha) {
  const ShadingRecord& r = *t.shading;
  // Equal vertex alphas stay exact (the weights need not sum to exactly 1), so that a
  // uniform alpha equal to the cutoff passes.
  const double vertex =
      r.vertex_alpha[0] == r.vertex_alpha[1] && r.vertex_alpha[0] == r.vertex_alpha[2]
          ? r.vertex_alpha[0]
          : mu0 * r.vertex_alpha[0] + mu1 * r.vertex_alpha[1] + mu2 * r.vertex_alpha[2];
  const double alpha = r.surface->base_alpha * vertex * texture_alpha;
  // A transmissive OPAQUE or MASK surface is drawn as a BLEND layer (its light passes, not its
  // alpha): alpha 1, or the mask's verdict.
  if (r.surface->transmissive() && r.surface->alpha_mode != AlphaMode::Blend) {
    return r.surface->alpha_mode == AlphaMode::Opaque || alpha >= r.surface->alpha_cutoff ? 1.0
                                                                                          : 0.0;
  }
  return alpha;
}

bool transmits(const TriangleSetup& t) {
  return t.shading != nullptr && t.shading->surface->transmissive();
}

ShadedColor shade_rgba(const TriangleSetup& t, double x_px, double y_px, bool clamp_inside) {
  if (transmits(t)) {
    double mu[3];
    perspective_weights(t, x_px, y_px, clamp_inside, mu);
    ShadedColor out{glm::vec3(0.0f), surface_alpha(t, mu[0], mu[1], mu[2])};
    out.rgb = shade_lit(t, mu[0], mu[1], mu[2], nullptr, &out.filter);
    out.transmissive = true;
    return out;
  }
  const glm::vec3 rgb = shade(t, x_px, y_px, clamp_inside);
  if (t.alpha_mode == AlphaMode::Opaque) return {rgb, 1.0};
  double mu[3];
  perspective_weights(t, x_px, y_px, clamp_inside, mu);
  return {rgb, surface_alpha(t, mu[0], mu[1], mu[2])};
}

bool mask_keeps(const TriangleSetup& t, double x_px, double y_px, bool clamp_inside) {
  if (t.alpha_mode != AlphaMode::Mask) return true;
  double mu[3];
  perspective_weights(t, x_px, y_px, clamp_inside, mu);
  return surface_alpha(t, mu[0], mu[1], mu[2]) >= t.shading->surface->alpha_cutoff;
}

glm::vec3 shade_lit(const TriangleSetup& t, double mu0, double mu1, double mu2,
                    const FragmentFootprint* footprint, glm::vec3* filter) {
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
  glm::dvec3 passes(0.0);
  glm::dvec3* const passes_out = filter != nullptr ? &passes : nullptr;
  const auto finish_all = [&](const glm::dvec3& radiance) {
    if (filter != nullptr) *filter = glm::vec3(passes);
    return finish(radiance);
  };
  if (r.textured == nullptr) {
    return finish_all(shade_point(*r.surface, base, p, n, n, glm::dvec3(0.0), passes_out));
  }
  // Textured: the surface with this point's texels (shading/texture_shading.cpp).
  const SurfaceSample sample = sample_surface(t, mu0, mu1, mu2, n, footprint);
  SurfaceShading s = *r.surface;
  s.metallic = sample.metallic;
  s.roughness = sample.roughness;
  s.occlusion = sample.occlusion;
  s.emissive = sample.emissive;
  s.specular_weight = sample.specular_weight;
  s.specular_color = sample.specular_color;
  s.clearcoat = sample.clearcoat;
  s.clearcoat_roughness = sample.clearcoat_roughness;
  s.sheen_color = sample.sheen_color;
  s.sheen_roughness = sample.sheen_roughness;
  s.iridescence = sample.iridescence;
  s.iridescence_thickness_nm = sample.iridescence_thickness_nm;
  s.anisotropy = sample.anisotropy;
  s.transmission = sample.transmission;
  s.thickness = sample.thickness;
  return finish_all(shade_point(s, base * glm::dvec3(sample.base_color), p, sample.normal,
                                sample.clearcoat_normal, sample.anisotropy_direction, passes_out));
}

}  // namespace covrast::detail
