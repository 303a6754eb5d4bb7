// The terms of the glTF 2.0 metallic-roughness BRDF (Specification, Appendix B.3) that both the
// punctual lights (shading/shading.cpp, pbr_brdf) and the environment's integrals
// (shading/environment_lighting.cpp) evaluate: one home, so both compute them with the same
// operations and get the same bits.
#pragma once

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace covrast::detail {

/// Smallest BRDF roughness alpha (= perceptual roughness^2): alpha = 0 (a perfect mirror) makes
/// D = 0/0 where n = h.
inline constexpr double kMinBrdfAlpha = 1e-3;

/// (1 - x)^5 by multiplication, x clamped to [0, 1]: the Schlick weight of F = f0 + (1 - f0) s.
inline double schlick_weight(double cos_theta) {
  const double m = std::clamp(1.0 - cos_theta, 0.0, 1.0);
  const double m2 = m * m;
  return m2 * m2 * m;
}

/// One factor of the height-correlated Smith visibility term,
///   g(x) = x + sqrt(alpha^2 + (1 - alpha^2) x^2),   V = 1 / (g(n.l) g(n.v)),
/// for x = |n . l| or |n . v|.
inline double smith_g(double n_dot_x, double alpha2) {
  return n_dot_x + std::sqrt(alpha2 + (1.0 - alpha2) * n_dot_x * n_dot_x);
}

/// What both GGX lobes read of unit n, v, l: h = normalize(l + v) (n when l = -v), |n . l|,
/// |n . v|, n . h, h . l and h . v; `lit` where the lobe is not 0 (n.h, h.l and h.v > 0).
struct HalfVector {
  glm::dvec3 h;
  double n_dot_l, n_dot_v, n_dot_h, h_dot_l, h_dot_v;
  bool lit() const { return n_dot_h > 0.0 && h_dot_l > 0.0 && h_dot_v > 0.0; }
};
inline HalfVector half_vector(const glm::dvec3& n, const glm::dvec3& v, const glm::dvec3& l) {
  const glm::dvec3 h_sum = l + v;
  const double h_length = glm::length(h_sum);
  HalfVector out;
  out.h = h_length > 0.0 ? h_sum * (1.0 / h_length) : n;
  out.n_dot_l = std::abs(glm::dot(n, l));
  out.n_dot_v = std::abs(glm::dot(n, v));
  out.n_dot_h = glm::dot(n, out.h);
  out.h_dot_l = glm::dot(out.h, l);
  out.h_dot_v = glm::dot(out.h, v);
  return out;
}

/// The GGX specular lobe of the glTF BRDF for unit n, v, l and alpha^2 (Appendix B.3.5):
/// D x V in one division, alpha^2 / (pi k^2 g_l g_v) with k = (n.h)^2 (alpha^2 - 1) + 1 (0 where
/// n.h, h.l or h.v <= 0), and h . v for the Fresnel term; h = normalize(l + v), n when l = -v.
struct GgxLobe {
  double d_vis = 0.0;
  double h_dot_v = 0.0;
};
inline GgxLobe ggx_lobe(const glm::dvec3& n, const glm::dvec3& v, const glm::dvec3& l,
                        double alpha2) {
  const HalfVector hv = half_vector(n, v, l);
  GgxLobe lobe;
  lobe.h_dot_v = hv.h_dot_v;
  if (hv.lit()) {
    const double k = hv.n_dot_h * hv.n_dot_h * (alpha2 - 1.0) + 1.0;
    const double gl = smith_g(hv.n_dot_l, alpha2);
    const double gv = smith_g(hv.n_dot_v, alpha2);
    lobe.d_vis = alpha2 / (std::numbers::pi * k * k * (gl * gv));
  }
  return lobe;
}

/// KHR_materials_anisotropy's lobe for the unit frame t, b, n, unit v, l and roughnesses
/// alpha_t along t, alpha_b along b (the extension's D_GGX_anisotropic and V_GGX_anisotropic,
/// Filament's anisotropic model):
///   D = a^3 / (pi |f|^4),  a = alpha_t alpha_b,  f = (alpha_b t.h, alpha_t b.h, a n.h)
///   V = min(0.5 / (|n.l| |(alpha_t t.v, alpha_b b.v, |n.v|)| + |n.v| |(alpha_t t.l,
///       alpha_b b.l, |n.l|)|), 1)
/// with the isotropic lobe's conditions (0 where n.h, h.l or h.v <= 0). Its V is the
/// height-correlated Smith term, where the core's is the separable one (ggx_lobe).
inline GgxLobe anisotropic_ggx_lobe(const glm::dvec3& n, const glm::dvec3& t, const glm::dvec3& b,
                                    const glm::dvec3& v, const glm::dvec3& l, double alpha_t,
                                    double alpha_b) {
  const HalfVector hv = half_vector(n, v, l);
  GgxLobe lobe;
  lobe.h_dot_v = hv.h_dot_v;
  if (hv.lit()) {
    const glm::dvec3& h = hv.h;
    const double a = alpha_t * alpha_b;
    const glm::dvec3 f(alpha_b * glm::dot(t, h), alpha_t * glm::dot(b, h), a * hv.n_dot_h);
    const double w2 = a / glm::dot(f, f);
    const double d = a * w2 * w2 / std::numbers::pi;
    const glm::dvec3 v_stretched(alpha_t * glm::dot(t, v), alpha_b * glm::dot(b, v), hv.n_dot_v);
    const glm::dvec3 l_stretched(alpha_t * glm::dot(t, l), alpha_b * glm::dot(b, l), hv.n_dot_l);
    const double ggx_v = hv.n_dot_l * glm::length(v_stretched);
    const double ggx_l = hv.n_dot_v * glm::length(l_stretched);
    lobe.d_vis = d * std::min(0.5 / (ggx_v + ggx_l), 1.0);
  }
  return lobe;
}

/// KHR_materials_clearcoat's layer weight per unit clearcoat, fresnel_coat with ior 1.5:
///   Fc = 0.04 + (1 - 0.04) (1 - |n_c . v|)^5.
inline double clearcoat_fresnel(const glm::dvec3& coat_normal, const glm::dvec3& v) {
  constexpr double kCoatF0 = 0.04;
  return kCoatF0 + (1.0 - kCoatF0) * schlick_weight(std::abs(glm::dot(coat_normal, v)));
}

}  // namespace covrast::detail
