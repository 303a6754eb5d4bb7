// Raster stage, coverage mode: the A-buffer's tile state (abuffer.hpp): set-up, the
// whole-tile and whole-block fast paths, and the plane order every part uses. Insertion is
// in abuffer_insert.cpp, overflow into samples in abuffer_samples.cpp, the resolve in
// abuffer_resolve.cpp and abuffer_visibility.cpp.
#include "raster/coverage/abuffer.hpp"

#include "core/checks.hpp"
#include "core/edge_function.hpp"
#include "core/testing_hooks.hpp"
#include "raster/coverage/abuffer_planes.hpp"

#include <algorithm>
#include <cstddef>

namespace covrast::detail {
namespace {

/// Whether pixel corner (x_px, y_px) lies inside or on every edge of the triangle (E without
/// the top-left bias), exact in int64: a rectangle whose four corners do is covered
/// completely (the triangle is convex).
bool corner_inside(const TriangleEdges& edges, std::int64_t x_px, std::int64_t y_px) {
  bool inside = true;
  for (const EdgeFunction& e : edges.e) {
    inside &= e.at(x_px * kSubpixelOne, y_px * kSubpixelOne) - e.bias >= 0;
  }
  return inside;
}

/// How plane `t` lies against plane `u` over every point of `r` (pixel corners included),
/// from their difference at the rectangle's corners (affine, so extreme there): +1 nearer
/// everywhere, -1 farther or equal everywhere, 0 undecided. The margin is far above the
/// rounding of the per-pixel tests, so whenever this decides, ABufferTile::add would have
/// decided the same at every pixel of `r`.
int compare_planes(const TriangleSetup& t, const TriangleSetup& u, const PixelRect& r) {
  constexpr double kMargin = 1e-9;
  const double xs[2] = {double(r.x0), double(r.x1)};
  const double ys[2] = {double(r.y0), double(r.y1)};
  int nearer = 0, farther = 0;
  for (double y : ys) {
    for (double x : xs) {
      const double d = t.depth_at(x, y) - u.depth_at(x, y);
      nearer += d < -kMargin;
      farther += d > kMargin;
    }
  }
  return nearer == 4 ? 1 : farther == 4 ? -1 : 0;
}

/// Fragments per pixel before the overflow policy: kMaxFragmentsPerPixel, or what a test
/// asked for (testing::CoverageHooks::fragment_capacity).
int fragment_capacity() {
  const int forced = testing::coverage_hooks.fragment_capacity.load();
  return forced <= 0 ? kMaxFragmentsPerPixel : std::clamp(forced, 2, kMaxFragmentsPerPixel);
}

}  // namespace

/// How plane `t` lies against plane `other` over pixel (x, y). Both are affine, so their
/// difference is extreme at the corners: nearer at all four corners is in front; farther or
/// equal at all four is behind (equal depth keeps the earlier triangle); else they cross.

DepthOrder order_of(const TriangleSetup& t, const TriangleSetup& other, int x, int y) {
  CornerDepths a = corner_depths(t, x, y), b = corner_depths(other, x, y);
  if (a.max() < b.min()) return DepthOrder::InFront;
  if (a.min() >= b.max()) return DepthOrder::Behind;
  int nearer = 0;
  for (int k = 0; k < 4; ++k) nearer += a.z[k] < b.z[k];
  if (nearer == 4) return DepthOrder::InFront;
  if (nearer == 0) return DepthOrder::Behind;
  return DepthOrder::Crossing;
}

ABufferTile::ABufferTile(int tile_px)
    : stride_(tile_px),
      capacity_(fragment_capacity()),
      mixed_capacity_(std::min(capacity_, kMaxMixedFragments)),
      block_stride_((tile_px + kBlockPx - 1) / kBlockPx),
      log_(std::size_t(tile_px) * tile_px),
      log_on_(true),
      clipping_on_(true) {
  const std::size_t blocks = std::size_t(block_stride_) * std::size_t(block_stride_);
  block_uniform_.resize(blocks);
  block_opaque_.resize(blocks);
  decided_.resize(blocks);
  std::size_t n = std::size_t(tile_px) * tile_px;
  opaque_.resize(n);
  opaque_z_.resize(n);
  head_.resize(n);
  tail_.resize(n);
  count_.resize(n);
  layer_.resize(n);
  layer_sums_.resize(n);
  open_count_.resize(n);
  closed_count_.resize(n);
  occluder_z_.resize(n);
  color_.resize(n);
  depth_.resize(n);
  transparent_head_.resize(n);
}

void ABufferTile::begin_tile(const PixelRect& rect) {
  rect_ = rect;
  tile_uniform_ = true;
  uniform_ = nullptr;
  std::fill(decided_.begin(), decided_.end(), 0);
  decided_stamp_ = 0;
  pool_.clear();
  log_.clear_entries();
  log_on_ = !testing::coverage_hooks.list_only.load(std::memory_order_relaxed);
  clipping_on_ = !testing::coverage_hooks.no_clipping.load(std::memory_order_relaxed);
  merged_slot_.clear();
  merged_.clear();
  samples_.clear();
  if (any_transparent_) {
    transparent_pool_.clear();
    any_transparent_ = false;
  }
}

PixelRect ABufferTile::block_rect(std::size_t b) const {
  const int bx = int(b % std::size_t(block_stride_)), by = int(b / std::size_t(block_stride_));
  const int x0 = rect_.x0 + bx * kBlockPx, y0 = rect_.y0 + by * kBlockPx;
  return PixelRect{x0, y0, std::min(x0 + kBlockPx, rect_.x1), std::min(y0 + kBlockPx, rect_.y1)};
}

void ABufferTile::split_tile() {
  tile_uniform_ = false;
  std::fill(block_uniform_.begin(), block_uniform_.end(), 1);
  std::fill(block_opaque_.begin(), block_opaque_.end(), uniform_);
}

void ABufferTile::materialize_block(std::size_t b) {
  block_uniform_[b] = 0;
  const TriangleSetup* opaque = block_opaque_[b];
  const PixelRect r = block_rect(b);
  for (int y = r.y0; y < r.y1; ++y) {
    const std::size_t row = std::size_t(y - rect_.y0) * stride_;
    for (int x = r.x0; x < r.x1; ++x) {
      const std::size_t pixel = row + (x - rect_.x0);
      opaque_[pixel] = opaque;
      // The centre depth exactly as add() computes it.
      if (opaque != nullptr) opaque_z_[pixel] = opaque->depth_at(x + 0.5, y + 0.5);
      // The per-pixel lists start here (not at begin_tile): blocks that stay uniform never
      // touch them.
      head_[pixel] = kEnd;
      count_[pixel] = 0;
      layer_[pixel] = Layer::Empty;
      open_count_[pixel] = 0;
      closed_count_[pixel] = 0;
      occluder_z_[pixel] = kFar;
      log_.start_pixel(pixel, log_on_);
    }
  }
}

bool ABufferTile::add_covering_blocks(const TriangleSetup& t, const PixelRect& r) {
  if (tile_uniform_) split_tile();
  ++decided_stamp_;
  const TriangleEdges edges(t);
  const int bx0 = (r.x0 - rect_.x0) / kBlockPx, bx1 = (r.x1 - 1 - rect_.x0) / kBlockPx;
  const int by0 = (r.y0 - rect_.y0) / kBlockPx, by1 = (r.y1 - 1 - rect_.y0) / kBlockPx;
  // Which block corners the triangle holds, once per corner (blocks share them).
  constexpr int kMaxCorners = kMaxTilePx / kBlockPx + 1;
  bool inside[kMaxCorners][kMaxCorners];
  for (int j = by0; j <= by1 + 1; ++j) {
    const std::int64_t y = std::min(rect_.y0 + j * kBlockPx, rect_.y1);
    for (int i = bx0; i <= bx1 + 1; ++i) {
      inside[j - by0][i - bx0] =
          corner_inside(edges, std::min(rect_.x0 + i * kBlockPx, rect_.x1), y);
    }
  }
  bool any = false;
  for (int by = by0; by <= by1; ++by) {
    for (int bx = bx0; bx <= bx1; ++bx) {
      const std::size_t b = std::size_t(by) * block_stride_ + bx;
      const int j = by - by0, i = bx - bx0;
      if (!block_uniform_[b] || !inside[j][i] || !inside[j][i + 1] || !inside[j + 1][i] ||
          !inside[j + 1][i + 1]) {
        continue;
      }
      const TriangleSetup* opaque = block_opaque_[b];
      const int order = opaque == nullptr ? 1 : compare_planes(t, *opaque, block_rect(b));
      if (order == 0) continue;
      if (order > 0) block_opaque_[b] = &t;
      decided_[b] = decided_stamp_;
      any = true;
    }
  }
  return any;
}

bool ABufferTile::add_covering_tile(const TriangleSetup& t, const PixelRect& r) {
  if (!tile_uniform_) return false;
  // Only a triangle whose box holds the tile can cover it.
  if (r.x0 != rect_.x0 || r.y0 != rect_.y0 || r.x1 != rect_.x1 || r.y1 != rect_.y1) return false;
  const TriangleEdges edges(t);
  if (!corner_inside(edges, rect_.x0, rect_.y0) || !corner_inside(edges, rect_.x1, rect_.y0) ||
      !corner_inside(edges, rect_.x0, rect_.y1) || !corner_inside(edges, rect_.x1, rect_.y1)) {
    return false;
  }
  const int order = uniform_ == nullptr ? 1 : compare_planes(t, *uniform_, rect_);
  if (order > 0) uniform_ = &t;
  return order != 0;
}

bool ABufferTile::hides_pixel(const TriangleSetup& t, int x, int y) const {
  const double centre_z = t.depth_at(x + 0.5, y + 0.5);  // the bits add() is given
  const std::size_t b = block_of(x, y);
  if (tile_uniform_ || block_uniform_[b]) {
    // Not materialised: the block's opaque triangle, with the centre depth it would get.
    const TriangleSetup* o = tile_uniform_ ? uniform_ : block_opaque_[b];
    return o != nullptr &&
           quick_order(t, centre_z, *o, o->depth_at(x + 0.5, y + 0.5)) == DepthOrder::Behind;
  }
  const std::size_t pixel = std::size_t(y - rect_.y0) * stride_ + (x - rect_.x0);
  const double near = centre_z - depth_reach(t);
  const bool behind_opaque =
      opaque_[pixel] != nullptr &&
      quick_order(t, centre_z, *opaque_[pixel], opaque_z_[pixel]) == DepthOrder::Behind;
  if (log_.state(pixel) == LogState::Off) return near >= occluder_z_[pixel] || behind_opaque;
  const int logged = log_.count(pixel);
  if (logged == 0) {
    // A partial fragment over a started list would turn the log off.
    return !list_started(pixel) && behind_opaque;
  }
  if (near >= log_.hidden_from(pixel)) return true;
  return logged < kMaxLoggedFragments && behind_opaque;  // at the limit: handed to the list
}

bool ABufferTile::hides_rect(const TriangleSetup& t, const PixelRect& r) const {
  COVRAST_CHECK(r.x0 >= rect_.x0 && r.y0 >= rect_.y0 && r.x1 <= rect_.x1 && r.y1 <= rect_.y1,
                "the pixels lie in the tile");
  if (r.empty() || (r.x1 - r.x0) * (r.y1 - r.y0) > kMaxHiddenTestPx) return false;
  for (int y = r.y0; y < r.y1; ++y) {
    for (int x = r.x0; x < r.x1; ++x) {
      if (!hides_pixel(t, x, y)) return false;
    }
  }
  return true;
}

std::size_t ABufferTile::scratch_bytes() const {
  return opaque_.size() * (sizeof(void*) + sizeof(double) + 2 * sizeof(std::uint32_t) + 1 +
                           sizeof(glm::vec3) + sizeof(float)) +
         pool_.capacity() * sizeof(Fragment) + merged_slot_.capacity() * sizeof(std::uint32_t) +
         merged_.capacity() * sizeof(MergedPiece) + samples_.capacity() * sizeof(PixelSamples) +
         transparent_head_.size() * sizeof(std::uint32_t) +
         transparent_pool_.capacity() * sizeof(Fragment) + log_.scratch_bytes();
}
}  // namespace covrast::detail
