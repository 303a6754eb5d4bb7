// Raster stage, coverage mode: ABufferTile::add and the per-pixel insertion it inlines (the
// log, the list, the open and closed sets' fast tests, the running sums), included at the end
// of abuffer.hpp, which declares them and says what each state means. Out-of-line parts live
// in abuffer_insert.cpp (open and closed sets, merging) and abuffer.cpp (tile and block paths).
#pragma once

#include "raster/coverage/abuffer.hpp"

namespace covrast::detail {

inline DepthOrder ABufferTile::order_against_opaque(const TriangleSetup& t, double t_centre_z,
                                                    std::size_t pixel, int x, int y) const {
  const TriangleSetup& o = *opaque_[pixel];
  const DepthOrder quick = quick_order(t, t_centre_z, o, opaque_z_[pixel]);
  return quick != DepthOrder::Crossing ? quick : order_of(t, o, x, y);
}

inline void ABufferTile::prepare_row(int x0, int x1, int y) {
  if (tile_uniform_) split_tile();
  if (const std::size_t b = block_of(x0, y); block_uniform_[b]) materialize_block(b);
  if (const std::size_t b = block_of(x1 - 1, y); block_uniform_[b]) materialize_block(b);
}

inline void ABufferTile::add(int x, int y, const TriangleSetup* t, std::uint32_t coverage,
                             double centre_z) {
  const std::size_t pixel = std::size_t(y - rect_.y0) * stride_ + (x - rect_.x0);
  if (log_.state(pixel) != LogState::Off && log_fragment(pixel, x, y, *t, coverage, centre_z)) {
    return;
  }
  add_to_list(pixel, x, y, t, coverage, centre_z);
}

inline bool ABufferTile::log_fragment(std::size_t pixel, int x, int y, const TriangleSetup& t,
                                      std::uint32_t coverage, double centre_z) {
  const double reach = depth_reach(t);
  if (log_.count(pixel) == 0) {
    // Nothing logged: a full fragment is the ordinary depth test against the opaque one.
    if (coverage == std::uint32_t(kCoverageOne)) return false;
    if (list_started(pixel)) {
      // That test kept a full fragment that crosses the opaque one.
      log_.turn_off(pixel);
      return false;
    }
  } else if (centre_z - reach >= log_.hidden_from(pixel)) {
    return true;  // behind a proven layer all over the pixel
  } else if (log_.count(pixel) == kMaxLoggedFragments) {
    hand_log_to_list(pixel, x, y);
    return false;
  }
  // The opaque surface (the nearest full fragment before the log began) stays apart, as the
  // list keeps it: the resolve puts it behind the log.
  if (opaque_[pixel] != nullptr &&
      order_against_opaque(t, centre_z, pixel, x, y) == DepthOrder::Behind) {
    return true;
  }
  log_.append(pixel, x, y, t, coverage, centre_z, reach);
  return true;
}

inline void ABufferTile::add_to_list(std::size_t pixel, int x, int y, const TriangleSetup* t,
                                     std::uint32_t coverage, double centre_z) {
  if (centre_z - depth_reach(*t) >= occluder_z_[pixel]) return;  // behind a closed set or samples
  // Hidden by the closed set: behind (or level with, being later) every member it overlaps.
  if (closed_count_[pixel] != 0 && behind_closed_set(pixel, *t, [&](const TriangleSetup& m) {
        return order_of(*t, m, x, y) == DepthOrder::Behind;
      })) {
    return;
  }
  if (layer_[pixel] == Layer::Sampled) {
    // The opaque surface is in the samples already; a full triangle goes there too.
    if (opaque_[pixel] != nullptr &&
        order_against_opaque(*t, centre_z, pixel, x, y) == DepthOrder::Behind) {
      return;
    }
    if (add_to_samples(pixel, x, y, *t)) bound_by_samples(pixel);
    return;
  }
  if (opaque_[pixel] == nullptr) {
    if (coverage == std::uint32_t(kCoverageOne)) {
      opaque_[pixel] = t;
      opaque_z_[pixel] = centre_z;
      return;
    }
  } else {
    switch (order_against_opaque(*t, centre_z, pixel, x, y)) {
      case DepthOrder::InFront:
        // A fully covered pixel is an ordinary depth test.
        if (coverage == std::uint32_t(kCoverageOne)) {
          opaque_[pixel] = t;
          opaque_z_[pixel] = centre_z;
          return;
        }
        break;
      case DepthOrder::Behind:
        return;  // hidden everywhere in the pixel
      case DepthOrder::Crossing:
        break;  // kept as a fragment, resolved per sample
    }
  }
  add_fragment(pixel, x, y, t, coverage, centre_z);
}

inline void ABufferTile::add_fragment(std::size_t pixel, int x, int y, const TriangleSetup* t,
                                      std::uint32_t coverage, double centre_z) {
  // Sampled pixels, and lists at their limit: the overflow policy.
  if (count_[pixel] >= (layer_[pixel] == Layer::One ? capacity_ : mixed_capacity_) &&
      overflow_fragment(pixel, x, y, t, coverage, centre_z)) {
    return;
  }
  std::uint32_t flags = 0;
  if (joins_open_set(pixel, *t)) {
    flags = kOpenFlag;
    add_to_sums(pixel, x, y, *t, coverage, centre_z);
  } else if (hidden_by_container(pixel, x, y, *t)) {
    return;
  }
  const std::uint32_t index = std::uint32_t(pool_.size());
  pool_.push_back(Fragment{t, kEnd, coverage | flags});
  if (head_[pixel] == kEnd) {
    head_[pixel] = index;
  } else {
    pool_[tail_[pixel]].next = index;
  }
  tail_[pixel] = index;
  ++count_[pixel];
  if (flags == 0) {
    layer_[pixel] = Layer::Mixed;
    return;
  }
  ++open_count_[pixel];
  layer_[pixel] = open_count_[pixel] == count_[pixel] ? Layer::One : Layer::Mixed;
  if (layer_sums_[pixel].coverage >= std::uint32_t(kCoverageOne)) complete_open_set(pixel, x, y);
}

template <class Behind>
bool ABufferTile::behind_closed_set(std::size_t pixel, const TriangleSetup& t,
                                    Behind behind) const {
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    if (!(pool_[f].coverage & kClosedFlag)) continue;
    const TriangleSetup* const* pieces;
    const int count = fragment_pieces(f, pieces);
    for (int k = 0; k < count; ++k) {
      if (!interiors_disjoint(t, *pieces[k]) && !behind(*pieces[k])) return false;
    }
  }
  return true;
}

inline bool ABufferTile::joins_open_set(std::size_t pixel, const TriangleSetup& t) const {
  if (open_count_[pixel] == 0) return true;
  // Pieces of one convex surface and facing (TriangleSetup::convex_surface): no walk.
  const std::uint32_t key = convex_key(t);
  if (key != kNoConvexKey && layer_sums_[pixel].convex_key == key) return true;
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    if (!(pool_[f].coverage & kOpenFlag)) continue;
    const TriangleSetup* const* pieces;
    const int count = fragment_pieces(f, pieces);
    for (int k = 0; k < count; ++k) {
      const TriangleSetup& m = *pieces[k];
      // One facing of one convex surface: disjoint without a test (TriangleSetup).
      if (one_convex_facing(t, m)) continue;
      if (!interiors_disjoint(t, m)) return false;
    }
  }
  return true;
}

inline void ABufferTile::add_to_sums(std::size_t pixel, int x, int y, const TriangleSetup& t,
                                     std::uint32_t coverage, double centre_z) {
  LayerSums& sums = layer_sums_[pixel];
  if (open_count_[pixel] == 0) {
    sums.coverage = 0;
    sums.rgb[0] = sums.rgb[1] = sums.rgb[2] = 0.0;
    sums.depth = std::numeric_limits<float>::infinity();
    sums.far = -std::numeric_limits<double>::infinity();
    sums.convex_key = convex_key(t);
  } else if (sums.convex_key != convex_key(t)) {
    sums.convex_key = kNoConvexKey;
  }
  const glm::vec3 c = shade_fragment(t, x, y);
  sums.coverage += coverage;
  sums.rgb[0] += double(coverage) * c.r;
  sums.rgb[1] += double(coverage) * c.g;
  sums.rgb[2] += double(coverage) * c.b;
  sums.depth = std::min(sums.depth, float(centre_z));
  sums.far = std::max(sums.far, centre_z + depth_reach(t));
}

}  // namespace covrast::detail
