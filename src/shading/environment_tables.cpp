// The environment's uniform-light tables (shading/environment_lighting.hpp, "split sum"):
// E_s, A and B of the BRDF under a uniform environment of radiance 1, as functions of n . v
// and perceptual roughness, integrated once per process by stratified quadrature (cosine
// directions for E_s, GGX half vectors for A and B) and interpolated bilinearly.
#include "shading/environment_lighting.hpp"
#include "shading/ggx_sampling.hpp"
#include "shading/pbr_terms.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace covrast::detail {
namespace {

/// Uniform-light tables: n . v in [0, 1] and perceptual roughness in [0, 1], both at
/// evenly spaced nodes; each entry from kTableSamples stratified directions.
constexpr int kTableMuNodes = 64;
constexpr int kTableRoughnessNodes = 32;
constexpr int kTableSamples = 4096;

/// The view direction with n . v = mu in the (x, z) plane of n = +Z.
glm::dvec3 view_at(double mu) { return {std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu}; }

struct UniformTables {
  std::vector<double> schlick_diffuse;   ///< [mu]: int s (n.l)+ dl / pi
  std::vector<double> specular;          ///< [r][mu]: int D V (n.l)+ dl
  std::vector<double> specular_schlick;  ///< [r][mu]: int s D V (n.l)+ dl
};

double table_mu(int i) {
  return std::max(kUniformTableMinMu, double(i) / double(kTableMuNodes - 1));
}

UniformTables build_uniform_tables() {
  UniformTables tables;
  tables.schlick_diffuse.resize(kTableMuNodes);
  tables.specular.resize(std::size_t(kTableMuNodes) * kTableRoughnessNodes);
  tables.specular_schlick.resize(tables.specular.size());
  const glm::dvec3 n(0.0, 0.0, 1.0), t(1.0, 0.0, 0.0), b(0.0, 1.0, 0.0);
  const std::vector<glm::dvec2> azimuths = hammersley_azimuths(kTableSamples);
  // The GGX half vectors of each roughness node (they do not depend on the view), with
  // n . h in w.
  std::vector<std::vector<glm::dvec4>> half_vectors(kTableRoughnessNodes);
  for (int j = 0; j < kTableRoughnessNodes; ++j) {
    const double r = double(j) / double(kTableRoughnessNodes - 1);
    const double alpha = std::max(r * r, kMinBrdfAlpha);
    for (int k = 0; k < kTableSamples; ++k) {
      double cos_h = 0.0;
      const glm::dvec3 h = ggx_half_vector((k + 0.5) / kTableSamples, azimuths[std::size_t(k)],
                                           alpha * alpha, n, t, b, cos_h);
      half_vectors[std::size_t(j)].push_back(glm::dvec4(h, cos_h));
    }
  }
  for (int i = 0; i < kTableMuNodes; ++i) {
    const double mu = table_mu(i);
    const glm::dvec3 v = view_at(mu);
    // Cosine-distributed l (pdf (n.l) / pi): int s (n.l)+ dl / pi = mean of s.
    double s_sum = 0.0;
    for (int k = 0; k < kTableSamples; ++k) {
      const double xi1 = (k + 0.5) / kTableSamples;
      const double sin_l = std::sqrt(xi1), cos_l = std::sqrt(1.0 - xi1);
      const glm::dvec2& azimuth = azimuths[std::size_t(k)];
      const glm::dvec3 l(sin_l * azimuth.x, sin_l * azimuth.y, cos_l);
      const glm::dvec3 h = glm::normalize(l + v);
      s_sum += schlick_weight(std::abs(glm::dot(v, h)));
    }
    tables.schlick_diffuse[std::size_t(i)] = s_sum / kTableSamples;
    for (int j = 0; j < kTableRoughnessNodes; ++j) {
      const double r = double(j) / double(kTableRoughnessNodes - 1);
      const double alpha = std::max(r * r, kMinBrdfAlpha), alpha2 = alpha * alpha;
      double a_sum = 0.0, b_sum = 0.0;
      for (const glm::dvec4& sample : half_vectors[std::size_t(j)]) {
        const glm::dvec3 h(sample);
        const double cos_h = sample.w;
        const double v_dot_h = glm::dot(v, h);
        if (!(v_dot_h > 0.0)) continue;
        const glm::dvec3 l = h * (2.0 * v_dot_h) - v;
        if (!(l.z > 0.0)) continue;
        // f cos / pdf with pdf(l) = D (n.h) / (4 v.h): V (n.l) 4 (v.h) / (n.h).
        const double w = smith_visibility(l.z, mu, alpha2) * l.z * 4.0 * v_dot_h / cos_h;
        a_sum += w;
        b_sum += w * schlick_weight(v_dot_h);
      }
      const std::size_t at = std::size_t(j) * kTableMuNodes + std::size_t(i);
      tables.specular[at] = a_sum / kTableSamples;
      tables.specular_schlick[at] = b_sum / kTableSamples;
    }
  }
  return tables;
}

const UniformTables& uniform_tables() {
  static const UniformTables tables = build_uniform_tables();  // thread-safe, once
  return tables;
}

}  // namespace

std::array<double, 3> uniform_environment_integrals(double mu, double roughness) {
  const UniformTables& tables = uniform_tables();
  const double x = std::clamp(mu, 0.0, 1.0) * (kTableMuNodes - 1);
  const double y = std::clamp(roughness, 0.0, 1.0) * (kTableRoughnessNodes - 1);
  const int i0 = std::min(int(x), kTableMuNodes - 2),
            j0 = std::min(int(y), kTableRoughnessNodes - 2);
  const double fx = x - i0, fy = y - j0;
  auto at = [&](const std::vector<double>& table, int i, int j) {
    return table[std::size_t(j) * kTableMuNodes + std::size_t(i)];
  };
  auto bilerp = [&](const std::vector<double>& table) {
    const double top = at(table, i0, j0) * (1.0 - fx) + at(table, i0 + 1, j0) * fx;
    const double bottom = at(table, i0, j0 + 1) * (1.0 - fx) + at(table, i0 + 1, j0 + 1) * fx;
    return top * (1.0 - fy) + bottom * fy;
  };
  const double s = tables.schlick_diffuse[std::size_t(i0)] * (1.0 - fx) +
                   tables.schlick_diffuse[std::size_t(i0 + 1)] * fx;
  return {s, bilerp(tables.specular), bilerp(tables.specular_schlick)};
}

}  // namespace covrast::detail
