// Image-based lighting: the moment pyramid for the irradiance, the radiance pyramid and the
// filtered GGX estimates for the rest (the formulas are in shading/environment_lighting.hpp).
#include "shading/environment_lighting.hpp"
#include "core/fork_join.hpp"
#include "shading/ggx_sampling.hpp"
#include "shading/pbr_terms.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>

namespace covrast::detail {
namespace {

constexpr double kPi = std::numbers::pi;
/// Finest moment cells: at most this many across (and half as many down). Cells the horizon
/// cuts take max(0, n . m); their error is at most Omega_cell sin(radius) each.
constexpr int kMomentCellsAcross = 64;
/// The irradiance nodes: E at the centres of a 128 x 64 equirectangular grid of normals.
constexpr int kIrradianceNodesAcross = 128;
constexpr int kIrradianceNodesDown = 64;
/// Prefiltered radiance: node 0 is the map itself (a mirror); nodes k = 1..kPrefilterNodes are
/// at perceptual roughness 2^((k - kPrefilterNodes) / 2), so alpha = roughness^2 doubles from
/// one to the next (0.0156 .. 1): the lobes of neighbours differ by the same factor, and
/// blending two of them stays close to the lobe between.
constexpr int kPrefilterNodes = 7;
/// A node's map is kPrefilterTexelsPerAlpha / alpha texels wide (its texels about alpha / 2
/// radians apart, a fraction of the lobe), rounded up to a power of two and kept within
/// [kPrefilterNarrowest, kPrefilterWidest] and the map's own width.
constexpr double kPrefilterTexelsPerAlpha = 6.4;
constexpr int kPrefilterWidest = 256;
constexpr int kPrefilterNarrowest = 32;
/// GGX directions per prefiltered texel: about kPrefilterBudget per node over its texels,
/// within [kPrefilterFewest, kPrefilterMost] (the small maps of rough nodes get many).
constexpr double kPrefilterBudget = 2.0e6;
constexpr int kPrefilterFewest = 64;
constexpr int kPrefilterMost = 1024;
/// Added to the filtered-importance-sampling level (Krivanek and Colbert add 1).
constexpr double kLodBias = 0.0;
/// A texel with at least this share of the map's power (luminance x solid angle) is a sun.
constexpr double kSunPowerShare = 0.01;
/// At most this many suns (the brightest); the rest stay in the map.
constexpr std::size_t kMaxSuns = 16;

double prefilter_node_roughness(int node) {
  // sqrt(2^(node - nodes)): ldexp is exact and sqrt correctly rounded, so the same bits on
  // every CPU.
  return std::sqrt(std::ldexp(1.0, node - kPrefilterNodes));
}

double luminance(const glm::dvec3& c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

int floor_pow2(int n) {
  int p = 1;
  while (p * 2 <= n) p *= 2;
  return p;
}

/// Bilinear interpolation of an equirectangular grid of `width` x `height` values (texel
/// centres at ((x + 0.5) / W, (y + 0.5) / H)) at `uv`: wrapping around in u, clamped at the
/// poles in v. The radiance pyramid's levels and the irradiance nodes are both such grids.
template <typename Value>
glm::dvec3 equirect_bilinear(const std::vector<Value>& values, int width, int height,
                             const glm::dvec2& uv) {
  const double x = uv.x * width - 0.5, y = uv.y * height - 0.5;
  const double x_floor = std::floor(x), y_floor = std::floor(y);
  const double fx = x - x_floor, fy = y - y_floor;
  // uv.x in [0, 1] puts x_floor in [-1, width - 1]: one step wraps it.
  const int x_int = int(x_floor);
  const int x0 = x_int < 0 ? width - 1 : std::min(x_int, width - 1);
  const int x1 = x0 + 1 == width ? 0 : x0 + 1;
  const int y0 = std::clamp(int(y_floor), 0, height - 1);
  const int y1 = std::clamp(int(y_floor) + 1, 0, height - 1);
  auto at = [&](int xi, int yi) {
    return glm::dvec3(values[std::size_t(yi) * std::size_t(width) + std::size_t(xi)]);
  };
  return (at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx) * (1.0 - fy) +
         (at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx) * fy;
}

/// The texels of a W x H map that carry at least kSunPowerShare of its power (luminance x
/// solid angle), at most kMaxSuns, brightest first (ties by index): each as a directional light
/// of illuminance L Omega from its centre direction (map frame), and set to zero in `texels`.
/// Only those few candidates are sorted.
std::vector<EnvironmentSun> take_out_suns(std::vector<glm::vec3>& texels, int w, int h) {
  const auto power_at = [&](std::size_t i, double omega) {
    return luminance(glm::dvec3(texels[i])) * omega;
  };
  double total = 0.0;
  for (int y = 0; y < h; ++y) {
    const double omega = environment_texel_solid_angle(y, w, h);
    for (int x = 0; x < w; ++x) total += power_at(std::size_t(y) * std::size_t(w) + x, omega);
  }
  struct Bright {
    double power;
    std::size_t index;
  };
  std::vector<Bright> bright;
  for (int y = 0; y < h; ++y) {
    const double omega = environment_texel_solid_angle(y, w, h);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
      const double power = power_at(i, omega);
      if (power > 0.0 && power >= kSunPowerShare * total) bright.push_back({power, i});
    }
  }
  std::sort(bright.begin(), bright.end(), [](const Bright& a, const Bright& b) {
    return a.power != b.power ? a.power > b.power : a.index < b.index;
  });
  std::vector<EnvironmentSun> suns;
  for (std::size_t k = 0; k < std::min(kMaxSuns, bright.size()); ++k) {
    const int x = int(bright[k].index % std::size_t(w)), y = int(bright[k].index / std::size_t(w));
    suns.push_back({environment_direction((x + 0.5) / w, (y + 0.5) / h),
                    glm::dvec3(texels[bright[k].index]) * environment_texel_solid_angle(y, w, h)});
    texels[bright[k].index] = glm::vec3(0.0f);
  }
  return suns;
}

}  // namespace

EnvironmentSky::EnvironmentSky(const EnvironmentLight& light)
    : map_(light.map.get()),
      cos_rotation_(std::cos(light.rotation_deg * (kPi / 180.0))),
      sin_rotation_(std::sin(light.rotation_deg * (kPi / 180.0))),
      intensity_(light.intensity) {}

glm::dvec3 EnvironmentSky::radiance(const glm::dvec3& d_world) const {
  const glm::dvec3 d_map = turn_about_y(d_world, cos_rotation_, -sin_rotation_);
  return equirect_bilinear(map_->radiance_linear, map_->width, map_->height,
                           environment_uv(d_map)) *
         intensity_;
}

PreparedEnvironmentMap::PreparedEnvironmentMap(const EnvironmentMap& map) {
  const int w = map.width, h = map.height;
  texel_solid_angle_ = 4.0 * kPi / (double(w) * double(h));
  // Suns: the brightest texels by power leave the map (zero in the copy the pyramids are
  // built from).
  std::vector<glm::vec3> texels = map.radiance_linear;
  suns_ = take_out_suns(texels, w, h);
  build_radiance_pyramid(std::move(texels), w, h);
  build_moment_pyramid();
  build_irradiance_nodes();
  build_prefiltered();
}

EnvironmentLighting::EnvironmentLighting(const EnvironmentLight& light)
    : prepared_(prepare_environment_map(*light.map)),
      suns_(prepared_->suns()),
      cos_rotation_(std::cos(light.rotation_deg * (kPi / 180.0))),
      sin_rotation_(std::sin(light.rotation_deg * (kPi / 180.0))),
      intensity_(light.intensity) {
  // The suns in the world frame, and x intensity.
  for (EnvironmentSun& sun : suns_) {
    sun.to_light = to_world(sun.to_light);
    sun.irradiance *= intensity_;
  }
}

// Radiance pyramid: each level halves the previous (rounding up), texels averaged with their
// solid angles as weights.
void PreparedEnvironmentMap::build_radiance_pyramid(std::vector<glm::vec3> texels, int w, int h) {
  radiance_.push_back({w, h, std::move(texels)});
  while (radiance_.back().width > 1 || radiance_.back().height > 1) {
    const RadianceLevel& fine = radiance_.back();
    RadianceLevel coarse{(fine.width + 1) / 2, (fine.height + 1) / 2, {}};
    coarse.texels.assign(std::size_t(coarse.width) * std::size_t(coarse.height), glm::vec3(0.0f));
    for (int y = 0; y < coarse.height; ++y) {
      for (int x = 0; x < coarse.width; ++x) {
        glm::dvec3 sum(0.0);
        double weight = 0.0;
        for (int fy = 2 * y; fy < std::min(2 * y + 2, fine.height); ++fy) {
          const double omega = environment_texel_solid_angle(fy, fine.width, fine.height);
          for (int fx = 2 * x; fx < std::min(2 * x + 2, fine.width); ++fx) {
            sum += glm::dvec3(
                       fine.texels[std::size_t(fy) * std::size_t(fine.width) + std::size_t(fx)]) *
                   omega;
            weight += omega;
          }
        }
        coarse.texels[std::size_t(y) * std::size_t(coarse.width) + std::size_t(x)] =
            glm::vec3(weight > 0.0 ? sum / weight : glm::dvec3(0.0));
      }
    }
    radiance_.push_back(std::move(coarse));
  }
}

void PreparedEnvironmentMap::set_cell_geometry(MomentCell& cell, double u0, double u1, double v0,
                                               double v1) {
  cell.centre = environment_direction(0.5 * (u0 + u1), 0.5 * (v0 + v1));
  // The farthest point of a latitude-longitude rectangle from its centre is a corner.
  double min_cos = 1.0;
  for (double u : {u0, u1}) {
    for (double v : {v0, v1}) {
      min_cos = std::min(min_cos, glm::dot(cell.centre, environment_direction(u, v)));
    }
  }
  const double radius = std::acos(std::clamp(min_cos, -1.0, 1.0)) + 1e-9;
  // Wider than a hemisphere: never wholly above or below a horizon.
  cell.sin_radius = radius < 0.5 * kPi ? std::sin(radius) : 2.0;
}

// Moment pyramid, from the radiance pyramid's level 0: the finest cells group whole texels;
// every coarser level merges 2 x 2.
void PreparedEnvironmentMap::build_moment_pyramid() {
  const int w = radiance_[0].width, h = radiance_[0].height;
  const int cells_x = floor_pow2(std::min(w, kMomentCellsAcross));
  const int cells_y = floor_pow2(std::min(h, kMomentCellsAcross / 2));
  MomentLevel finest{cells_x, cells_y, {}};
  finest.cells.resize(std::size_t(cells_x) * std::size_t(cells_y));
  for (int y = 0; y < h; ++y) {
    const double omega = environment_texel_solid_angle(y, w, h);
    const int cy = int(std::int64_t(y) * cells_y / h);
    for (int x = 0; x < w; ++x) {
      const int cx = int(std::int64_t(x) * cells_x / w);
      const glm::dvec3 d = environment_direction((x + 0.5) / w, (y + 0.5) / h) * omega;
      const glm::dvec3 l(radiance_[0].texels[std::size_t(y) * std::size_t(w) + std::size_t(x)]);
      MomentCell& cell = finest.cells[std::size_t(cy) * std::size_t(cells_x) + std::size_t(cx)];
      for (int c = 0; c < 3; ++c) cell.m[std::size_t(c)] += d * l[c];
    }
  }
  for (int cy = 0; cy < cells_y; ++cy) {
    for (int cx = 0; cx < cells_x; ++cx) {
      set_cell_geometry(finest.cells[std::size_t(cy) * std::size_t(cells_x) + std::size_t(cx)],
                        double(cx) / cells_x, double(cx + 1) / cells_x, double(cy) / cells_y,
                        double(cy + 1) / cells_y);
    }
  }
  moments_.push_back(std::move(finest));
  while (moments_.back().width > 2 && moments_.back().height > 1) {
    const MomentLevel& fine = moments_.back();
    MomentLevel coarse{fine.width / 2, fine.height / 2, {}};
    coarse.cells.resize(std::size_t(coarse.width) * std::size_t(coarse.height));
    for (int cy = 0; cy < coarse.height; ++cy) {
      for (int cx = 0; cx < coarse.width; ++cx) {
        MomentCell& cell =
            coarse.cells[std::size_t(cy) * std::size_t(coarse.width) + std::size_t(cx)];
        for (int k = 0; k < 4; ++k) {
          const MomentCell& child =
              fine.cells[std::size_t(2 * cy + k / 2) * std::size_t(fine.width) +
                         std::size_t(2 * cx + k % 2)];
          for (int c = 0; c < 3; ++c) cell.m[std::size_t(c)] += child.m[std::size_t(c)];
        }
        set_cell_geometry(cell, double(cx) / coarse.width, double(cx + 1) / coarse.width,
                          double(cy) / coarse.height, double(cy + 1) / coarse.height);
      }
    }
    moments_.push_back(std::move(coarse));
  }
}

// The irradiance of the map without its suns at the nodes, by the exact walk; smooth (a
// cosine-weighted integral of a map without bright points), so interpolated between them.
void PreparedEnvironmentMap::build_irradiance_nodes() {
  irradiance_nodes_.reserve(std::size_t(kIrradianceNodesAcross) * kIrradianceNodesDown);
  for (int y = 0; y < kIrradianceNodesDown; ++y) {
    for (int x = 0; x < kIrradianceNodesAcross; ++x) {
      irradiance_nodes_.push_back(walk_irradiance(environment_direction(
          (x + 0.5) / kIrradianceNodesAcross, (y + 0.5) / kIrradianceNodesDown)));
    }
  }
}

glm::dvec3 EnvironmentLighting::to_world(const glm::dvec3& d) const {
  return turn_about_y(d, cos_rotation_, sin_rotation_);
}

glm::dvec3 EnvironmentLighting::to_map(const glm::dvec3& d) const {
  return turn_about_y(d, cos_rotation_, -sin_rotation_);
}

glm::dvec3 EnvironmentLighting::irradiance(const glm::dvec3& n_world) const {
  glm::dvec3 e = irradiance_without_suns(n_world);
  for (const EnvironmentSun& sun : suns_) {
    e += sun.irradiance * std::max(0.0, glm::dot(n_world, sun.to_light));
  }
  return e;
}

glm::dvec3 EnvironmentLighting::irradiance_without_suns(const glm::dvec3& n_world) const {
  return prepared_->irradiance_without_suns(to_map(n_world)) * intensity_;
}

glm::dvec3 PreparedEnvironmentMap::irradiance_without_suns(const glm::dvec3& n_map) const {
  return equirect_bilinear(irradiance_nodes_, kIrradianceNodesAcross, kIrradianceNodesDown,
                           environment_uv(n_map));
}

glm::dvec3 PreparedEnvironmentMap::walk_irradiance(const glm::dvec3& n) const {
  glm::dvec3 e(0.0);
  // Depth-first over the cells the horizon cuts; (level, index) pairs.
  struct Pending {
    int level;
    int index;
  };
  static thread_local std::vector<Pending> stack;  // reused: no allocation per point
  stack.clear();
  const int top = int(moments_.size()) - 1;
  for (int i = 0; i < int(moments_[std::size_t(top)].cells.size()); ++i) stack.push_back({top, i});
  while (!stack.empty()) {
    const Pending p = stack.back();
    stack.pop_back();
    const MomentLevel& level = moments_[std::size_t(p.level)];
    const MomentCell& cell = level.cells[std::size_t(p.index)];
    const double c = glm::dot(n, cell.centre);
    if (c <= -cell.sin_radius) continue;  // wholly below the horizon
    if (c >= cell.sin_radius || p.level == 0) {
      // Wholly above: exact; a finest cell the horizon cuts: max(0, n . m).
      for (int k = 0; k < 3; ++k) {
        const double part = glm::dot(n, cell.m[std::size_t(k)]);
        e[k] += c >= cell.sin_radius ? part : std::max(0.0, part);
      }
      continue;
    }
    const int cx = p.index % level.width, cy = p.index / level.width;
    const int fine_width = moments_[std::size_t(p.level - 1)].width;
    for (int k = 0; k < 4; ++k) {
      stack.push_back({p.level - 1, (2 * cy + k / 2) * fine_width + 2 * cx + k % 2});
    }
  }
  return e;
}

glm::dvec3 PreparedEnvironmentMap::bilinear(const RadianceLevel& level,
                                            const glm::dvec2& uv) const {
  return equirect_bilinear(level.texels, level.width, level.height, uv);
}

glm::dvec3 PreparedEnvironmentMap::lookup(const glm::dvec3& d_map, double lod) const {
  const double top = double(radiance_.size() - 1);
  lod = std::clamp(lod, 0.0, top);
  const int l0 = std::min(int(lod), int(radiance_.size()) - 1);
  const double t = lod - l0;
  const glm::dvec2 uv = environment_uv(d_map);
  const glm::dvec3 a = bilinear(radiance_[std::size_t(l0)], uv);
  if (t == 0.0) return a;
  return a * (1.0 - t) + bilinear(radiance_[std::size_t(l0 + 1)], uv) * t;
}

void PreparedEnvironmentMap::build_prefiltered() {
  const int widest = std::min(floor_pow2(radiance_[0].width), kPrefilterWidest);
  for (int node = 1; node <= kPrefilterNodes; ++node) {
    const double roughness = prefilter_node_roughness(node);
    const double alpha = std::max(roughness * roughness, kMinBrdfAlpha), alpha2 = alpha * alpha;
    int width = kPrefilterNarrowest;
    while (width < widest && width < kPrefilterTexelsPerAlpha / alpha) width *= 2;
    RadianceLevel level{width, std::max(1, width / 2), {}};
    const int samples =
        std::clamp(floor_pow2(int(kPrefilterBudget / (double(width) * level.height))),
                   kPrefilterFewest, kPrefilterMost);
    const std::vector<PrefilterSample> lobe = prefilter_lobe(samples, alpha2);
    level.texels.resize(std::size_t(level.width) * std::size_t(level.height));
    // Rows are independent and each texel's sum runs in a fixed order: the same bits for
    // every thread count.
    fork_join_for(0, level.height, [&](int y) {
      for (int x = 0; x < level.width; ++x) {
        const glm::dvec3 r =
            environment_direction((x + 0.5) / level.width, (y + 0.5) / level.height);
        level.texels[std::size_t(y) * std::size_t(level.width) + std::size_t(x)] =
            glm::vec3(prefilter_texel(r, lobe));
      }
    });
    prefiltered_.push_back(std::move(level));
  }
}

std::vector<PreparedEnvironmentMap::PrefilterSample> PreparedEnvironmentMap::prefilter_lobe(
    int samples, double alpha2) const {
  // n = v = r (the split-sum assumption): P(r) = sum L(l) w / sum w over GGX half vectors with
  // w = V(n.l, 1) (n.l), the weight of A's estimator at n = v (Karis, "Real Shading in Unreal
  // Engine 4", SIGGRAPH 2013 course notes, weights by n.l alone). In the frame of r a sample
  // depends only on its index, so its direction, weight and pyramid level are computed here
  // once per node: the level of its share of the sphere 1 / (N pdf), pdf(l) = D (n.h) / (4
  // v.h) = D / 4 with v = n (filtered importance sampling).
  const std::vector<glm::dvec2> azimuths = hammersley_azimuths(samples);
  const glm::dvec3 n(0.0, 0.0, 1.0), t(1.0, 0.0, 0.0), b(0.0, 1.0, 0.0);
  std::vector<PrefilterSample> lobe;
  for (int k = 0; k < samples; ++k) {
    double cos_h = 0.0;
    const glm::dvec3 h =
        ggx_half_vector((k + 0.5) / samples, azimuths[std::size_t(k)], alpha2, n, t, b, cos_h);
    const double n_dot_l = 2.0 * cos_h * cos_h - 1.0;
    if (!(n_dot_l > 0.0)) continue;
    const double k_d = cos_h * cos_h * (alpha2 - 1.0) + 1.0;
    const double pdf = alpha2 / (kPi * k_d * k_d) / 4.0;
    const double lod = 0.5 * std::log2(1.0 / (samples * pdf * texel_solid_angle_)) + kLodBias;
    lobe.push_back({h * (2.0 * cos_h) - n, smith_visibility(n_dot_l, 1.0, alpha2) * n_dot_l, lod});
  }
  return lobe;
}

glm::dvec3 PreparedEnvironmentMap::prefilter_texel(const glm::dvec3& r,
                                                   const std::vector<PrefilterSample>& lobe) const {
  glm::dvec3 t, b;
  tangent_frame(r, t, b);
  glm::dvec3 sum(0.0);
  double weight = 0.0;
  for (const PrefilterSample& sample : lobe) {
    const glm::dvec3 l = t * sample.l_local.x + b * sample.l_local.y + r * sample.l_local.z;
    sum += lookup(l, sample.lod) * sample.weight;
    weight += sample.weight;
  }
  return weight > 0.0 ? sum / weight : lookup(r, 0.0);
}

glm::dvec3 PreparedEnvironmentMap::prefiltered_radiance(const glm::dvec3& r_map,
                                                        double roughness) const {
  // Between the map and node 1 linear in roughness; between two nodes linear in log alpha;
  // bilinear within each.
  roughness = std::clamp(roughness, 0.0, 1.0);
  const double first = prefilter_node_roughness(1);
  int k0 = 0;
  double t = roughness / first;
  if (roughness >= first) {
    const double x = kPrefilterNodes + 2.0 * std::log2(roughness);
    k0 = std::clamp(int(x), 1, kPrefilterNodes - 1);
    t = std::min(1.0, x - k0);
  }
  const glm::dvec2 uv = environment_uv(r_map);
  auto node = [&](int k) {
    const RadianceLevel& level = k == 0 ? radiance_[0] : prefiltered_[std::size_t(k - 1)];
    return bilinear(level, uv);
  };
  const glm::dvec3 a = node(k0);
  return t == 0.0 ? a : a * (1.0 - t) + node(k0 + 1) * t;
}

EnvironmentIntegrals EnvironmentLighting::integrals(const glm::dvec3& n_world,
                                                    const glm::dvec3& v_world, double roughness,
                                                    const glm::dvec3& mirror_normal_world) const {
  EnvironmentIntegrals out;
  out.irradiance = irradiance_without_suns(n_world);
  const glm::dvec3 n = to_map(n_world);
  glm::dvec3 v = to_map(v_world);
  // A view at or below the shading horizon (normal maps, interpolated normals): moved to just
  // above it, as the BRDF's |n . v| would see it.
  double mu = glm::dot(n, v);
  if (mu < kUniformTableMinMu) {
    v = glm::normalize(v + n * (kUniformTableMinMu - mu));
    mu = std::max(glm::dot(n, v), kUniformTableMinMu);
  }
  const std::array<double, 3> uniform = uniform_environment_integrals(mu, roughness);
  out.irradiance_schlick = out.irradiance * (uniform[0] / kPi);

  // Split sum: the radiance prefiltered around the mirror direction times the uniform-light
  // values, exact when L is uniform.
  glm::dvec3 r = n * (2.0 * mu) - v;
  if (mirror_normal_world != n_world) {
    const glm::dvec3 mirror = to_map(mirror_normal_world);
    r = mirror * (2.0 * glm::dot(mirror, v)) - v;
  }
  const glm::dvec3 prefiltered = prepared_->prefiltered_radiance(r, roughness) * intensity_;
  out.specular = prefiltered * uniform[1];
  out.specular_schlick = prefiltered * uniform[2];
  return out;
}

}  // namespace covrast::detail
