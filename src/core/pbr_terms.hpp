// The terms of the glTF 2.0 metallic-roughness BRDF (Specification, Appendix B.3) that both the
// punctual lights (core/shading.cpp, pbr_brdf) and the environment's integrals
// (core/environment_lighting.cpp) evaluate: one home, so both compute them with the same
// operations and get the same bits.
#pragma once

#include <algorithm>
#include <cmath>

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

}  // namespace covrast::detail
