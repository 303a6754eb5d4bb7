// Raster stage, coverage mode: the A-buffer's insertion beyond ABufferTile::add
// (abuffer.hpp): closing an open set that fills the pixel, and merging fragments when a
// list is full.
#include "raster/coverage/abuffer.hpp"

#include "core/checks.hpp"
#include "raster/coverage/abuffer_planes.hpp"
#include "raster/coverage/fragment_shading.hpp"
#include "raster/coverage/visible_parts.hpp"

#include <algorithm>

namespace covrast::detail {

void ABufferTile::merge_into(std::uint32_t f, const TriangleSetup& t, std::uint32_t coverage, int x,
                             int y) {
  Fragment& fragment = pool_[f];
  if (!(fragment.coverage & kMergedFlag)) {
    if (merged_slot_.size() < pool_.size()) merged_slot_.resize(pool_.size(), kEnd);
    merged_slot_[f] = std::uint32_t(merged_.size());
    const std::uint32_t own = fragment.coverage & kCoverageBits;
    merged_.push_back(MergedPiece{pixel_sample_mask(*fragment.triangle, x, y),
                                  shade_fragment(*fragment.triangle, x, y),
                                  own,
                                  1,
                                  {fragment.triangle}});
  }
  MergedPiece& m = merged_[merged_slot_[f]];
  m.mask |= pixel_sample_mask(t, x, y);
  m.piece[m.pieces++] = &t;
  // Running coverage-weighted mean of the pieces' colours.
  const glm::vec3 color = shade_fragment(t, x, y);
  const std::uint32_t weight = m.weight + coverage;
  if (weight > 0) {
    m.color = (m.color * float(m.weight) + color * float(coverage)) / float(weight);
  }
  m.weight = weight;
  const std::uint32_t sum = (fragment.coverage & kCoverageBits) + coverage;
  fragment.coverage = (fragment.coverage & (kOpenFlag | kClosedFlag)) | kMergedFlag |
                      std::min<std::uint32_t>(sum, kCoverageOne);
}

bool ABufferTile::merge_into_open_set(std::size_t pixel, int x, int y, const TriangleSetup& t,
                                      std::uint32_t coverage, double centre_z) {
  // The member with the fewest pieces, preferring one that shares a vertex with t (a
  // neighbour in the tessellation: the merged colour then mixes neighbours).
  std::uint32_t into = kEnd;
  int best = 2 * kMaxMergedPieces;
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    if (!(pool_[f].coverage & kOpenFlag)) continue;
    const TriangleSetup* const* pieces;
    const int count = fragment_pieces(f, pieces);
    if (count >= kMaxMergedPieces) continue;
    const int rank = share_vertex(*pool_[f].triangle, t) ? count : count + kMaxMergedPieces;
    if (rank < best) {
      best = rank;
      into = f;
    }
  }
  if (into == kEnd) return false;
  merge_into(into, t, coverage, x, y);
  add_to_sums(pixel, x, y, t, coverage, centre_z);
  if (layer_sums_[pixel].coverage >= std::uint32_t(kCoverageOne)) complete_open_set(pixel, x, y);
  return true;
}

template <class Drop>
void ABufferTile::remove_fragments(std::size_t pixel, Drop drop) {
  std::uint32_t last = kEnd;
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    if (drop(pool_[f])) {
      if (last == kEnd) {
        head_[pixel] = pool_[f].next;
      } else {
        pool_[last].next = pool_[f].next;
      }
      --count_[pixel];
      continue;
    }
    last = f;
  }
  tail_[pixel] = last;
}

bool ABufferTile::hidden_by_container(std::size_t pixel, int x, int y,
                                      const TriangleSetup& t) const {
  // Copies of one triangle arrive one after the other (one mesh, or instances in order), so
  // the newest fragment is the one to test: O(1) per fragment, not a walk of the list.
  const std::uint32_t f = tail_[pixel];
  if (head_[pixel] == kEnd || (pool_[f].coverage & kMergedFlag)) return false;
  const TriangleSetup& m = *pool_[f].triangle;
  return contains_triangle(m, t) && order_of(t, m, x, y) == DepthOrder::Behind;
}

void ABufferTile::complete_open_set(std::size_t pixel, int x, int y) {
  COVRAST_CHECK(layer_sums_[pixel].coverage >= std::uint32_t(kCoverageOne),
                "a closed set's areas fill the pixel");
  COVRAST_CHECK(pairwise_disjoint(pixel, kOpenFlag), "an open set's members are pairwise disjoint");
  occluder_z_[pixel] = std::min(occluder_z_[pixel], layer_sums_[pixel].far);
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    std::uint32_t& c = pool_[f].coverage;
    c = (c & kOpenFlag) ? (c & ~kOpenFlag) | kClosedFlag : c & ~kClosedFlag;
  }
  closed_count_[pixel] = open_count_[pixel];
  open_count_[pixel] = 0;
  if (count_[pixel] != closed_count_[pixel]) {
    // The fragments stored before the set completed: each is earlier than some members, so
    // it must be strictly behind (a level plane keeps the earlier triangle), and the depth
    // bound of earlier closed sets does not apply to it (it may be one of their members).
    const double far = layer_sums_[pixel].far;
    remove_fragments(pixel, [&](const Fragment& f) {
      if (f.coverage & kClosedFlag) return false;
      const TriangleSetup& t = *f.triangle;
      if (t.depth_at(x + 0.5, y + 0.5) - depth_reach(t) > far) return true;
      return behind_closed_set(pixel, t,
                               [&](const TriangleSetup& m) { return behind_all_over(t, m, x, y); });
    });
  }
  if (count_[pixel] == closed_count_[pixel]) {
    layer_[pixel] = Layer::One;  // the sums are the closed set's
    return;
  }
  // Fragments in front of the closed set in places: a new open set from them, in list order.
  layer_[pixel] = Layer::Mixed;
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    Fragment& fragment = pool_[f];
    if ((fragment.coverage & kClosedFlag) || !joins_open_set(pixel, *fragment.triangle)) continue;
    const TriangleSetup& t = *fragment.triangle;
    add_to_sums(pixel, x, y, t, fragment.coverage & kCoverageBits, t.depth_at(x + 0.5, y + 0.5));
    fragment.coverage |= kOpenFlag;
    ++open_count_[pixel];
  }
}

ABufferTile::Compaction ABufferTile::drop_hidden(std::size_t pixel, int x, int y,
                                                 const TriangleSetup& t) {
  // Visibility only shrinks as fragments arrive: a fragment that the stored ones and the
  // opaque surface hide all over its part of the pixel never shows again.
  if (!clipping_on_) return Compaction::Full;
  const TriangleSetup* tri[kMaxVisibleFragments];
  int n = 0;
  double depth_px = 0.0;  // the list's summed coverage [pixels]
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    if ((pool_[f].coverage & kMergedFlag) || n + 1 == kMaxVisibleFragments) return Compaction::Full;
    depth_px += double(pool_[f].coverage & kCoverageBits) / kCoverageOne;
    tri[n++] = pool_[f].triangle;
  }
  // A shallower list is a dense mesh's pieces, which the clipping would mostly keep.
  if (depth_px < kCompactionDepth) return Compaction::Full;
  tri[n++] = &t;
  double area[kMaxVisibleFragments];
  if (!visible_areas(n, tri, opaque_[pixel], x, y, area)) return Compaction::Full;
  // Where the visible parts fill the pixel, nothing behind the farthest of them shows: the
  // depth bound of closed sets and samples, with their margin (filled to within 1e-9 of the
  // pixel: what a farther fragment might show in the rest is far below an 8.8 step).
  const TriangleSetup* opaque = opaque_[pixel];
  double covered = 0.0;
  double far = opaque != nullptr ? opaque_z_[pixel] + depth_reach(*opaque) : -kFar;
  for (int i = 0; i < n; ++i) {
    if (area[i] == 0.0) continue;
    covered += area[i];
    far = std::max(far, tri[i]->depth_at(x + 0.5, y + 0.5) + depth_reach(*tri[i]));
  }
  if (opaque != nullptr || covered >= 1.0 - 1e-9) {
    occluder_z_[pixel] = std::min(occluder_z_[pixel], far + kOccluderMargin);
  }
  // Members of an open or closed set stay: the set's sums and counts stand for them.
  int i = 0;
  remove_fragments(pixel, [&](const Fragment& f) {
    return area[i++] == 0.0 && !(f.coverage & (kOpenFlag | kClosedFlag));
  });
  if (area[n - 1] == 0.0) return Compaction::NewHidden;
  // Half the list at least, so that each clipping of the list pays for many fragments.
  return count_[pixel] <= mixed_capacity_ / 2 ? Compaction::Room : Compaction::Full;
}
}  // namespace covrast::detail
