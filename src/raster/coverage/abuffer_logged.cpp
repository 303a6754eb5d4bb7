// Raster stage, coverage mode: the resolve of pixels that logged their fragments
// (pixel_log.hpp), and the hand-over of a log to the fragment list.
#include "core/checks.hpp"
#include "raster/coverage/abuffer.hpp"
#include "raster/coverage/abuffer_planes.hpp"
#include "raster/coverage/fragment_shading.hpp"
#include "raster/coverage/sample_mask.hpp"
#include "raster/coverage/triangle_overlap.hpp"
#include "raster/coverage/visible_parts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace covrast::detail {
namespace {

/// nearest_at_point's view of merged fragments, of which a log has none.
struct NotMerged {
  int pieces;
  const TriangleSetup* piece[1];
};

/// The area [pixels^2] that triangles a and b share inside pixel (x, y). For the invariant
/// checks: the log proves its layers disjoint inside the pixel, not as whole triangles.
[[maybe_unused]] double shared_area_in_pixel(const TriangleSetup& a, const TriangleSetup& b, int x,
                                             int y) {
  ClipPolygon poly = part_in_pixel(a, x, y);
  clip_by_triangle(poly, b);
  return polygon_area(poly);
}

bool any(const SampleMask& m) { return (m.word[0] | m.word[1] | m.word[2] | m.word[3]) != 0; }

/// A masked pixel's fragments (the log's, and the opaque surface as one that covers the
/// pixel), nearest first once sorted, and what the masked resolve finds for each.
struct MaskedPixel {
  static constexpr int kCapacity = kMaxLoggedFragments + 1;
  int n = 0;
  const TriangleSetup* tri[kCapacity];
  std::uint32_t coverage[kCapacity];
  double centre_z[kCapacity];
  double near[kCapacity], far[kCapacity];  ///< where the plane lies within the pixel
  SampleMask mask[kCapacity], kept[kCapacity];
  SampleMask held = SampleMask::none();  ///< the samples some fragment holds
  bool lost_any = false;                 ///< a fragment lost samples to a nearer one
  int shown = 0;             ///< fragments from here on lie behind full coverage (no mask)
  int considered = 0;        ///< fragments with a weight: the shown ones and the nearest hidden one
  double weight[kCapacity];  ///< [pixels]
  bool estimated[kCapacity];
  int own_count[kCapacity], kept_count[kCapacity];  ///< of mask and kept, for the shown ones

  void add(const TriangleSetup& t, std::uint32_t c, double z, double reach) {
    tri[n] = &t;
    coverage[n] = c;
    centre_z[n] = z;
    near[n] = z - reach;
    far[n] = z + reach;
    ++n;
  }
  double area(int i) const { return double(coverage[i]) / kCoverageOne; }

  /// By the near end of the range, ties in arrival order (insertion sort: stable, and short).
  void sort_nearest_first() {
    for (int i = 1; i < n; ++i) {
      const TriangleSetup* t = tri[i];
      const std::uint32_t c = coverage[i];
      const double z = centre_z[i], lo = near[i], hi = far[i];
      int j = i;
      for (; j > 0 && near[j - 1] > lo; --j) {
        tri[j] = tri[j - 1];
        coverage[j] = coverage[j - 1];
        centre_z[j] = centre_z[j - 1];
        near[j] = near[j - 1];
        far[j] = far[j - 1];
      }
      tri[j] = t, coverage[j] = c, centre_z[j] = z, near[j] = lo, far[j] = hi;
    }
  }

  /// Front to back: fragment i takes the samples of its mask that no nearer fragment holds.
  /// Behind a holder's whole range it loses the shared samples at once; where the ranges
  /// overlap, the planes decide each shared sample (nearer wins; level: the earlier
  /// primitive), as the list's samples do. Once every sample is held and the next range
  /// starts behind every range so far, the rest is hidden: their masks are never computed.
  void take_samples(int x, int y) {
    double farthest = -std::numeric_limits<double>::infinity();
    shown = n;
    for (int i = 0; i < n; ++i) {
      if (near[i] > farthest && held == SampleMask::all()) {
        shown = i;
        lost_any = true;
        return;
      }
      farthest = std::max(farthest, far[i]);
      mask[i] = pixel_sample_mask(*tri[i], x, y);
      SampleMask free = mask[i];
      for (int j = 0; j < i; ++j) {
        const SampleMask shared = free & kept[j];
        if (!any(shared)) continue;
        lost_any = true;
        if (far[j] <= near[i]) {
          free = free.without(shared);
        } else {
          split_shared(x, y, i, j, shared, free);
        }
      }
      kept[i] = free;
      held |= mask[i];
    }
  }

  /// The samples `shared` by fragments i and j whose ranges overlap, sample by sample.
  void split_shared(int x, int y, int i, int j, const SampleMask& shared, SampleMask& free) {
    const SamplePlane plane_i(*tri[i], x, y), plane_j(*tri[j], x, y);
    const bool i_first = tri[i]->primitive < tri[j]->primitive;
    for_each_sample(shared, [&](int k) {
      const double zi = plane_i.at(k), zj = plane_j.at(k);
      const std::uint64_t bit = 1ull << (k & 63);
      if (zi < zj || (zi == zj && i_first)) {
        kept[j].word[k >> 6] &= ~bit;
      } else {
        free.word[k >> 6] &= ~bit;
      }
    });
  }

  /// Whether a shown fragment i takes shade_fragment_visible's colour (shows_side), at its
  /// weight scaled by `scale`.
  bool shows_partly(int i, double scale) const {
    return i < shown && shows_side(*tri[i], weight[i] * scale, own_count[i], kept_count[i]);
  }

  /// The weights, as the list's sample resolve gives them: the exact area where a fragment
  /// keeps all its samples; else its area times the share it keeps, those estimates scaled
  /// together to fill what the exact areas and the background's samples leave, each at most
  /// its area. A sliver that owns no sample shows or not at a point inside its part of the
  /// pixel, against every fragment that covers the point (as the list does).
  void weigh(int x, int y) {
    const NotMerged* const no_merged[kCapacity] = {};  // a log holds no merges
    double exact = 0.0, estimate = 0.0;
    for (int i = 0; i < shown; ++i) {
      own_count[i] = mask[i].count();
      kept_count[i] = kept[i].count();
      const int own = own_count[i], keeps = kept_count[i];
      estimated[i] = own != 0 && keeps != own;
      if (own == 0) {
        double px, py;
        const bool shows = inner_point(part_in_pixel(*tri[i], x, y), px, py) &&
                           nearest_at_point(n, tri, no_merged, i, px, py);
        weight[i] = shows ? area(i) : 0.0;
      } else {
        weight[i] = keeps == own ? area(i) : area(i) * double(keeps) / own;
      }
      (estimated[i] ? estimate : exact) += weight[i];
    }
    // The nearest of the hidden fragments: what shows through the strips between samples
    // that the exact areas leave, as the list's opaque surface does.
    considered = shown < n ? shown + 1 : n;
    if (shown < n) {
      weight[shown] = 0.0;
      estimated[shown] = true;
    }
    if (!lost_any) return;
    // What the exact areas and the background leave goes to the estimates, in proportion;
    // when none kept a sample, to the nearest hidden fragment.
    const double behind_share = double(kMaskSamples - held.count()) / kMaskSamples;
    const bool to_hidden = !(estimate > 0.0) && shown < n;
    const double basis = to_hidden ? area(shown) : estimate;
    const double scale = basis > 0.0 ? std::max(0.0, 1.0 - exact - behind_share) / basis : 0.0;
    for (int i = 0; i < considered; ++i) {
      if (!estimated[i] || (to_hidden && i != shown)) continue;
      weight[i] = std::min((to_hidden ? area(i) : weight[i]) * scale, area(i));
    }
  }
};

}  // namespace

void ABufferTile::hand_log_to_list(std::size_t pixel, int x, int y) {
  // The fragments leave the log before the list takes them (add_to_list never logs).
  LoggedFragment logged[kMaxLoggedFragments];
  int n = 0;
  log_.for_each(pixel, [&](const LoggedFragment& f) { logged[n++] = f; });
  log_.turn_off(pixel);
  for (int i = 0; i < n; ++i) {
    add_to_list(pixel, x, y, logged[i].triangle, logged[i].coverage, logged[i].centre_z);
  }
}

ABufferTile::LayerSums ABufferTile::logged_sums(std::size_t pixel, int x, int y) const {
  const PixelLog::LayerColor c = log_.layer_color(pixel, x, y);
  return LayerSums{
      log_.coverage_sum(pixel), {c.rgb[0], c.rgb[1], c.rgb[2]}, c.depth, 0.0, kNoConvexKey};
}

void ABufferTile::resolve_logged(std::size_t pixel, int x, int y, glm::vec3 background) {
  // A layer shows over the opaque surface alone when it lies in front of it all over the
  // pixel: before the nearest the opaque plane comes (+inf: no opaque surface).
  const TriangleSetup* opaque = opaque_[pixel];
  const double opaque_near = opaque != nullptr ? opaque_z_[pixel] - depth_reach(*opaque)
                                               : std::numeric_limits<double>::infinity();
  // A proven layer hides the opaque surface.
  if (log_.state(pixel) == LogState::Proven && log_.hidden_from(pixel) < opaque_near) {
    ++paths_.proven_layer;
    resolve_proven(pixel, x, y);
    return;
  }
  // Pieces of one facing of a convex surface that do not fill the pixel (its silhouette), in
  // front of the opaque surface all over the pixel or with none behind: their areas add over
  // what is behind, as the list's open set adds them.
  if (log_.state(pixel) == LogState::Open && log_.one_convex_facing(pixel) &&
      log_.farthest(pixel) < opaque_near) {
    ++paths_.proven_layer;
    const LayerSums sums = logged_sums(pixel, x, y);
    const glm::vec3 behind = opaque != nullptr ? shade_fragment(*opaque, x, y) : background;
    color_[pixel] = front_layer_color(sums, behind);
    depth_[pixel] = opaque != nullptr ? std::min(sums.depth, float(opaque_z_[pixel])) : sums.depth;
    return;
  }
  if (resolve_clipped_log(pixel, x, y, background)) {
    ++paths_.clipped;
    return;
  }
  ++paths_.masked;
  resolve_masked(pixel, x, y, background);
}

void ABufferTile::resolve_proven(std::size_t pixel, int x, int y) {
  COVRAST_CHECK(
      [&] {
        const TriangleSetup* tri[kMaxLoggedFragments];
        int n = 0;
        log_.for_each(pixel, [&](const LoggedFragment& f) { tri[n++] = f.triangle; });
        for (int i = 0; i < n; ++i) {
          for (int j = i + 1; j < n; ++j) {
            // Pairs of one convex facing are taken as disjoint without a test, as by the
            // list (docs/coverage.md, section 3a: snapped slivers at a silhouette).
            if (one_convex_facing(*tri[i], *tri[j])) continue;
            if (!interiors_disjoint(*tri[i], *tri[j]) &&
                shared_area_in_pixel(*tri[i], *tri[j], x, y) > 1e-9) {
              return false;
            }
          }
        }
        return true;
      }(),
      "a proven layer's fragments are pairwise disjoint inside the pixel");
  // The log's running sums, kept as the open set's are (add_to_sums): the same bits.
  const LayerSums sums = logged_sums(pixel, x, y);
  COVRAST_CHECK(sums.coverage >= std::uint32_t(kCoverageOne), "a proven layer fills its pixel");
  color_[pixel] = front_layer_color(sums, glm::vec3(0.0f));  // nothing of what is behind shows
  depth_[pixel] = sums.depth;
}

bool ABufferTile::resolve_clipped_log(std::size_t pixel, int x, int y, glm::vec3 background) {
  const int n = int(log_.count(pixel));
  if (!clipping_on_ || n > kMaxClippedLog) return false;
  const TriangleSetup* opaque = opaque_[pixel];
  // A textured fragment that shows in part is shaded over the samples it keeps
  // (resolve_masked), which the clipping does not give.
  if (opaque != nullptr && textured(*opaque)) return false;
  const TriangleSetup* tri[kMaxClippedLog] = {};
  float centre_z[kMaxClippedLog] = {};
  int k = 0;
  bool any_textured = false;
  log_.for_each(pixel, [&](const LoggedFragment& f) {
    any_textured = any_textured || textured(*f.triangle);
    centre_z[k] = float(f.centre_z);
    tri[k++] = f.triangle;
  });
  double area[kMaxClippedLog];
  if (any_textured || !visible_areas(n, tri, opaque, x, y, area)) return false;
  const PixelShares shares = pixel_shares(n, area);
  const glm::dvec3 rgb =
      weighted_sum(n, area, shares.scale, [&](int i) { return shade_fragment(*tri[i], x, y); });
  float depth = std::numeric_limits<float>::infinity();
  for (int i = 0; i < n; ++i) {
    if (area[i] != 0.0) depth = std::min(depth, centre_z[i]);
  }
  glm::vec3 behind = background;
  if (opaque != nullptr && shares.rest > 0.0) {
    behind = shade_fragment(*opaque, x, y);
    depth = std::min(depth, float(opaque_z_[pixel]));
  }
  color_[pixel] = glm::vec3(rgb + shares.rest * glm::dvec3(behind));
  depth_[pixel] = depth;
  return true;
}

void ABufferTile::resolve_masked(std::size_t pixel, int x, int y, glm::vec3 background) {
  MaskedPixel p;
  if (opaque_[pixel] != nullptr) {
    // The opaque surface takes part as a fragment that covers the pixel.
    p.add(*opaque_[pixel], std::uint32_t(kCoverageOne), opaque_z_[pixel],
          depth_reach(*opaque_[pixel]));
  }
  log_.for_each(
      pixel, [&](const LoggedFragment& f) { p.add(*f.triangle, f.coverage, f.centre_z, f.reach); });
  p.sort_nearest_first();
  p.take_samples(x, y);
  p.weigh(x, y);
  float depth = std::numeric_limits<float>::infinity();
  for (int i = 0; i < p.considered; ++i) {
    COVRAST_CHECK(p.weight[i] >= 0.0 && p.weight[i] <= p.area(i) * (1.0 + 1e-9),
                  "a fragment's visible weight lies between 0 and its exact area");
    depth = std::min(depth, float(p.centre_z[i]));
  }
  const PixelShares shares = pixel_shares(p.considered, p.weight);
  const glm::dvec3 rgb = weighted_sum(p.considered, p.weight, shares.scale, [&](int i) {
    return p.shows_partly(i, shares.scale)
               ? shade_fragment_visible(*p.tri[i], x, y, p.mask[i], p.kept[i])
               : shade_fragment(*p.tri[i], x, y);
  });
  color_[pixel] = glm::vec3(rgb + shares.rest * glm::dvec3(background));
  depth_[pixel] = depth;
}

}  // namespace covrast::detail
