// Resolve stage, coverage mode: the A-buffer; see abuffer.hpp.
#include "raster/coverage/abuffer.hpp"

#include "core/edge_function.hpp"
#include "core/shading.hpp"
#include "core/srgb8.hpp"
#include "raster/coverage/coverage_kernel.hpp"
#include "raster/coverage/sample_mask.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstring>
#include <limits>

namespace covrast::detail {
namespace {

/// Window depth of a triangle's plane at the four corners of pixel (x, y), always from the
/// same operations so that every comparison below sees the same numbers.
struct CornerDepths {
  double z[4];
  double min() const { return std::min(std::min(z[0], z[1]), std::min(z[2], z[3])); }
  double max() const { return std::max(std::max(z[0], z[1]), std::max(z[2], z[3])); }
};

CornerDepths corner_depths(const TriangleSetup& t, int x, int y) {
  const double z = t.depth_at(x, y);
  return {{z, z + t.dzdx, z + t.dzdy, (z + t.dzdx) + t.dzdy}};
}

struct DepthRange {
  double min;
  double max;
};
constexpr double kFar = std::numeric_limits<double>::infinity();

DepthRange depth_range(const TriangleSetup& t, int x, int y) {
  CornerDepths c = corner_depths(t, x, y);
  return {c.min(), c.max()};
}

bool same_surface(const TriangleSetup& a, const TriangleSetup& b) {
  return a.surface == b.surface && a.front_facing == b.front_facing;
}

/// Pixel (x, y) showing `opaque` (null: the background) alone: its colour, and its window
/// depth in `depth`.
glm::vec3 opaque_pixel(const TriangleSetup* opaque, int x, int y, glm::vec3 background,
                       float& depth) {
  const double cx = x + 0.5, cy = y + 0.5;
  depth =
      opaque != nullptr ? float(opaque->depth_at(cx, cy)) : std::numeric_limits<float>::infinity();
  return opaque != nullptr ? shade(*opaque, cx, cy, true) : background;
}

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

/// A triangle's depth over a pixel from its depth at the pixel centre: z(centre) -+
/// (|dz/dx| + |dz/dy|) / 2.
DepthRange range_around(const TriangleSetup& t, double centre_z) {
  const double reach = 0.5 * (std::fabs(t.dzdx) + std::fabs(t.dzdy));
  return DepthRange{centre_z - reach, centre_z + reach};
}

/// Whether two fragments are pieces of one layer of a surface: same mesh instance and facing,
/// and sharing a vertex; a merged fragment stands for several adjacent pieces (merges keep to
/// the open set, see merge_into_open_set), so it joins any fragment of its surface that overlaps it
/// in depth.
bool layer_neighbours(const TriangleSetup& a, bool a_merged, DepthRange ra, const TriangleSetup& b,
                      bool b_merged, DepthRange rb) {
  if (!same_surface(a, b)) return false;
  if (share_vertex(a, b)) return true;
  return (a_merged || b_merged) && !(ra.max < rb.min || rb.max < ra.min);
}

/// The front layer of a pixel's fragments: the one nearest at its nearest point (among the
/// `active` ones; null: all) and every fragment connected to it through `connected`,
/// transitively. Marks them in `in_layer` and returns their count, summed coverage and the
/// farthest depth they reach (members 0 when no fragment is active).
struct FrontLayer {
  int members;
  std::uint32_t coverage;
  double max_depth;
};
template <class Connected>
FrontLayer find_front_layer(int n, const DepthRange* range, const std::uint32_t* coverage,
                            const bool* active, Connected connected, bool* in_layer) {
  int nearest = -1;
  for (int i = 0; i < n; ++i) {
    in_layer[i] = false;
    if ((active == nullptr || active[i]) && (nearest < 0 || range[i].min < range[nearest].min)) {
      nearest = i;
    }
  }
  if (nearest < 0) return FrontLayer{0, 0, 0.0};
  int stack[kMaxFragmentsPerPixel], top = 0;
  in_layer[nearest] = true;
  stack[top++] = nearest;
  FrontLayer layer{1, coverage[nearest], range[nearest].max};
  while (top > 0) {
    const int m = stack[--top];
    for (int j = 0; j < n; ++j) {
      if (in_layer[j] || (active != nullptr && !active[j]) || !connected(m, j)) continue;
      in_layer[j] = true;
      stack[top++] = j;
      ++layer.members;
      layer.coverage += coverage[j];
      layer.max_depth = std::max(layer.max_depth, range[j].max);
    }
  }
  return layer;
}

/// Whether `far` is behind `near` all over pixel (x, y): farther or level at its four corners
/// (the planes are affine), and not the same plane drawn earlier (equal depth keeps the
/// earlier triangle, as the samples do).
bool behind_all_over(const TriangleSetup& far, const TriangleSetup& near, int x, int y) {
  const CornerDepths f = corner_depths(far, x, y), n = corner_depths(near, x, y);
  int level = 0;
  for (int k = 0; k < 4; ++k) {
    if (f.z[k] < n.z[k]) return false;
    level += f.z[k] == n.z[k];
  }
  return level < 4 || near.primitive < far.primitive;
}

/// The triangles each fragment of a pixel stands for: itself, or a merged fragment's pieces.
struct FragmentPieces {
  const TriangleSetup* const* piece;
  int count;
};

/// Whether two fragments' triangles have pairwise disjoint interiors (triangle_overlap.hpp).
bool fragments_disjoint(FragmentPieces a, FragmentPieces b) {
  for (int i = 0; i < a.count; ++i) {
    for (int j = 0; j < b.count; ++j) {
      if (!interiors_disjoint(*a.piece[i], *b.piece[j])) return false;
    }
  }
  return true;
}

/// Whether the fragments i with `member[i]` (all when null) provably do not overlap, so
/// that their exact areas add.
bool pieces_disjoint(int n, const FragmentPieces* pieces, const bool* member) {
  for (int i = 0; i < n; ++i) {
    if (member != nullptr && !member[i]) continue;
    for (int j = i + 1; j < n; ++j) {
      if (member != nullptr && !member[j]) continue;
      if (!fragments_disjoint(pieces[i], pieces[j])) return false;
    }
  }
  return true;
}

/// A convex polygon in pixel coordinates: the pixel square clipped by up to four lines.
struct ClipPolygon {
  double x[8], y[8];
  int n = 0;
};

/// Keeps the part of `poly` where the affine function f(x, y) = c + a x + b y is >= 0.
void clip_half_plane(ClipPolygon& poly, double c, double a, double b) {
  ClipPolygon out;
  for (int i = 0; i < poly.n; ++i) {
    const int j = (i + 1) % poly.n;
    const double fi = c + a * poly.x[i] + b * poly.y[i];
    const double fj = c + a * poly.x[j] + b * poly.y[j];
    if (fi >= 0) {
      out.x[out.n] = poly.x[i];
      out.y[out.n++] = poly.y[i];
    }
    if ((fi >= 0) != (fj >= 0)) {
      const double u = fi / (fi - fj);
      out.x[out.n] = poly.x[i] + u * (poly.x[j] - poly.x[i]);
      out.y[out.n++] = poly.y[i] + u * (poly.y[j] - poly.y[i]);
    }
  }
  poly = out;
}

double polygon_area(const ClipPolygon& poly) {
  double twice = 0;
  for (int i = 0; i < poly.n; ++i) {
    const int j = (i + 1) % poly.n;
    twice += poly.x[i] * poly.y[j] - poly.x[j] * poly.y[i];
  }
  return 0.5 * std::fabs(twice);
}

/// The part of pixel (x, y) inside triangle `t`: the pixel square clipped by its three edges.
ClipPolygon part_in_pixel(const TriangleSetup& t, int x, int y) {
  ClipPolygon poly;
  const double px[4] = {double(x), double(x + 1), double(x + 1), double(x)};
  const double py[4] = {double(y), double(y), double(y + 1), double(y + 1)};
  for (int k = 0; k < 4; ++k) {
    poly.x[k] = px[k];
    poly.y[k] = py[k];
  }
  poly.n = 4;
  // Inside edge i -> j (positive doubled area, y down): (xj - xi)(py - yi) - (yj - yi)(px - xi) >=
  // 0.
  const double s = 1.0 / kSubpixelOne;
  for (int i = 0; i < 3 && poly.n > 0; ++i) {
    const int j = (i + 1) % 3;
    const double xi = t.x_fx8[i] * s, yi = t.y_fx8[i] * s;
    const double dx = t.x_fx8[j] * s - xi, dy = t.y_fx8[j] * s - yi;
    clip_half_plane(poly, dy * xi - dx * yi, -dy, dx);
  }
  return poly;
}

/// The vertex average of a convex polygon (a point inside it) [pixels]; false when empty.
bool inner_point(const ClipPolygon& poly, double& px, double& py) {
  if (poly.n == 0) return false;
  px = py = 0.0;
  for (int i = 0; i < poly.n; ++i) {
    px += poly.x[i];
    py += poly.y[i];
  }
  px /= poly.n;
  py /= poly.n;
  return true;
}

/// The share of triangle `t`'s part of pixel (x, y) where its plane is nearer than the
/// opaque plane `o`: the pixel square clipped by t's three edges, then by the line where the
/// planes meet (both affine, so the line is straight), by exact polygon clipping in double.
/// Negative when t's part is too thin to measure.
double visible_share(const TriangleSetup& t, const TriangleSetup& o, int x, int y) {
  ClipPolygon poly = part_in_pixel(t, x, y);
  const double inside = polygon_area(poly);
  if (!(inside > 1e-12)) return -1.0;
  // Nearer where d = z_o - z_t > 0; d is affine: d(p) = d0 + ddx x + ddy y.
  const double d0 = o.depth_at(0.0, 0.0) - t.depth_at(0.0, 0.0);
  clip_half_plane(poly, d0, o.dzdx - t.dzdx, o.dzdy - t.dzdy);
  return std::clamp(polygon_area(poly) / inside, 0.0, 1.0);
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

namespace {
std::atomic<bool> g_list_resolve{false};
std::atomic<bool> g_mask_resolve{false};
std::atomic<std::uint64_t> g_layer_resolves{0};
std::atomic<int> g_capacity{kMaxFragmentsPerPixel};
}  // namespace

void force_abuffer_capacity(int fragments) {
  g_capacity.store(fragments <= 0 ? kMaxFragmentsPerPixel
                                  : std::clamp(fragments, 2, kMaxFragmentsPerPixel));
}

void force_abuffer_list_resolve(bool on) { g_list_resolve.store(on); }
void force_abuffer_mask_resolve(bool on) {
  g_mask_resolve.store(on);
  g_list_resolve.store(on);
}
std::uint64_t abuffer_layer_resolves() { return g_layer_resolves.load(); }

ABufferTile::ABufferTile(int tile_px)
    : stride_(tile_px),
      capacity_(g_capacity.load()),
      mixed_capacity_(std::min(capacity_, kMaxMixedFragments)),
      block_stride_((tile_px + kBlockPx - 1) / kBlockPx) {
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
}

void ABufferTile::begin_tile(const PixelRect& rect) {
  rect_ = rect;
  tile_uniform_ = true;
  uniform_ = nullptr;
  std::fill(decided_.begin(), decided_.end(), 0);
  decided_stamp_ = 0;
  pool_.clear();
  merged_slot_.clear();
  merged_.clear();
  samples_.clear();
}

/// A layer in front of everything else: colour = (sum coverage_i colour_i) / max(sum
/// coverage_i, 1) + (1 - min(sum coverage_i, 1)) * behind, in 8.8 units; a sum above one
/// pixel (rounding, or merged pieces) is normalised.
glm::vec3 ABufferTile::front_layer_color(const LayerSums& sums, glm::vec3 behind) {
  const std::uint32_t full = kCoverageOne;
  const double denominator = double(std::max(sums.coverage, full));
  const double rest = double(full - std::min(sums.coverage, full)) / kCoverageOne;
  return glm::vec3(float(sums.rgb[0] / denominator + rest * behind.r),
                   float(sums.rgb[1] / denominator + rest * behind.g),
                   float(sums.rgb[2] / denominator + rest * behind.b));
}

namespace {

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

}  // namespace

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

void ABufferTile::merge_into(std::uint32_t f, const TriangleSetup& t, std::uint32_t coverage, int x,
                             int y) {
  Fragment& fragment = pool_[f];
  if (!(fragment.coverage & kMergedFlag)) {
    if (merged_slot_.size() < pool_.size()) merged_slot_.resize(pool_.size(), kEnd);
    merged_slot_[f] = std::uint32_t(merged_.size());
    const std::uint32_t own = fragment.coverage & kCoverageBits;
    merged_.push_back(MergedPiece{pixel_sample_mask(*fragment.triangle, x, y),
                                  shade(*fragment.triangle, x + 0.5, y + 0.5, true),
                                  own,
                                  1,
                                  {fragment.triangle}});
  }
  MergedPiece& m = merged_[merged_slot_[f]];
  m.mask |= pixel_sample_mask(t, x, y);
  m.piece[m.pieces++] = &t;
  // Running coverage-weighted mean of the pieces' colours.
  const glm::vec3 color = shade(t, x + 0.5, y + 0.5, true);
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

bool ABufferTile::overflow_fragment(std::size_t pixel, int x, int y, const TriangleSetup* t,
                                    std::uint32_t coverage, double centre_z) {
  ++overflows_;
  if (layer_[pixel] == Layer::Sampled) {
    add_to_samples(pixel, x, y, *t);
    return true;
  }
  if (open_count_[pixel] != 0 && joins_open_set(pixel, *t) &&
      merge_into_open_set(pixel, x, y, *t, coverage, centre_z)) {
    return true;
  }
  to_samples(pixel, x, y);
  add_to_samples(pixel, x, y, *t);
  return true;
}

namespace {

/// Sample shares (won / owned) are quantised: a sliver of the next layer that shows along an
/// edge of the front one is mostly missed by the samples, and what they miss would go to the
/// opaque surface or the background behind, which may be hidden there. So the weights that
/// are estimates (`estimated`) are scaled together to fill what the exact ones leave, less
/// the share of the samples that the surface behind won; each stays within its own coverage.
void fill_estimated_share(int n, const std::uint32_t* cov, const bool* estimated,
                          double behind_share, double* weight) {
  double exact = 0.0, estimate = 0.0;
  for (int i = 0; i < n; ++i) (estimated[i] ? estimate : exact) += weight[i];
  if (!(estimate > 0.0)) return;
  const double scale = std::max(0.0, 1.0 - exact - behind_share) / estimate;
  for (int i = 0; i < n; ++i) {
    if (estimated[i]) weight[i] = std::min(weight[i] * scale, double(cov[i]) / kCoverageOne);
  }
}

}  // namespace

glm::vec3 ABufferTile::resolve_pixel(std::size_t pixel, int x, int y, glm::vec3 background,
                                     float& depth) {
  const double cx = x + 0.5, cy = y + 0.5;
  const TriangleSetup* opaque = opaque_[pixel];
  const glm::vec3 behind = opaque_pixel(opaque, x, y, background, depth);
  if (head_[pixel] == kEnd) return behind;

  const DepthRange opaque_range =
      opaque != nullptr ? depth_range(*opaque, x, y) : DepthRange{kFar, kFar};
  const TriangleSetup* tri[kMaxFragmentsPerPixel];
  std::uint32_t cov[kMaxFragmentsPerPixel];
  DepthRange range[kMaxFragmentsPerPixel];
  const MergedPiece* merged[kMaxFragmentsPerPixel];  // null unless it stands for several
  FragmentPieces pieces[kMaxFragmentsPerPixel];
  int n = 0;
  bool crossing = false;  // some fragment's plane crosses the opaque one in this pixel
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    const TriangleSetup* t = pool_[f].triangle;
    const double centre_z = t->depth_at(cx, cy);
    pieces[n].count = fragment_pieces(f, pieces[n].piece);
    // A merged fragment spans its pieces' planes: its range is their union, and it is
    // behind the opaque surface only where every piece is.
    DepthRange r{kFar, -kFar};
    bool behind_opaque = opaque != nullptr, crosses_opaque = false;
    for (int k = 0; k < pieces[n].count; ++k) {
      const TriangleSetup& p = *pieces[n].piece[k];
      const DepthRange pr =
          &p == t ? range_around(p, centre_z) : range_around(p, p.depth_at(cx, cy));
      r = {std::min(r.min, pr.min), std::max(r.max, pr.max)};
      if (opaque == nullptr) continue;
      const DepthOrder order = pr.max < opaque_range.min    ? DepthOrder::InFront
                               : pr.min >= opaque_range.max ? DepthOrder::Behind
                                                            : order_of(p, *opaque, x, y);
      behind_opaque = behind_opaque && order == DepthOrder::Behind;
      crosses_opaque = crosses_opaque || order == DepthOrder::Crossing;
    }
    if (behind_opaque) continue;  // hidden: the opaque surface came later
    crossing = crossing || crosses_opaque;
    tri[n] = t;
    const std::uint32_t c = pool_[f].coverage;
    cov[n] = c & kCoverageBits;
    merged[n] = (c & kMergedFlag) ? &merged_piece(f) : nullptr;
    range[n] = r;
    depth = std::min(depth, float(centre_z));
    ++n;
  }
  if (n == 0) return behind;

  const bool sums_allowed = !g_mask_resolve.load(std::memory_order_relaxed);
  // Pairwise disjoint fragments in front of the opaque surface: their exact areas add (what
  // the open set's sums give; resolve() takes those directly where it can).
  auto layer_color = [&](const bool* member) {
    LayerSums sums{0, {0.0, 0.0, 0.0}, depth, 0.0, kNoConvexKey};
    for (int i = 0; i < n; ++i) {
      if (member != nullptr && !member[i]) continue;
      const glm::vec3 c = merged[i] != nullptr ? merged[i]->color : shade(*tri[i], cx, cy, true);
      sums.coverage += cov[i];
      sums.rgb[0] += double(cov[i]) * c.r;
      sums.rgb[1] += double(cov[i]) * c.g;
      sums.rgb[2] += double(cov[i]) * c.b;
    }
    return front_layer_color(sums, behind);
  };
  if (sums_allowed && !crossing && pieces_disjoint(n, pieces, nullptr)) {
    return layer_color(nullptr);
  }

  // The front layer: the fragment nearest at its nearest point and every fragment
  // connected to it (same mesh instance and facing, through shared vertices; a merged
  // fragment already stands for adjacent pieces of its surface). When its pieces provably
  // do not overlap and it lies wholly in front of everything else, its exact areas add, and
  // when they fill the pixel nothing behind shows.
  auto connected = [&](int i, int j) {
    return layer_neighbours(*tri[i], merged[i] != nullptr, range[i], *tri[j], merged[j] != nullptr,
                            range[j]);
  };
  bool in_front[kMaxFragmentsPerPixel];
  const FrontLayer front = find_front_layer(n, range, cov, nullptr, connected, in_front);
  bool front_separate = !crossing;
  for (int j = 0; j < n && front_separate; ++j) {
    if (!in_front[j] && !(front.max_depth < range[j].min)) front_separate = false;
  }
  if (sums_allowed && front_separate &&
      (front.members == n || front.coverage >= std::uint32_t(kCoverageOne)) &&
      pieces_disjoint(n, pieces, in_front)) {
    return layer_color(in_front);
  }
  double weight[kMaxFragmentsPerPixel];
  // One triangle crossing the opaque plane inside the pixel (where two surfaces
  // interpenetrate): its visible part is exact by polygon clipping, no masks needed.
  const double share =
      n == 1 && crossing && merged[0] == nullptr ? visible_share(*tri[0], *opaque, x, y) : -1.0;
  if (share >= 0.0) {
    weight[0] = double(cov[0]) / kCoverageOne * share;
  } else {
    bool estimated[kMaxFragmentsPerPixel];
    const int behind_samples = sample_weights(x, y, opaque, n, tri, cov, merged, weight, estimated);
    fill_estimated_share(n, cov, estimated, double(behind_samples) / kMaskSamples, weight);
  }
  double total = 0;
  for (int i = 0; i < n; ++i) total += weight[i];
  const double scale = total > 1.0 ? 1.0 / total : 1.0;
  const double rest = total > 1.0 ? 0.0 : 1.0 - total;
  double r = rest * behind.r, g = rest * behind.g, b = rest * behind.b;
  for (int i = 0; i < n; ++i) {
    if (weight[i] == 0) continue;
    const glm::vec3 c = merged[i] != nullptr ? merged[i]->color : shade(*tri[i], cx, cy, true);
    double w = weight[i] * scale;
    r += w * c.r;
    g += w * c.g;
    b += w * c.b;
  }
  return glm::vec3(float(r), float(g), float(b));
}

namespace {

/// Sample offsets from the pixel's corner [pixels], exact in double.
constexpr auto kSampleOffsetX = [] {
  std::array<double, kMaskSamples> offset{};
  for (int k = 0; k < kMaskSamples; ++k) {
    offset[std::size_t(k)] = double(kMaskSampleX_fx9[std::size_t(k)]) / kMaskUnitsPerPixel;
  }
  return offset;
}();
constexpr auto kSampleOffsetY = [] {
  std::array<double, kMaskSamples> offset{};
  for (int k = 0; k < kMaskSamples; ++k) {
    offset[std::size_t(k)] = double(kMaskSampleY_fx9[std::size_t(k)]) / kMaskUnitsPerPixel;
  }
  return offset;
}();

/// A triangle's plane at the samples of one pixel: z(k) = z0 + dz/dx * x(k) + dz/dy * y(k),
/// z0 its depth at the pixel's corner, (x(k), y(k)) sample k's offset. Every comparison of
/// sample_weights uses this expression (no contraction: -ffp-contract=off), so its results
/// do not depend on where or how often they are evaluated.
struct SamplePlane {
  double z0, dzdx, dzdy;
  SamplePlane(const TriangleSetup& t, int x, int y)
      : z0(t.depth_at(x, y)), dzdx(t.dzdx), dzdy(t.dzdy) {}
  double at(int k) const {
    return z0 + dzdx * kSampleOffsetX[std::size_t(k)] + dzdy * kSampleOffsetY[std::size_t(k)];
  }
};

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

/// Whether point p [pixels] lies inside or on the edges of `t`.
bool covers_point(const TriangleSetup& t, double px, double py) {
  const double s = 1.0 / kSubpixelOne;
  for (int i = 0; i < 3; ++i) {
    const int j = i == 2 ? 0 : i + 1;
    const double xi = t.x_fx8[i] * s, yi = t.y_fx8[i] * s;
    if ((t.x_fx8[j] * s - xi) * (py - yi) - (t.y_fx8[j] * s - yi) * (px - xi) < 0.0) return false;
  }
  return true;
}

/// Whether fragment i is the nearest at point p of its part of the pixel among the fragments
/// that cover p (nearer, or level and earlier, than each). Samples cannot tell it for a
/// fragment too thin to own one: two such slivers folded over one another along a shared
/// edge own the same (no) samples and each would show.
template <class Merged>
bool nearest_at_point(int n, const TriangleSetup* const* tri, const Merged* const* merged, int i,
                      double px, double py) {
  const double z = tri[i]->depth_at(px, py);
  auto hides = [&](const TriangleSetup& o) {
    if (!covers_point(o, px, py)) return false;
    const double oz = o.depth_at(px, py);
    return oz < z || (oz == z && o.primitive < tri[i]->primitive);
  };
  for (int j = 0; j < n; ++j) {
    if (j == i) continue;
    if (merged[j] == nullptr) {
      if (hides(*tri[j])) return false;
      continue;
    }
    for (int k = 0; k < merged[j]->pieces; ++k) {
      if (hides(*merged[j]->piece[k])) return false;
    }
  }
  return true;
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
  std::uint32_t best_primitive[kMaskSamples];
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
            opaque != nullptr ? opaque->primitive : kNoTriangle);
  std::memset(best, 0, sizeof(best));
  // Samples `owned` of triangle `t`, for fragment i: nearest wins; equal depth keeps the
  // earlier triangle. The (depth, primitive) order is total, so the winner does not depend
  // on the order fragments are visited in.
  auto depth_test = [&](const SampleMask& owned, const TriangleSetup& t, int i) {
    const SamplePlane plane(t, x, y);
    for_each_sample(owned, [&](int s) {
      const double z = plane.at(s);
      if (z < best_z[s] || (z == best_z[s] && t.primitive < best_primitive[s])) {
        best_z[s] = z;
        best_primitive[s] = t.primitive;
        best[s] = std::uint8_t(i + 1);
      }
    });
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

void ABufferTile::to_samples(std::size_t pixel, int x, int y) {
  const std::uint32_t slot = std::uint32_t(samples_.size());
  samples_.emplace_back();
  PixelSamples& samples = samples_.back();
  const TriangleSetup* opaque = opaque_[pixel];
  if (opaque != nullptr) {
    const SamplePlane plane(*opaque, x, y);
    for (int s = 0; s < kMaskSamples; ++s) samples.z[s] = plane.at(s);
  } else {
    std::fill(samples.z, samples.z + kMaskSamples, kFar);
  }
  std::fill(samples.winner, samples.winner + kMaskSamples, opaque);
  // The stored fragments, in list order (merged ones by their pieces, which they always know:
  // merges happen only inside the open set), then the list is gone.
  const std::uint32_t head = head_[pixel];
  layer_[pixel] = Layer::Sampled;
  tail_[pixel] = slot;
  count_[pixel] = std::uint8_t(kMaxFragmentsPerPixel);  // every later fragment comes here
  for (std::uint32_t f = head; f != kEnd; f = pool_[f].next) {
    if (!(pool_[f].coverage & kMergedFlag)) {
      add_to_samples(pixel, x, y, *pool_[f].triangle);
      continue;
    }
    const MergedPiece& m = merged_piece(f);  // an open-set member: its pieces, one by one
    for (int k = 0; k < m.pieces; ++k) add_to_samples(pixel, x, y, *m.piece[k]);
  }
  head_[pixel] = kEnd;
  open_count_[pixel] = closed_count_[pixel] = 0;
}

void ABufferTile::add_to_samples(std::size_t pixel, int x, int y, const TriangleSetup& t) {
  PixelSamples& samples = samples_[tail_[pixel]];
  const SampleMask mask = pixel_sample_mask(t, x, y);
  const SamplePlane plane(t, x, y);
  for_each_sample(mask, [&](int s) {
    const double z = plane.at(s);
    const TriangleSetup* w = samples.winner[s];
    // The order of sample_weights: nearer wins; at equal depth the earlier triangle.
    if (z < samples.z[s] || (z == samples.z[s] && w != nullptr && t.primitive < w->primitive)) {
      samples.z[s] = z;
      samples.winner[s] = &t;
    }
  });
}

glm::vec3 ABufferTile::resolve_samples(std::size_t pixel, int x, int y, glm::vec3 background,
                                       float& depth) {
  // Each triangle that won samples shows over its exact area times the share of its own
  // samples that it won (as sample_weights weighs fragments), and the background over its
  // share of the samples. A piece too thin to own a sample drops out, so the triangles'
  // weights are scaled to fill what the background leaves: the pieces of a tessellation
  // still cover the pixel, and no background leaks where none shows.
  const PixelSamples& samples = samples_[tail_[pixel]];
  const TriangleSetup* winner[kMaskSamples];
  int won[kMaskSamples];
  int winners = 0, background_won = 0;
  const TriangleSetup* last = nullptr;
  int last_slot = -1;
  depth = std::numeric_limits<float>::infinity();
  for (int s = 0; s < kMaskSamples; ++s) {
    const TriangleSetup* w = samples.winner[s];
    if (w == nullptr) {
      ++background_won;
      continue;
    }
    depth = std::min(depth, float(samples.z[s]));
    if (w != last) {  // winners come in runs: look each run's up once
      last = w;
      last_slot = int(std::find(winner, winner + winners, w) - winner);
      if (last_slot == winners) {
        winner[winners] = w;
        won[winners++] = 0;
      }
    }
    ++won[last_slot];
  }
  double weight[kMaskSamples];
  double total = 0.0;
  for (int k = 0; k < winners; ++k) {
    const int owned = pixel_sample_mask(*winner[k], x, y).count();
    const double area = std::clamp(polygon_area(part_in_pixel(*winner[k], x, y)), 0.0, 1.0);
    weight[k] = owned > 0 && area > 0.0 ? area * won[k] / owned : double(won[k]) / kMaskSamples;
    total += weight[k];
  }
  const double background_share = double(background_won) / kMaskSamples;
  const double scale = total > 0.0 ? (1.0 - background_share) / total : 0.0;
  double r = background_share * background.r, g = background_share * background.g,
         b = background_share * background.b;
  for (int k = 0; k < winners; ++k) {
    const glm::vec3 c = shade(*winner[k], x + 0.5, y + 0.5, true);
    const double w = weight[k] * scale;
    r += w * c.r;
    g += w * c.g;
    b += w * c.b;
  }
  return glm::vec3(float(r), float(g), float(b));
}

void ABufferTile::resolve_opaque_block(const TriangleSetup* opaque, const PixelRect& r,
                                       const FrameTarget& target) {
  if (opaque == nullptr || opaque->flat_color) {
    // One colour: encode it once and fill; depth as write_tile stores it (at most 1, the
    // background 1).
    const glm::vec3 c = opaque != nullptr ? opaque->color[0] : target.background_linear;
    const std::uint8_t code[3] = {encode_srgb8(c.r), encode_srgb8(c.g), encode_srgb8(c.b)};
    for (int y = r.y0; y < r.y1; ++y) {
      std::uint8_t* dst = target.color->pixel(r.x0, y);
      for (int x = r.x0; x < r.x1; ++x, dst += 3) {
        dst[0] = code[0];
        dst[1] = code[1];
        dst[2] = code[2];
      }
      if (target.depth == nullptr) continue;
      float* depth = &target.depth->depth[std::size_t(y) * target.depth->width + r.x0];
      for (int x = r.x0; x < r.x1; ++x) {
        *depth++ = opaque != nullptr ? clamp_window_depth(float(opaque->depth_at(x + 0.5, y + 0.5)))
                                     : 1.0f;
      }
    }
    return;
  }
  for (int y = r.y0; y < r.y1; ++y) {
    const std::size_t row = std::size_t(y - rect_.y0) * stride_;
    for (int x = r.x0; x < r.x1; ++x) {
      color_[row + (x - rect_.x0)] =
          opaque_pixel(opaque, x, y, target.background_linear, depth_[row + (x - rect_.x0)]);
    }
  }
  const std::size_t first = std::size_t(r.y0 - rect_.y0) * stride_ + (r.x0 - rect_.x0);
  write_tile(target, r, color_.data() + first, depth_.data() + first, stride_);
}

void ABufferTile::resolve(const FrameTarget& target) {
  if (tile_uniform_) {
    resolve_opaque_block(uniform_, rect_, target);
    return;
  }
  const bool use_sums = !g_list_resolve.load(std::memory_order_relaxed);
  std::uint64_t from_sums = 0;
  const int block_cols = (rect_.x1 - rect_.x0 + kBlockPx - 1) / kBlockPx;
  const int block_rows = (rect_.y1 - rect_.y0 + kBlockPx - 1) / kBlockPx;
  for (int by = 0; by < block_rows; ++by) {
    for (int bx = 0; bx < block_cols; ++bx) {
      const std::size_t block = std::size_t(by) * block_stride_ + bx;
      const PixelRect br = block_rect(block);
      if (block_uniform_[block]) {
        resolve_opaque_block(block_opaque_[block], br, target);
        continue;
      }
      for (int y = br.y0; y < br.y1; ++y) {
        for (int x = br.x0; x < br.x1; ++x) {
          const std::size_t pixel = std::size_t(y - rect_.y0) * stride_ + (x - rect_.x0);
          if (use_sums && layer_[pixel] == Layer::One && opaque_[pixel] == nullptr) {
            // One layer over the background: what resolve_pixel's first branch gives.
            const LayerSums& sums = layer_sums_[pixel];
            color_[pixel] = front_layer_color(sums, target.background_linear);
            depth_[pixel] = sums.depth;
            ++from_sums;
            continue;
          }
          if (layer_[pixel] == Layer::Sampled) {
            color_[pixel] = resolve_samples(pixel, x, y, target.background_linear, depth_[pixel]);
            continue;
          }
          if (head_[pixel] == kEnd) {
            // No fragments: the opaque surface or the background, as resolve_pixel gives it.
            color_[pixel] =
                opaque_pixel(opaque_[pixel], x, y, target.background_linear, depth_[pixel]);
            continue;
          }
          color_[pixel] = resolve_pixel(pixel, x, y, target.background_linear, depth_[pixel]);
        }
      }
      const std::size_t first = std::size_t(br.y0 - rect_.y0) * stride_ + (br.x0 - rect_.x0);
      write_tile(target, br, color_.data() + first, depth_.data() + first, stride_);
    }
  }
  g_layer_resolves.fetch_add(from_sums, std::memory_order_relaxed);
}

std::size_t ABufferTile::scratch_bytes() const {
  return opaque_.size() * (sizeof(void*) + sizeof(double) + 2 * sizeof(std::uint32_t) + 1 +
                           sizeof(glm::vec3) + sizeof(float)) +
         pool_.capacity() * sizeof(Fragment) + merged_slot_.capacity() * sizeof(std::uint32_t) +
         merged_.capacity() * sizeof(MergedPiece) + samples_.capacity() * sizeof(PixelSamples);
}

}  // namespace covrast::detail
