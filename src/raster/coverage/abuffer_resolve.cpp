// Raster stage, coverage mode: the A-buffer's resolve (abuffer.hpp): uniform blocks, the
// one-layer sums, and the list resolve of resolve_pixel; the sample-based weights it falls
// back on are in abuffer_visibility.cpp.
#include "raster/coverage/abuffer.hpp"

#include "color/srgb8.hpp"
#include "core/checks.hpp"
#include "core/testing_hooks.hpp"
#include "raster/coverage/abuffer_planes.hpp"
#include "raster/coverage/fragment_shading.hpp"
#include "raster/coverage/triangle_overlap.hpp"
#include "raster/coverage/visible_parts.hpp"

#include <algorithm>
#include <cstddef>
#include <limits>

namespace covrast::detail {
namespace {

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
  return opaque != nullptr ? shade_fragment(*opaque, x, y) : background;
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

/// The triangles each fragment of a pixel stands for: itself, or a merged fragment's pieces.
struct FragmentPieces {
  const TriangleSetup* const* piece;
  int count;
};

/// Whether two fragments' triangles have pairwise disjoint interiors (triangle_overlap.hpp).
/// With `as_open_set`, pairs of one convex surface and facing count as disjoint untested, as
/// the open set takes them (one_convex_facing).
bool fragments_disjoint(FragmentPieces a, FragmentPieces b, bool as_open_set = false) {
  for (int i = 0; i < a.count; ++i) {
    for (int j = 0; j < b.count; ++j) {
      if (as_open_set && one_convex_facing(*a.piece[i], *b.piece[j])) continue;
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
  clip_to_line(poly, d0, o.dzdx - t.dzdx, o.dzdy - t.dzdy);
  return std::clamp(polygon_area(poly) / inside, 0.0, 1.0);
}

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

/// The fragments of a pixel's list that the opaque surface does not hide (resolve_pixel).
struct ABufferTile::ListFragments {
  int n = 0;
  bool crossing = false;  ///< some fragment's plane crosses the opaque one in this pixel
  const TriangleSetup* tri[kMaxFragmentsPerPixel];
  std::uint32_t cov[kMaxFragmentsPerPixel];
  DepthRange range[kMaxFragmentsPerPixel];
  const MergedPiece* merged[kMaxFragmentsPerPixel];  ///< null unless it stands for several
  FragmentPieces pieces[kMaxFragmentsPerPixel];

  int shown_side = -1;               ///< a fragment whose colour is `shown_side_color`
  glm::vec3 shown_side_color{0.0f};  ///< what shows of it (shade_fragment_visible)

  bool any_merged() const {
    for (int i = 0; i < n; ++i) {
      if (merged[i] != nullptr) return true;
    }
    return false;
  }
  glm::vec3 color(int i, int x, int y) const {
    if (i == shown_side) return shown_side_color;
    return merged[i] != nullptr ? merged[i]->color : shade_fragment(*tri[i], x, y);
  }
};

void ABufferTile::gather_list(std::size_t pixel, int x, int y, ListFragments& l,
                              float& depth) const {
  const double cx = x + 0.5, cy = y + 0.5;
  const TriangleSetup* opaque = opaque_[pixel];
  const DepthRange opaque_range =
      opaque != nullptr ? depth_range(*opaque, x, y) : DepthRange{kFar, kFar};
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    const TriangleSetup* t = pool_[f].triangle;
    const double centre_z = t->depth_at(cx, cy);
    const int n = l.n;
    l.pieces[n].count = fragment_pieces(f, l.pieces[n].piece);
    // A merged fragment spans its pieces' planes: its range is their union, and it is
    // behind the opaque surface only where every piece is.
    DepthRange r{kFar, -kFar};
    bool behind_opaque = opaque != nullptr, crosses_opaque = false;
    for (int k = 0; k < l.pieces[n].count; ++k) {
      const TriangleSetup& p = *l.pieces[n].piece[k];
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
    l.crossing = l.crossing || crosses_opaque;
    l.tri[n] = t;
    const std::uint32_t c = pool_[f].coverage;
    l.cov[n] = c & kCoverageBits;
    l.merged[n] = (c & kMergedFlag) ? &merged_piece(f) : nullptr;
    l.range[n] = r;
    depth = std::min(depth, float(centre_z));
    ++l.n;
  }
}

glm::vec3 ABufferTile::list_layer_color(const ListFragments& l, const bool* member,
                                        glm::vec3 behind, float depth, const Transmittance* tr,
                                        int x, int y) {
  // Pairwise disjoint fragments (those with `member`, all when null) in front of what is
  // behind: their exact areas add, as the open set's sums add them.
  LayerSums sums{0, {0.0, 0.0, 0.0}, depth, 0.0, kNoConvexKey};
  for (int i = 0; i < l.n; ++i) {
    if (member != nullptr && !member[i]) continue;
    sums.coverage += l.cov[i];
    add_kept(sums.rgb, double(l.cov[i]), tr, l.tri[i], l.color(i, x, y));
  }
  return front_layer_color(sums, behind);
}

bool ABufferTile::front_layer_alone(const ListFragments& l, bool* in_front) {
  // The front layer: the fragment nearest at its nearest point and every fragment connected
  // to it (same mesh instance and facing, through shared vertices; a merged fragment already
  // stands for adjacent pieces of its surface). When its pieces provably do not overlap and
  // it lies wholly in front of everything else, its exact areas add, and when they fill the
  // pixel nothing behind shows.
  auto connected = [&](int i, int j) {
    return layer_neighbours(*l.tri[i], l.merged[i] != nullptr, l.range[i], *l.tri[j],
                            l.merged[j] != nullptr, l.range[j]);
  };
  const FrontLayer front = find_front_layer(l.n, l.range, l.cov, nullptr, connected, in_front);
  if (l.crossing) return false;
  for (int j = 0; j < l.n; ++j) {
    if (!in_front[j] && !(front.max_depth < l.range[j].min)) return false;
  }
  return (front.members == l.n || front.coverage >= std::uint32_t(kCoverageOne)) &&
         pieces_disjoint(l.n, l.pieces, in_front);
}

glm::vec3 ABufferTile::list_weighted_color(const ListFragments& l, const double* weight,
                                           glm::vec3 behind, const Transmittance* tr, int x,
                                           int y) {
  // colour = sum_i w_i c_i + (1 - sum_i w_i) behind, the weights normalised when they exceed
  // the pixel.
  for (int i = 0; i < l.n; ++i) {
    COVRAST_CHECK(weight[i] >= 0.0 && weight[i] <= double(l.cov[i]) / kCoverageOne * (1.0 + 1e-9),
                  "a fragment's visible weight lies between 0 and its exact area");
  }
  const PixelShares shares = pixel_shares(l.n, weight);
  double rgb[3] = {shares.rest * behind.r, shares.rest * behind.g, shares.rest * behind.b};
  for (int i = 0; i < l.n; ++i) {
    if (weight[i] == 0) continue;
    add_kept(rgb, weight[i] * shares.scale, tr, l.tri[i], l.color(i, x, y));
  }
  return glm::vec3(float(rgb[0]), float(rgb[1]), float(rgb[2]));
}

glm::vec3 ABufferTile::resolve_pixel(std::size_t pixel, int x, int y, glm::vec3 background,
                                     float& depth, const Transmittance* tr) {
  const TriangleSetup* opaque = opaque_[pixel];
  glm::vec3 behind = opaque_pixel(opaque, x, y, background, depth);
  // Seen through transparent fragments: each opaque contributor times what they leave of it.
  if (tr != nullptr) behind *= glm::vec3(tr->of(opaque));
  // The path this pixel takes, counted for the opaque resolve (a transparent pixel is
  // counted once, by resolve()).
  const auto took = [&](std::uint64_t CoverageResolvePaths::*path) {
    if (tr == nullptr) ++(paths_.*path);
  };
  ListFragments l;
  if (head_[pixel] != kEnd) gather_list(pixel, x, y, l, depth);
  if (l.n == 0) {
    took(&CoverageResolvePaths::opaque);  // no list, or it lies behind the opaque surface
    return behind;
  }
  const bool sums_allowed = !testing::coverage_hooks.mask_resolve.load(std::memory_order_relaxed);
  if (sums_allowed && !l.crossing && pieces_disjoint(l.n, l.pieces, nullptr)) {
    took(&CoverageResolvePaths::disjoint);
    return list_layer_color(l, nullptr, behind, depth, tr, x, y);
  }
  bool in_front[kMaxFragmentsPerPixel];
  if (sums_allowed && front_layer_alone(l, in_front)) {
    took(&CoverageResolvePaths::front_layer);
    return list_layer_color(l, in_front, behind, depth, tr, x, y);
  }
  double weight[kMaxFragmentsPerPixel];
  // One triangle crossing the opaque plane inside the pixel (where two surfaces
  // interpenetrate): its visible part is exact by polygon clipping, no masks needed.
  const double share = l.n == 1 && l.crossing && l.merged[0] == nullptr
                           ? visible_share(*l.tri[0], *opaque, x, y)
                           : -1.0;
  if (share >= 0.0) {
    took(&CoverageResolvePaths::clipped);
    weight[0] = double(l.cov[0]) / kCoverageOne * share;
    show_crossing_sides(l, *opaque, x, y, weight[0], tr, behind);
  } else if (sums_allowed && clipping_on_ && l.n <= kMaxVisibleFragments && !l.any_merged() &&
             visible_areas(l.n, l.tri, opaque, x, y, weight)) {
    // Any other mix: each fragment's visible part by exact clipping (visible_parts.hpp). A
    // merged fragment (pieces under one colour, each with its own plane) or a pixel too
    // complex for the clipping's bounds takes the samples. A fragment's 8.8 coverage is its
    // area as the kernel rounds it: the exact part may exceed it by that rounding.
    took(&CoverageResolvePaths::clipped);
    for (int i = 0; i < l.n; ++i) weight[i] = std::min(weight[i], double(l.cov[i]) / kCoverageOne);
  } else {
    took(&CoverageResolvePaths::samples);
    bool estimated[kMaxFragmentsPerPixel];
    const int behind_samples =
        sample_weights(x, y, opaque, l.n, l.tri, l.cov, l.merged, weight, estimated);
    fill_estimated_share(l.n, l.cov, estimated, double(behind_samples) / kMaskSamples, weight);
  }
  return list_weighted_color(l, weight, behind, tr, x, y);
}

void ABufferTile::show_crossing_sides(ListFragments& l, const TriangleSetup& opaque, int x, int y,
                                      double weight, const Transmittance* tr, glm::vec3& behind) {
  // The clipped path weighs the crossing triangle t by its exact visible share, and each
  // surface hides a side of the other: at the samples t owns, the nearer plane (level: the
  // earlier primitive, as everywhere) shows. A textured side is moved towards what shows of
  // it (shade_fragment_visible), the weights stay exact.
  const TriangleSetup& t = *l.tri[0];
  if (!textured(t) && !textured(opaque)) return;
  const SampleMask own = pixel_sample_mask(t, x, y);
  SampleMask t_shows = SampleMask::none();
  const SamplePlane t_plane(t, x, y), o_plane(opaque, x, y);
  const bool t_first = t.primitive < opaque.primitive;
  for_each_sample(own, [&](int k) {
    const double zt = t_plane.at(k), zo = o_plane.at(k);
    if (zt < zo || (zt == zo && t_first)) t_shows.word[k >> 6] |= 1ull << (k & 63);
  });
  const int own_count = own.count(), shows_count = t_shows.count();
  if (shows_count == 0) return;
  if (shows_side(t, weight, own_count, shows_count)) {
    l.shown_side = 0;
    l.shown_side_color = shade_fragment_visible(t, x, y, own, t_shows);
  }
  // The opaque surface covers the pixel (weight 1) and loses the samples where t shows.
  if (shows_side(opaque, 1.0, kMaskSamples, kMaskSamples - shows_count)) {
    behind =
        shade_fragment_visible(opaque, x, y, SampleMask::all(), SampleMask::all().without(t_shows));
    if (tr != nullptr) behind *= glm::vec3(tr->of(&opaque));
  }
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

bool ABufferTile::pairwise_disjoint(std::size_t pixel, std::uint32_t only) const {
  auto member = [&](std::uint32_t f) { return only == 0 || (pool_[f].coverage & only) != 0; };
  for (std::uint32_t f = head_[pixel]; f != kEnd; f = pool_[f].next) {
    if (!member(f)) continue;
    FragmentPieces a{};
    a.count = fragment_pieces(f, a.piece);
    for (std::uint32_t g = pool_[f].next; g != kEnd; g = pool_[g].next) {
      if (!member(g)) continue;
      FragmentPieces b{};
      b.count = fragment_pieces(g, b.piece);
      if (!fragments_disjoint(a, b, true)) return false;
    }
  }
  return true;
}

void ABufferTile::resolve(const FrameTarget& target) {
  [[maybe_unused]] const std::uint64_t counted_before = paths_.total();
  resolve_tile(target);
  COVRAST_CHECK(paths_.total() - counted_before == rect_.pixel_count(),
                "every pixel of a tile takes exactly one resolve path");
}

void ABufferTile::resolve_tile(const FrameTarget& target) {
  if (tile_uniform_) {
    paths_.uniform_tile += rect_.pixel_count();
    resolve_opaque_block(uniform_, rect_, target);
    return;
  }
  testing::CoverageHooks& hooks = testing::coverage_hooks;
  const bool use_sums = !hooks.list_resolve.load(std::memory_order_relaxed) &&
                        !hooks.mask_resolve.load(std::memory_order_relaxed);
  const int block_cols = (rect_.x1 - rect_.x0 + kBlockPx - 1) / kBlockPx;
  const int block_rows = (rect_.y1 - rect_.y0 + kBlockPx - 1) / kBlockPx;
  for (int by = 0; by < block_rows; ++by) {
    for (int bx = 0; bx < block_cols; ++bx) {
      const std::size_t block = std::size_t(by) * block_stride_ + bx;
      const PixelRect br = block_rect(block);
      if (block_uniform_[block]) {
        paths_.uniform_block += br.pixel_count();
        resolve_opaque_block(block_opaque_[block], br, target);
        continue;
      }
      for (int y = br.y0; y < br.y1; ++y) {
        for (int x = br.x0; x < br.x1; ++x) {
          const std::size_t pixel = std::size_t(y - rect_.y0) * stride_ + (x - rect_.x0);
          if (log_.count(pixel) != 0) {
            // Transparent fragments and the list-resolve switches: the list takes the log.
            if (!use_sums || (any_transparent_ && transparent_head_[pixel] != kEnd)) {
              hand_log_to_list(pixel, x, y);
            } else {
              resolve_logged(pixel, x, y, target.background_linear);
              continue;
            }
          }
          if (any_transparent_ && transparent_head_[pixel] != kEnd) {
            // Transparent fragments: none of the one-layer shortcuts (they assume nothing
            // in front of the opaque resolve).
            ++paths_.transparent;
            color_[pixel] =
                resolve_transparent(pixel, x, y, target.background_linear, depth_[pixel]);
            continue;
          }
          if (use_sums && layer_[pixel] == Layer::One && opaque_[pixel] == nullptr) {
            // One layer over the background: what resolve_pixel's first branch gives.
            COVRAST_CHECK(pairwise_disjoint(pixel, 0),
                          "a one-layer pixel's fragments are pairwise disjoint");
            const LayerSums& sums = layer_sums_[pixel];
            color_[pixel] = front_layer_color(sums, target.background_linear);
            depth_[pixel] = sums.depth;
            ++paths_.layer_sums;
            continue;
          }
          if (layer_[pixel] == Layer::Sampled) {
            ++paths_.overflowed;
            color_[pixel] = resolve_samples(pixel, x, y, target.background_linear, depth_[pixel]);
            continue;
          }
          if (head_[pixel] == kEnd) {
            ++paths_.opaque;
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
}
}  // namespace covrast::detail
