// Raster stage, coverage mode: order-independent transparency in the A-buffer (abuffer.hpp,
// docs/transparency.md). Fragments of BLEND triangles live in a per-pixel list of their own;
// the opaque fragments resolve as they always do. A pixel with transparent fragments is
// composited front to back in exact depth order, per sub-pixel sample region:
//
//   colour = sum_j  area_j alpha_j S_j c_j  +  sum_o  W_o keep_o c_o
//
// - j runs over the transparent fragments, area_j its exact coverage (the kernel's 8.8
//   value), alpha_j and c_j its alpha and colour at the pixel centre clamped into it (as
//   shading), S_j the mean over the 256 mask samples it covers of V_j(s) T_j(s): V_j(s) = 1
//   where it is nearer than the nearest opaque surface at s and behind no transmissive
//   fragment with alpha > 0 (composite.hpp, ends_layers), T_j(s) = prod pass_i over the
//   transparent fragments i nearer than it at s (ties: lower primitive index first), pass_i =
//   (1 - alpha_i) + alpha_i filter_i per channel (shading/composite.hpp: a transmissive
//   fragment's filter tints what it passes; 0 for every other one).
//   The front fragment of a stack has S_j = 1 and keeps its exact area.
// - o runs over the opaque contributors (opaque fragments, the pixel's opaque surface, the
//   background), W_o their weights from the opaque resolve, keep_o the mean over the samples
//   where o is the nearest opaque surface of T(s) = prod pass_i over every transparent
//   fragment in front of it there.
// A fragment too thin to own a sample is judged at one point inside its part of the pixel.
// Everything is per pixel and sorted by depth, so draw order does not matter.
#include "raster/coverage/abuffer.hpp"

#include "core/testing_hooks.hpp"
#include "raster/coverage/abuffer_planes.hpp"
#include "raster/coverage/fragment_shading.hpp"
#include "shading/composite.hpp"

#include <algorithm>
#include <limits>

namespace covrast::detail {

/// One transparent fragment of the pixel being resolved.
struct ABufferTile::Clear {
  const TriangleSetup* t;
  double area;   ///< exact coverage [pixels]
  double alpha;  ///< at the shading point
  glm::vec3 rgb;
  glm::dvec3 pass;   ///< (1 - alpha) + alpha filter
  bool ends_layers;  ///< transmissive: only the opaque scene shows behind it (composite.hpp)
  SampleMask mask;
  int owned;              ///< samples in mask
  glm::dvec3 shown{0.0};  ///< sum over its samples of V T (then the mean S)
};

void ABufferTile::add_transparent(int x, int y, const TriangleSetup* t, std::uint32_t coverage,
                                  double centre_z) {
  const std::size_t pixel = std::size_t(y - rect_.y0) * stride_ + (x - rect_.x0);
  // Behind (or level with) the opaque surface at all four corners, or behind everything a
  // closed set or the samples hide: shows nowhere. The opaque surface only moves nearer.
  if (centre_z - depth_reach(*t) >= occluder_z_[pixel]) return;
  if (layer_[pixel] != Layer::Sampled && opaque_[pixel] != nullptr &&
      order_against_opaque(*t, centre_z, pixel, x, y) == DepthOrder::Behind) {
    return;
  }
  if (!any_transparent_) {
    std::fill(transparent_head_.begin(), transparent_head_.end(), kEnd);
    any_transparent_ = true;
  }
  const auto index = std::uint32_t(transparent_pool_.size());
  transparent_pool_.push_back(Fragment{t, transparent_head_[pixel], coverage});
  transparent_head_[pixel] = index;
}

void ABufferTile::opaque_samples(std::size_t pixel, int x, int y, double* z,
                                 const TriangleSetup** id) const {
  if (layer_[pixel] == Layer::Sampled) {
    const PixelSamples& samples = samples_[tail_[pixel]];
    for (int k = 0; k < kMaskSamples; ++k) {
      z[k] = samples.z[k];
      id[k] = samples.winner[k];
    }
    return;
  }
  const TriangleSetup* opaque = opaque_[pixel];
  if (opaque != nullptr) {
    const SamplePlane plane(*opaque, x, y);
    for (int k = 0; k < kMaskSamples; ++k) z[k] = plane.at(k);
  } else {
    std::fill(z, z + kMaskSamples, std::numeric_limits<double>::infinity());
  }
  std::fill(id, id + kMaskSamples, opaque);
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    const TriangleSetup* t = pool_[f].triangle;
    const SampleMask mask =
        (pool_[f].coverage & kMergedFlag) ? merged_piece(f).mask : pixel_sample_mask(*t, x, y);
    const SamplePlane plane(*t, x, y);
    for_each_sample(mask, [&](int k) {
      const double zk = plane.at(k);
      if (zk < z[k]) {
        z[k] = zk;
        id[k] = t;
      }
    });
  }
}

bool ABufferTile::uniform_transparency(std::size_t pixel, int x, int y, glm::dvec3& transmit,
                                       glm::dvec3& light) const {
  if (layer_[pixel] == Layer::Sampled) return false;
  // The nearest any opaque contributor gets in the pixel.
  double opaque_min = opaque_[pixel] != nullptr ? depth_range(*opaque_[pixel], x, y).min : kFar;
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    const TriangleSetup* const* pieces;
    const int count = fragment_pieces(f, pieces);
    for (int k = 0; k < count; ++k) {
      opaque_min = std::min(opaque_min, depth_range(*pieces[k], x, y).min);
    }
  }
  struct Layer1 {
    const TriangleSetup* t;
    DepthRange range;
  };
  thread_local std::vector<Layer1> layers;
  layers.clear();
  for (std::uint32_t f = transparent_head_[pixel]; f != kEnd; f = transparent_pool_[f].next) {
    const TriangleSetup* t = transparent_pool_[f].triangle;
    const DepthRange range = depth_range(*t, x, y);
    if (transparent_pool_[f].coverage != std::uint32_t(kCoverageOne) || !(range.max < opaque_min)) {
      return false;
    }
    layers.push_back({t, range});
  }
  std::sort(layers.begin(), layers.end(),
            [](const Layer1& a, const Layer1& b) { return a.range.min < b.range.min; });
  for (std::size_t k = 1; k < layers.size(); ++k) {
    if (!(layers[k - 1].range.max < layers[k].range.min)) return false;  // they may cross
  }
  FrontToBack layers_over;
  for (const Layer1& layer : layers) layers_over.add(shade_fragment_rgba(*layer.t, x, y));
  transmit = layers_over.transmit;
  light = layers_over.light;
  return true;
}

glm::vec3 ABufferTile::opaque_through(std::size_t pixel, int x, int y, glm::vec3 background,
                                      float& depth, const Transmittance& tr) {
  if (layer_[pixel] == Layer::Sampled) return resolve_samples(pixel, x, y, background, depth, &tr);
  if (head_[pixel] != kEnd) return resolve_pixel(pixel, x, y, background, depth, &tr);
  const TriangleSetup* o = opaque_[pixel];
  depth =
      o != nullptr ? float(o->depth_at(x + 0.5, y + 0.5)) : std::numeric_limits<float>::infinity();
  return (o != nullptr ? shade_fragment(*o, x, y) : background) * glm::vec3(tr.of(o));
}

void ABufferTile::transmittance_by_samples(std::vector<Clear>& clear, int x, int y,
                                           const double* z_opaque, const TriangleSetup* const* id,
                                           Transmittance& tr) {
  const int n = int(clear.size());
  thread_local std::vector<SamplePlane> plane;
  plane.clear();
  for (const Clear& c : clear) plane.emplace_back(*c.t, x, y);
  // Per sample: the transparent fragments in front of the opaque surface, nearest first.
  glm::dvec3 sum_t[kMaskSamples + 1], total_t(0.0);
  int count[kMaskSamples + 1];
  thread_local std::vector<std::pair<double, int>> stack;
  for (int k = 0; k < kMaskSamples; ++k) {
    stack.clear();
    for (int j = 0; j < n; ++j) {
      if (!clear[j].mask.has(k)) continue;
      const double z = plane[j].at(k);
      if (z < z_opaque[k]) stack.emplace_back(z, j);
    }
    std::sort(stack.begin(), stack.end(), [&](const auto& a, const auto& b) {
      return nearer_first(a.first, *clear[a.second].t, b.first, *clear[b.second].t);
    });
    glm::dvec3 t(1.0);
    for (const auto& [z, j] : stack) {
      clear[j].shown += t;
      t *= clear[j].pass;
      if (clear[j].ends_layers) break;
    }
    total_t += t;
    int slot = 0;
    while (slot < tr.n && tr.who[slot] != id[k]) ++slot;
    if (slot == tr.n) {
      tr.who[tr.n++] = id[k];
      sum_t[slot] = glm::dvec3(0.0);
      count[slot] = 0;
    }
    sum_t[slot] += t;
    ++count[slot];
  }
  for (int s = 0; s < tr.n; ++s) tr.keep[s] = sum_t[s] / double(count[s]);
  tr.fallback = total_t / double(kMaskSamples);
}

void ABufferTile::sliver_transmittance(std::size_t pixel, int x, int y, std::vector<Clear>& clear,
                                       const Transmittance& tr) const {
  // V T at one point inside the sliver's part of the pixel, against the opaque contributors
  // that own samples (and the opaque surface) containing it.
  const int n = int(clear.size());
  for (int j = 0; j < n; ++j) {
    Clear& c = clear[j];
    if (c.owned > 0) continue;
    double px, py;
    if (!inner_point(part_in_pixel(*c.t, x, y), px, py)) continue;
    const double zj = c.t->depth_at(px, py);
    bool visible = true;
    for (int s = 0; s < tr.n && visible; ++s) {
      if (tr.who[s] != nullptr && covers_point(*tr.who[s], px, py)) {
        visible = !(tr.who[s]->depth_at(px, py) <= zj);
      }
    }
    if (const TriangleSetup* o = opaque_[pixel];
        o != nullptr && layer_[pixel] != Layer::Sampled && !(zj < o->depth_at(px, py))) {
      visible = false;
    }
    glm::dvec3 t(1.0);
    for (int i = 0; i < n && visible; ++i) {
      if (i == j || !covers_point(*clear[i].t, px, py)) continue;
      if (nearer_first(clear[i].t->depth_at(px, py), *clear[i].t, zj, *c.t)) {
        t *= clear[i].pass;
        visible = !clear[i].ends_layers;  // behind a transmissive layer
      }
    }
    c.shown = visible ? t : glm::dvec3(0.0);
    c.owned = 1;
  }
}

glm::vec3 ABufferTile::resolve_transparent(std::size_t pixel, int x, int y, glm::vec3 background,
                                           float& depth) {
  Transmittance tr;
  glm::dvec3 transmit;
  glm::dvec3 light;
  if (!testing::coverage_hooks.mask_resolve.load(std::memory_order_relaxed) &&
      uniform_transparency(pixel, x, y, transmit, light)) {
    // Interior of transparent surfaces in front of everything opaque: one transmittance for
    // the whole pixel (the general formula with S_j and keep_o constant).
    tr.fallback = transmit;
    const glm::vec3 behind = opaque_through(pixel, x, y, background, depth, tr);
    return glm::vec3(float(light.r + behind.r), float(light.g + behind.g),
                     float(light.b + behind.b));
  }
  double z_opaque[kMaskSamples];
  const TriangleSetup* id[kMaskSamples];
  opaque_samples(pixel, x, y, z_opaque, id);
  thread_local std::vector<Clear> clear;
  clear.clear();
  for (std::uint32_t f = transparent_head_[pixel]; f != kEnd; f = transparent_pool_[f].next) {
    const TriangleSetup* t = transparent_pool_[f].triangle;
    const ShadedColor c = shade_fragment_rgba(*t, x, y);
    const SampleMask mask = pixel_sample_mask(*t, x, y);
    const double alpha = std::clamp(c.alpha, 0.0, 1.0);
    clear.push_back(Clear{t, double(transparent_pool_[f].coverage) / kCoverageOne, alpha, c.rgb,
                          passes(alpha, c.filter), ends_layers(c, alpha), mask, mask.count()});
  }
  transmittance_by_samples(clear, x, y, z_opaque, id, tr);
  sliver_transmittance(pixel, x, y, clear, tr);  // the fragments without a sample
  // The opaque part seen through the transparent fragments, then their own light.
  const glm::vec3 opaque_part = opaque_through(pixel, x, y, background, depth, tr);
  double r = opaque_part.r, g = opaque_part.g, b = opaque_part.b;
  for (const Clear& c : clear) {
    const double w = c.area * c.alpha;
    r += w * (c.shown.r / c.owned) * c.rgb.r;
    g += w * (c.shown.g / c.owned) * c.rgb.g;
    b += w * (c.shown.b / c.owned) * c.rgb.b;
  }
  return glm::vec3(float(r), float(g), float(b));
}

}  // namespace covrast::detail
