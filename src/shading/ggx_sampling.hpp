// GGX importance sampling on Hammersley points, shared by the environment's prefiltered
// radiance (environment_lighting.cpp) and its uniform-light tables (environment_tables.cpp).
// Double precision, no contraction: the same directions on every target.
#pragma once

#include "shading/pbr_terms.hpp"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace covrast::detail {

/// Van der Corput radical inverse in base 2: the second Hammersley coordinate.
inline double radical_inverse2(unsigned i) {
  double inv = 0.5, r = 0.0;
  while (i != 0) {
    if ((i & 1U) != 0) r += inv;
    inv *= 0.5;
    i >>= 1U;
  }
  return r;
}

/// An orthonormal basis (t, b) around unit n: Duff et al., "Building an Orthonormal Basis,
/// Revisited", JCGT 6(1), 2017.
inline void tangent_frame(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double c = n.x * n.y * a;
  t = glm::dvec3(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = glm::dvec3(c, sign + n.y * n.y * a, -n.y);
}

/// cos and sin of the azimuth 2 pi xi2 of the first `count` Hammersley points: the same for
/// every shading point and roughness, so computed once.
inline std::vector<glm::dvec2> hammersley_azimuths(int count) {
  std::vector<glm::dvec2> azimuths;
  for (int k = 0; k < count; ++k) {
    const double phi = 2.0 * std::numbers::pi * radical_inverse2(unsigned(k));
    azimuths.push_back({std::cos(phi), std::sin(phi)});
  }
  return azimuths;
}

/// The half vector of GGX sample (xi1, azimuth) around n: cos(theta_h) = sqrt((1 - xi1) / (1 +
/// (alpha^2 - 1) xi1)) samples D(h) (n . h) (Walter et al. 2007, eq. 35).
inline glm::dvec3 ggx_half_vector(double xi1, const glm::dvec2& azimuth, double alpha2,
                                  const glm::dvec3& n, const glm::dvec3& t, const glm::dvec3& b,
                                  double& cos_h) {
  cos_h = std::sqrt((1.0 - xi1) / (1.0 + (alpha2 - 1.0) * xi1));
  const double sin_h = std::sqrt(std::max(0.0, 1.0 - cos_h * cos_h));
  return t * (sin_h * azimuth.x) + b * (sin_h * azimuth.y) + n * cos_h;
}

/// V = 1 / (g(n.l) g(n.v)), the specification's height-correlated Smith term, for n.l,
/// n.v > 0.
inline double smith_visibility(double n_dot_l, double n_dot_v, double alpha2) {
  return 1.0 / (smith_g(n_dot_l, alpha2) * smith_g(n_dot_v, alpha2));
}

}  // namespace covrast::detail
