// KHR_materials_sheen's BRDF and its albedo table (shading/sheen.hpp).
#include "shading/sheen.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace covrast::detail {
namespace {

constexpr double kPi = std::numbers::pi;

/// l(x) of the visibility's Lambda, its five coefficients lerped between the fits at alpha = 0
/// and alpha = 1 by (1 - alpha)^2.
double sheen_l(double x, double alpha) {
  const double t = (1.0 - alpha) * (1.0 - alpha);
  const auto mix = [t](double at_one, double at_zero) { return at_one + (at_zero - at_one) * t; };
  const double a = mix(21.5473, 25.3245), b = mix(3.82987, 3.32435), c = mix(0.19823, 0.16801);
  const double d = mix(-1.97760, -1.27393), e = mix(-4.32054, -4.85967);
  return a / (1.0 + b * std::pow(x, c)) + d * x + e;
}

double sheen_lambda(double cos_theta, double alpha) {
  // Clamped: a unit-vector dot product can round above 1, and l(1 - x) then takes a negative
  // number to a fractional power (NaN).
  const double x = std::min(std::abs(cos_theta), 1.0);
  return x < 0.5 ? std::exp(sheen_l(x, alpha))
                 : std::exp(2.0 * sheen_l(0.5, alpha) - sheen_l(1.0 - x, alpha));
}

double sheen_alpha(double sheen_roughness) {
  return std::max(sheen_roughness * sheen_roughness, kMinSheenAlpha);
}

constexpr int kMuNodes = 32, kRoughnessNodes = 16;

/// E(mu, r) at the table's nodes: mu = i / 31 (0 replaced by 1e-4), r = j / 15, by the midpoint
/// rule over the hemisphere of l in (cos theta, phi), phi in [0, pi] doubled (the lobe is
/// symmetric about the plane of n and v).
std::vector<double> albedo_table() {
  constexpr int kCos = 128, kPhi = 64;
  std::vector<double> table(std::size_t(kMuNodes) * kRoughnessNodes);
  const glm::dvec3 n(0.0, 0.0, 1.0);
  for (int j = 0; j < kRoughnessNodes; ++j) {
    const double r = double(j) / (kRoughnessNodes - 1);
    for (int i = 0; i < kMuNodes; ++i) {
      const double mu = std::max(double(i) / (kMuNodes - 1), 1e-4);
      const glm::dvec3 v(std::sqrt(1.0 - mu * mu), 0.0, mu);
      double sum = 0.0;
      for (int a = 0; a < kCos; ++a) {
        const double cos_l = (a + 0.5) / kCos, sin_l = std::sqrt(1.0 - cos_l * cos_l);
        for (int b = 0; b < kPhi; ++b) {
          const double phi = kPi * (b + 0.5) / kPhi;
          const glm::dvec3 l(sin_l * std::cos(phi), sin_l * std::sin(phi), cos_l);
          sum += sheen_lobe(n, v, l, r) * cos_l;
        }
      }
      table[std::size_t(j) * kMuNodes + std::size_t(i)] = sum * (1.0 / kCos) * (2.0 * kPi / kPhi);
    }
  }
  return table;
}

}  // namespace

double sheen_lobe(const glm::dvec3& n, const glm::dvec3& v, const glm::dvec3& l,
                  double sheen_roughness) {
  const double n_dot_l = glm::dot(n, l), n_dot_v = glm::dot(n, v);
  if (!(n_dot_l > 0.0 && n_dot_v > 0.0)) return 0.0;
  const glm::dvec3 h_sum = l + v;
  const double h_length = glm::length(h_sum);
  const double n_dot_h = h_length > 0.0 ? glm::dot(n, h_sum) / h_length : 1.0;
  const double alpha = sheen_alpha(sheen_roughness);
  const double sin2h = std::max(1.0 - n_dot_h * n_dot_h, 0.0);
  const double d = (2.0 + 1.0 / alpha) * std::pow(sin2h, 0.5 / alpha) / (2.0 * kPi);
  const double vis = 1.0 / ((1.0 + sheen_lambda(n_dot_v, alpha) + sheen_lambda(n_dot_l, alpha)) *
                            (4.0 * n_dot_v * n_dot_l));
  return d * vis;
}

double sheen_albedo(double mu, double sheen_roughness) {
  static const std::vector<double> table = albedo_table();
  const double x = std::clamp(mu, 0.0, 1.0) * (kMuNodes - 1);
  const double y = std::clamp(sheen_roughness, 0.0, 1.0) * (kRoughnessNodes - 1);
  const int i0 = std::min(int(x), kMuNodes - 2), j0 = std::min(int(y), kRoughnessNodes - 2);
  const double fx = x - i0, fy = y - j0;
  const auto at = [&](int i, int j) { return table[std::size_t(j) * kMuNodes + std::size_t(i)]; };
  const double top = at(i0, j0) * (1.0 - fx) + at(i0 + 1, j0) * fx;
  const double bottom = at(i0, j0 + 1) * (1.0 - fx) + at(i0 + 1, j0 + 1) * fx;
  return top * (1.0 - fy) + bottom * fy;
}

}  // namespace covrast::detail
