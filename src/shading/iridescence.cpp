// KHR_materials_iridescence's thin-film Fresnel term (shading/iridescence.hpp).
#include "shading/iridescence.hpp"

#include "shading/pbr_terms.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace covrast::detail {
namespace {

constexpr double kPi = std::numbers::pi;

/// ((n_t - n_i) / (n_t + n_i))^2: the reflectance at normal incidence from ior n_i into n_t.
double ior_to_f0(double transmitted, double incident) {
  const double r = (transmitted - incident) / (transmitted + incident);
  return r * r;
}

/// Schlick's approximation with F90 = 1.
double schlick(double f0, double cos_theta) {
  return f0 + (1.0 - f0) * schlick_weight(std::abs(cos_theta));
}

/// The CIE XYZ matching functions' Fourier transform at optical path difference `opd_nm` and
/// phase `shift` per channel, as Gaussian fits (Belcour and Barla 2017), in linear Rec. 709.
glm::dvec3 sensitivity(double opd_nm, const glm::dvec3& shift) {
  const double phase = 2.0 * kPi * opd_nm * 1.0e-9;
  const double phase2 = phase * phase;
  const glm::dvec3 val(5.4856e-13, 4.4201e-13, 5.2481e-13);
  const glm::dvec3 pos(1.6810e+06, 1.7953e+06, 2.2084e+06);
  const glm::dvec3 var(4.3278e+09, 9.3046e+09, 6.6121e+09);
  glm::dvec3 xyz;
  for (int c = 0; c < 3; ++c) {
    xyz[c] = val[c] * std::sqrt(2.0 * kPi * var[c]) * std::cos(pos[c] * phase + shift[c]) *
             std::exp(-phase2 * var[c]);
  }
  xyz.x += 9.7470e-14 * std::sqrt(2.0 * kPi * 4.5282e+09) * std::cos(2.2399e+06 * phase + shift.x) *
           std::exp(-4.5282e+09 * phase2);
  xyz /= 1.0685e-7;
  // XYZ to linear Rec. 709 (sRGB primaries, D65).
  return {3.2404542 * xyz.x - 1.5371385 * xyz.y - 0.4985314 * xyz.z,
          -0.9692660 * xyz.x + 1.8760108 * xyz.y + 0.0415560 * xyz.z,
          0.0556434 * xyz.x - 0.2040259 * xyz.y + 1.0572252 * xyz.z};
}

}  // namespace

glm::dvec3 iridescent_fresnel(double outside_ior, double film_ior, const glm::dvec3& base_f0,
                              double thickness_nm, double cos_theta1) {
  // Into the film (Snell); total internal reflection reflects everything.
  const double ratio = outside_ior / film_ior;
  const double cos2_theta2 = 1.0 - ratio * ratio * (1.0 - cos_theta1 * cos_theta1);
  if (cos2_theta2 < 0.0) return glm::dvec3(1.0);
  const double cos_theta2 = std::sqrt(cos2_theta2);
  // First interface: outside -> film.
  const double r12 = schlick(ior_to_f0(film_ior, outside_ior), cos_theta1);
  const double t121 = 1.0 - r12;
  const double phi12 = film_ior < outside_ior ? kPi : 0.0;
  const double phi21 = kPi - phi12;
  // Second interface: film -> base, the base's ior from its F0.
  glm::dvec3 r23, phi23;
  for (int c = 0; c < 3; ++c) {
    const double root = std::sqrt(std::clamp(base_f0[c], 0.0, 0.9999));
    const double base_ior = (1.0 + root) / (1.0 - root);
    r23[c] = schlick(ior_to_f0(base_ior, film_ior), cos_theta2);
    phi23[c] = base_ior < film_ior ? kPi : 0.0;
  }
  const double opd = 2.0 * film_ior * thickness_nm * cos_theta2;
  const glm::dvec3 phi = glm::dvec3(phi21) + phi23;
  // Analytic spectral integration: the DC term C0 = R12 + Rs and two pairs of Diracs,
  // C_m = (Rs - T121) r123^m.
  glm::dvec3 out, cm, r123;
  for (int c = 0; c < 3; ++c) {
    const double r123_sq = std::clamp(r12 * r23[c], 1e-5, 0.9999);
    const double rs = t121 * t121 * r23[c] / (1.0 - r123_sq);
    r123[c] = std::sqrt(r123_sq);
    out[c] = r12 + rs;
    cm[c] = rs - t121;
  }
  for (int m = 1; m <= 2; ++m) {
    const glm::dvec3 s = 2.0 * sensitivity(m * opd, double(m) * phi);
    for (int c = 0; c < 3; ++c) {
      cm[c] *= r123[c];
      out[c] += cm[c] * s[c];
    }
  }
  return glm::max(out, glm::dvec3(0.0));
}

}  // namespace covrast::detail
