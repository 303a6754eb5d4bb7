// Raster stage, coverage mode: the visible weight of each fragment of a pixel whose
// fragments overlap, from the sub-pixel samples and the exact tests that let a fragment keep
// its whole area (ABufferTile::sample_weights, ABufferTile::shows_whole).
#include "raster/coverage/abuffer.hpp"

#include "raster/coverage/abuffer_planes.hpp"
#include "raster/coverage/sample_depth.hpp"
#include "raster/coverage/triangle_overlap.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>

namespace covrast::detail {

namespace {

/// The fragment that took one of fragment i's samples (its mask `mine`; `best` holds each
/// sample's winner plus one), or -1 when it won them all.
int lost_to(const SampleMask& mine, const std::uint8_t* best, int i) {
  for (int w = 0; w < 4; ++w) {
    for (std::uint64_t bits = mine.word[w]; bits != 0; bits &= bits - 1) {
      const int winner = best[w * 64 + std::countr_zero(bits)] - 1;
      if (winner != i) return winner;
    }
  }
  return -1;
}

}  // namespace

/// Visibility per sub-pixel sample, with per-sample depth from each plane: a fragment's
/// weight is its coverage times the share of its samples where it is the nearest (equal
/// depth keeps the earlier triangle). Only the samples a fragment owns are evaluated.
int ABufferTile::sample_weights(int x, int y, const TriangleSetup* opaque, int n,
                                const TriangleSetup* const* tri, const std::uint32_t* cov,
                                const MergedPiece* const* merged, double* weight,
                                bool* estimated) const {
  double best_z[kMaskSamples];
  std::uint64_t best_primitive[kMaskSamples];
  // Per sample, the fragment nearest so far plus one (0: none); once every fragment is
  // tested, won[k + 1] counts the samples fragment k holds and won[0] those the opaque
  // surface or the background keeps.
  std::uint8_t best[kMaskSamples];
  int won[kMaxFragmentsPerPixel + 1] = {};
  static_assert(kMaxFragmentsPerPixel < 256);
  if (opaque != nullptr) {
    const SamplePlane plane(*opaque, x, y);
    for (int s = 0; s < kMaskSamples; ++s) best_z[s] = plane.at(s);
  } else {
    std::fill(best_z, best_z + kMaskSamples, std::numeric_limits<double>::infinity());
  }
  std::fill(best_primitive, best_primitive + kMaskSamples,
            std::uint64_t(opaque != nullptr ? opaque->primitive : kNoTriangle));
  std::memset(best, 0, sizeof(best));
  // Samples `owned` of triangle `t`, for fragment i: nearest wins; equal depth keeps the
  // earlier triangle. The (depth, primitive) order is total, so the winner does not depend
  // on the order fragments are visited in.
  auto depth_test = [&](const SampleMask& owned, const TriangleSetup& t, int i) {
    const SamplePlane plane(t, x, y);
    const SampleMask won = depth_test_samples(PixelPlane{plane.z0, plane.dzdx, plane.dzdy}, owned,
                                              t.primitive, best_z, best_primitive);
    for_each_sample(won, [&](int s) { best[s] = std::uint8_t(i + 1); });
  };
  SampleMask mask[kMaxFragmentsPerPixel];
  for (int i = 0; i < n; ++i) {
    if (merged[i] == nullptr) {
      mask[i] = pixel_sample_mask(*tri[i], x, y);
      depth_test(mask[i], *tri[i], i);
      continue;
    }
    // A merged fragment is the union of its pieces (disjoint members of one open set), each
    // depth-tested with its own plane: one plane for all would misplace pieces that tilt
    // differently, as the long slivers of CAD models do.
    mask[i] = merged[i]->mask;
    for (int k = 0; k < merged[i]->pieces; ++k) {
      const TriangleSetup& piece = *merged[i]->piece[k];
      depth_test(pixel_sample_mask(piece, x, y), piece, i);
    }
  }
  for (int s = 0; s < kMaskSamples; ++s) ++won[best[s]];
  for (int i = 0; i < n; ++i) {
    const int samples = mask[i].count();
    double share;
    estimated[i] = false;
    if (samples > 0 && won[i + 1] == samples) {
      share = 1.0;  // it won all its samples: the same share as when nothing hides it
    } else if (shows_whole(x, y, opaque, n, tri, merged, i,
                           samples > 0 ? lost_to(mask[i], best, i) : -1)) {
      share = 1.0;  // nothing in front of it overlaps it: its whole area shows
    } else if (samples > 0) {
      share = double(won[i + 1]) / samples;
      estimated[i] = true;
    } else if (double px, py;
               merged[i] == nullptr && inner_point(part_in_pixel(*tri[i], x, y), px, py)) {
      // Too thin to own a sample: visible or not where it is, at a point inside its part of
      // the pixel, against the opaque surface and every fragment covering that point.
      share = (opaque == nullptr || tri[i]->depth_at(px, py) < opaque->depth_at(px, py)) &&
                      nearest_at_point(n, tri, merged, i, px, py)
                  ? 1.0
                  : 0.0;
    } else {
      // A merged piece without samples: spread it over the pixel, and count the samples
      // where its plane would be nearer than what won them.
      const SamplePlane plane(*tri[i], x, y);
      int nearer = 0;
      for (int k = 0; k < kMaskSamples; ++k) nearer += plane.at(k) < best_z[k];
      share = nearer / double(kMaskSamples);
      estimated[i] = true;
    }
    weight[i] = double(cov[i]) / kCoverageOne * share;
  }
  return won[0];
}

bool ABufferTile::shows_whole(int x, int y, const TriangleSetup* opaque, int n,
                              const TriangleSetup* const* tri, const MergedPiece* const* merged,
                              int i, int suspect) {
  constexpr int kMaxPairs = 32;  // beyond it, n^2 tests cost more than they can save
  if (n > kMaxPairs || merged[i] != nullptr) return false;
  if (opaque != nullptr && !behind_all_over(*opaque, *tri[i], x, y)) return false;
  // Every other fragment misses it (a separating edge) or lies behind it all over the
  // pixel; the one that took a sample of it is the likeliest not to, so it goes first.
  auto misses = [&](int j) {
    return (merged[j] == nullptr && interiors_disjoint(*tri[i], *tri[j])) ||
           behind_all_over(*tri[j], *tri[i], x, y);
  };
  if (suspect >= 0 && !misses(suspect)) return false;
  for (int j = 0; j < n; ++j) {
    if (j != i && j != suspect && !misses(j)) return false;
  }
  return true;
}

}  // namespace covrast::detail
