// Image-based lighting (docs/environments.md): an environment map prepared once (and kept for
// later renders of the same texels) so that shade_point can integrate the glTF BRDF against it
// at every shading point.
//
// Outgoing radiance from the environment at a point with unit normal n and view v:
//   L_o = integral over the sphere of f(l, v) L(l) max(0, n . l) dl
// with f the glTF BRDF (Specification Appendix B.3.5, shading/shading.cpp pbr_brdf):
//   f = (1 - F) c_diff / pi + F D V,   F = f0 + (1 - f0) s,   s = (1 - |v . h|)^5,
// which splits into four integrals that do not depend on the base colour:
//   E   = int L (n.l)+           (irradiance)         E_s = int s L (n.l)+ / pi
//   A   = int D V L (n.l)+                            B   = int s D V L (n.l)+
//   L_o = c_diff (1 - f0) (E / pi - E_s) + f0 A + (1 - f0) B.
// E is exact up to the texels cut by the horizon: the map is grouped into a pyramid of cells
// that keep the first moment m = sum_t L_t d_t Omega_t of their texels, and for a cell wholly
// above the horizon int_cell L (n.l) dl = n . m exactly (n . l is linear in l); cells the
// horizon cuts are refined down to the finest cells, which take max(0, n . m). E is computed so
// at the nodes of a 128 x 64 grid of normals and interpolated bilinearly between them (the
// map without its suns is smooth after the cosine convolution).
// A and B are the split sum the glTF viewers compute (Karis, "Real Shading in Unreal Engine 4",
// SIGGRAPH 2013 course notes): A = P(r, roughness) A_1(n.v, roughness), B likewise with B_1,
// where A_1, B_1 are their values under uniform light (tables computed once by dense
// quadrature) and P is the radiance prefiltered by the GGX lobe of a surface seen head-on
// (n = v = r) around the mirror direction r, weighted by V (n.l) so that it is the lobe of A
// itself at n = v (Karis weights by n.l alone). P is prepared at set-up in small
// equirectangular maps at seven roughness nodes (alpha doubling from 1/64 to 1), each texel
// by GGX directions read from a radiance pyramid at the level of each direction's solid angle
// (filtered importance sampling: Krivanek and Colbert, "Real-time shading with filtered
// importance sampling", EGSR 2008), and read at shading time bilinearly between two nodes.
// E_s is E times its uniform-light ratio. A uniform environment is integrated exactly (the
// white furnace); elsewhere the error is the split sum's (its lobe is that of n = v at every
// view: at grazing views the true lobe is stretched and turned) and the prefiltering's;
// docs/environments.md gives both as measured against brute-force quadrature.
#pragma once

#include <covrast/environment.hpp>

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace covrast::detail {

/// The parts of L_o that depend on the environment, for one (n, v, roughness).
struct EnvironmentIntegrals {
  glm::dvec3 irradiance{0.0};          ///< E = int L (n.l)+ dl
  glm::dvec3 irradiance_schlick{0.0};  ///< E_s = int s L (n.l)+ dl / pi
  glm::dvec3 specular{0.0};            ///< A = int D V L (n.l)+ dl
  glm::dvec3 specular_schlick{0.0};    ///< B = int s D V L (n.l)+ dl
};

/// A texel bright enough to be lit as a directional light (sun-like): direction and
/// illuminance L Omega, in the world frame.
struct EnvironmentSun {
  glm::dvec3 to_light;
  glm::dvec3 irradiance;
};

/// What the lighting keeps of a map: built from its texels alone (in the map's frame, at
/// intensity 1), so one preparation serves every light, rotation and intensity with the same
/// texels (prepare_environment_map keeps the recent ones).
class PreparedEnvironmentMap {
 public:
  /// The moment pyramid, the radiance pyramid, the irradiance nodes and the prefiltered
  /// nodes of a non-empty map; its suns taken out.
  explicit PreparedEnvironmentMap(const EnvironmentMap& map);

  /// The suns, in the map's frame, at intensity 1.
  const std::vector<EnvironmentSun>& suns() const { return suns_; }
  /// E(n) without the suns for a unit normal in the map's frame, from the irradiance nodes.
  glm::dvec3 irradiance_without_suns(const glm::dvec3& n_map) const;
  /// The radiance prefiltered by the GGX lobe of `roughness` around map direction r_map.
  glm::dvec3 prefiltered_radiance(const glm::dvec3& r_map, double roughness) const;

 private:
  struct MomentCell {
    glm::dvec3 centre;            ///< unit direction of the cell's uv centre
    double sin_radius;            ///< sin of the cell's angular radius around `centre`
    std::array<glm::dvec3, 3> m;  ///< per channel: sum_t L_t[c] d_t Omega_t
  };
  struct MomentLevel {
    int width = 0, height = 0;
    std::vector<MomentCell> cells;
  };
  struct RadianceLevel {
    int width = 0, height = 0;
    std::vector<glm::vec3> texels;
  };

  /// E(n) of the map without suns for a unit normal in the map's frame, by the pyramid walk.
  glm::dvec3 walk_irradiance(const glm::dvec3& n_map) const;
  glm::dvec3 lookup(const glm::dvec3& d_map, double lod) const;
  glm::dvec3 bilinear(const RadianceLevel& level, const glm::dvec2& uv) const;
  /// One GGX direction of the prefiltering lobe, in the frame of the mirror direction (+Z).
  struct PrefilterSample {
    glm::dvec3 l_local;
    double weight;  ///< V(n.l, 1) (n.l)
    double lod;     ///< pyramid level of its share of the sphere
  };
  void build_radiance_pyramid(std::vector<glm::vec3> texels, int width, int height);
  static void set_cell_geometry(MomentCell& cell, double u0, double u1, double v0, double v1);
  void build_moment_pyramid();
  void build_irradiance_nodes();
  void build_prefiltered();
  std::vector<PrefilterSample> prefilter_lobe(int samples, double alpha2) const;
  glm::dvec3 prefilter_texel(const glm::dvec3& r, const std::vector<PrefilterSample>& lobe) const;

  std::vector<EnvironmentSun> suns_;  ///< map frame, intensity 1
  std::vector<MomentLevel> moments_;  ///< [0] the finest cells, back() the roots
  std::vector<RadianceLevel> radiance_;
  std::vector<RadianceLevel> prefiltered_;    ///< nodes 1..kPrefilterNodes (node 0: radiance_[0])
  std::vector<glm::dvec3> irradiance_nodes_;  ///< walk_irradiance at the node normals
  double texel_solid_angle_ = 0.0;            ///< 4 pi / (W H) of level 0
};

/// The preparation of `map` (non-empty). A process-wide cache keeps the most recently used
/// preparations with a copy of the texels each was built from; a map whose size and texel
/// bits equal a kept copy gets that preparation (the same object, so the same bits as a new
/// one), anything else, a map changed in place included, is prepared anew
/// (environment_map_cache.cpp). Safe to call from several threads.
std::shared_ptr<const PreparedEnvironmentMap> prepare_environment_map(const EnvironmentMap& map);

/// The cache's counts since the process started (the tests read them).
struct EnvironmentMapCacheCounts {
  std::uint64_t hits = 0;
  std::uint64_t preparations = 0;
};
EnvironmentMapCacheCounts environment_map_cache_counts();

/// An environment light ready for shading: the prepared map, turned and scaled as the light
/// says.
class EnvironmentLighting {
 public:
  /// Prepares `light` (its map must be non-empty) through prepare_environment_map; intensity
  /// and rotation are applied at evaluation.
  explicit EnvironmentLighting(const EnvironmentLight& light);

  /// E(n) = int L(l) max(0, n . l) dl for a unit world-space normal.
  glm::dvec3 irradiance(const glm::dvec3& n_world) const;
  /// E(n) without the suns (integrals()' irradiance, alone).
  glm::dvec3 irradiance_without_suns(const glm::dvec3& n_world) const;

  /// All four integrals, without the suns, for unit world-space n and v (n . v may be <= 0: then
  /// only E counts) and perceptual roughness in [0, 1].
  EnvironmentIntegrals integrals(const glm::dvec3& n_world, const glm::dvec3& v_world,
                                 double roughness) const {
    return integrals(n_world, v_world, roughness, n_world);
  }
  /// The same with the prefiltered radiance read around the mirror direction of v about
  /// `mirror_normal_world` (unit) instead of n: KHR_materials_anisotropy's bent normal.
  EnvironmentIntegrals integrals(const glm::dvec3& n_world, const glm::dvec3& v_world,
                                 double roughness, const glm::dvec3& mirror_normal_world) const;

  /// The texels taken out of the map as directional lights (integrals() leaves them out;
  /// irradiance() includes them): each holds at least kSunPowerShare of the map's power.
  const std::vector<EnvironmentSun>& suns() const { return suns_; }
  /// The preparation this light reads (shared with other lights of the same texels).
  const PreparedEnvironmentMap& prepared() const { return *prepared_; }

 private:
  glm::dvec3 to_map(const glm::dvec3& d) const;
  glm::dvec3 to_world(const glm::dvec3& d) const;

  std::shared_ptr<const PreparedEnvironmentMap> prepared_;
  std::vector<EnvironmentSun> suns_;  ///< world frame, x intensity
  double cos_rotation_ = 1.0, sin_rotation_ = 0.0;
  double intensity_ = 1.0;
};

/// R_y(a) d, given cos a and sin a: a map turned by a about +Y into the world is
/// turn_about_y(d, cos a, sin a), and a world direction in the map is turn_about_y(d, cos a,
/// -sin a).
inline glm::dvec3 turn_about_y(const glm::dvec3& d, double cos_a, double sin_a) {
  return {d.x * cos_a + d.z * sin_a, d.y, -d.x * sin_a + d.z * cos_a};
}

/// What a skybox shows: the radiance of a light's map arriving from a unit world direction
/// (turned and scaled as the light says), bilinear in the map with its suns left in. The
/// light's map must outlive it.
class EnvironmentSky {
 public:
  explicit EnvironmentSky(const EnvironmentLight& light);
  glm::dvec3 radiance(const glm::dvec3& d_world) const;

 private:
  const EnvironmentMap* map_;
  double cos_rotation_ = 1.0, sin_rotation_ = 0.0;
  double intensity_ = 1.0;
};

/// Uniform-light values (L = 1) of E_s, A and B for n . v = mu and perceptual roughness r:
/// {int s (n.l)+ dl / pi, int D V (n.l)+ dl, int s D V (n.l)+ dl}.
/// From tables computed once per process by dense quadrature, interpolated bilinearly.
/// Exposed for the tests.
std::array<double, 3> uniform_environment_integrals(double mu, double roughness);

/// The smallest n . v of the tables' first node (n . v = 0 has no reflection); a view below it
/// is moved up to it before the tables are read.
inline constexpr double kUniformTableMinMu = 1e-4;

}  // namespace covrast::detail
