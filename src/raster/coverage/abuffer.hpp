// Raster stage, coverage mode: the mode's tile state, a per-tile A-buffer (Carpenter 1984)
// whose weights are the exact analytic areas of the coverage kernel. Its parts: this header
// (the tile state), abuffer_add.hpp (the per-pixel insertion, ABufferTile::add, inline),
// abuffer.cpp (tile and block fast paths),
// abuffer_insert.cpp (open and closed sets, merging), abuffer_samples.cpp (overflow into
// samples), abuffer_resolve.cpp and abuffer_visibility.cpp (the resolve), abuffer_planes.hpp
// (depth planes and pixel polygons they share).
//
// Partly covered pixels first log their fragments without any overlap test (pixel_log.hpp):
// most pixels of a dense mesh are tiled by one layer of its triangles, which the log proves
// from the edges its fragments share and resolves from their areas; a pixel where layers
// meet resolves from its fragments' sample masks, front to back (abuffer_logged.cpp). The
// machinery below serves the rest: pixels whose first partial fragment meets a fragment list
// already there, logs that grow past kMaxLoggedFragments, transparent pixels, and the
// testing switches that ask for it.
//
// Fully covered pixels take a fast path: an ordinary depth test against one opaque
// surface per pixel (depth planes compared at the pixel's four corners, so a plane that
// crosses the opaque one inside the pixel is kept as a fragment instead). The same test
// runs once per tile, and once per 8x8 block, while the tile or block still shows a single
// opaque triangle and the new one covers it completely; per-pixel state is written only
// when a block needs it. Partly covered pixels keep a short list of fragments (triangle,
// 8.8 coverage), resolved front to back when the tile is done.
//
// Exact areas add only where fragments provably do not overlap (triangle_overlap.hpp: a
// separating edge, exact in integers). Each pixel grows an *open set* of fragments in
// arrival order: a fragment joins it when it overlaps none of its members. So
//  - while every fragment of a pixel is in the open set (Layer::One), the pixel keeps the
//    set's running sums and, over the background, resolves from them alone:
//    colour = sum(coverage_i * colour_i) / max(sum coverage, 1) + (1 - sum coverage) *
//    background, exactly what the per-sample resolve gives for disjoint fragments;
//  - when the open set's areas add up to the whole pixel, the pixel is covered by it
//    (disjoint pieces whose areas fill the square leave at most the rounding of the 8.8
//    values uncovered). It becomes the pixel's *closed set*: a later fragment that is farther
//    than, or as far as, every member it overlaps (planes compared at the pixel corners) is
//    hidden everywhere and never stored, and the fragments already stored that it hides
//    leave the list. This is what keeps lists short on dense and open meshes, where no
//    single triangle covers a pixel; the farthest depth of the set bounds it cheaply first;
//  - otherwise the pixel resolves from its list (resolve_pixel): a set of pairwise disjoint
//    fragments in front of the opaque surface adds its areas; else 256 sub-pixel samples
//    with per-sample depth from each plane decide what hides what: a fragment that nothing
//    in front of it overlaps keeps its exact area, the others get their coverage times the
//    share of their samples where they are nearest; what remains goes to the opaque surface
//    behind, or the background.
#pragma once

#include "core/tile_raster.hpp"
#include "core/triangle_setup.hpp"
#include "raster/coverage/coverage_kernel.hpp"
#include "raster/coverage/fragment_shading.hpp"
#include "raster/coverage/pixel_log.hpp"
#include "raster/coverage/sample_mask.hpp"
#include "raster/coverage/triangle_overlap.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

namespace covrast::detail {

/// Fragments one pixel keeps while they are one disjoint set (sub-pixel triangles of dense
/// meshes put dozens in a pixel, up to ~180 at the pole of a UV sphere). Beyond it (counted
/// in overflow_count()) a fragment that joins the set merges into a member that keeps its
/// pieces, so the sums stay exact; otherwise the pixel turns into samples (PixelSamples).
inline constexpr int kMaxFragmentsPerPixel = 128;
/// Fragments a pixel keeps while they are not one disjoint set: past it, the list resolve
/// would compare every fragment with every other (O(n^2)), so the pixel turns into 256
/// depth-tested samples instead, at the cost of MSAA per further fragment.
inline constexpr int kMaxMixedFragments = 32;

/// The margin a pixel's depth bound (occluder_z_) keeps behind the farthest depth that fills
/// the pixel (its samples', or its visible parts'): far above the rounding of a centre depth,
/// a reach and a plane value (all within 1e-15 of their exact values in [0, 1]).
inline constexpr double kOccluderMargin = 1e-9;

/// Block side [pixels] of the A-buffer's block-level fast path.
inline constexpr int kAbufferBlockPx = 8;

/// How far a triangle's plane can move from its pixel-centre depth within the pixel:
/// (|dz/dx| + |dz/dy|) / 2.
inline double depth_reach(const TriangleSetup& t) {
  return 0.5 * (std::fabs(t.dzdx) + std::fabs(t.dzdy));
}

/// How one triangle's depth plane lies against another's over a pixel.
enum class DepthOrder { InFront, Behind, Crossing };

/// Whether two triangles share a vertex: neighbours in a tessellation do (an edge, or a
/// fan's centre). It groups fragments into a front layer and picks merge partners; it proves
/// nothing about overlap (triangle_overlap.hpp does). b's vertices are compared with all of
/// a's at once, in 4-lane integer vectors (GCC/Clang vector extensions: SSE2 on x86-64, NEON
/// on Arm), without a branch per pair.
inline bool share_vertex(const TriangleSetup& a, const TriangleSetup& b) {
  using Lanes = std::int32_t __attribute__((vector_size(16)));
  // a's x0 x1 x2 and y0 y1 y2 (the fourth lane is the next member's bytes, masked out below).
  static_assert(offsetof(TriangleSetup, y_fx8) + sizeof(Lanes) <= sizeof(TriangleSetup));
  const char* bytes = reinterpret_cast<const char*>(&a);
  Lanes ax, ay;
  std::memcpy(&ax, bytes + offsetof(TriangleSetup, x_fx8), sizeof(Lanes));
  std::memcpy(&ay, bytes + offsetof(TriangleSetup, y_fx8), sizeof(Lanes));
  const Lanes same = ((ax == b.x_fx8[0]) & (ay == b.y_fx8[0])) |
                     ((ax == b.x_fx8[1]) & (ay == b.y_fx8[1])) |
                     ((ax == b.x_fx8[2]) & (ay == b.y_fx8[2]));
  return (same[0] | same[1] | same[2]) != 0;
}

/// Whether a and b are pieces of one convex surface with one facing, which the open set
/// takes as disjoint without a test. Exact for the true projection; after snapping to the
/// 1/256 grid, a sliver at the silhouette whose snapped facing differs from its true one can
/// overlap its neighbours by part of its own (tiny) area: on the sphere grid at 96x54 the
/// exact test everywhere changes 23 pixels by at most 4/255, at 1920x1080 none by more than
/// 1/255.
inline bool one_convex_facing(const TriangleSetup& a, const TriangleSetup& b) {
  return a.convex_surface && b.convex_surface && a.surface == b.surface &&
         a.front_facing == b.front_facing;
}

/// How a pixel's visible weights w_i (each at most its fragment's area) share it: colour =
/// scale sum_i w_i c_i + rest behind. Visible parts are disjoint, so their sum passes the
/// pixel only by rounding or where samples and areas disagree: then the weights are
/// normalised and nothing behind shows.
struct PixelShares {
  double scale = 1.0;
  double rest = 1.0;
};

inline PixelShares pixel_shares(int n, const double* weight) {
  double total = 0.0;
  for (int i = 0; i < n; ++i) total += weight[i];
  return {total > 1.0 ? 1.0 / total : 1.0, total > 1.0 ? 0.0 : 1.0 - total};
}

/// scale sum_i w_i c_i over the fragments with a weight, c_i = color_of(i), in index order.
template <class ColorOf>
glm::dvec3 weighted_sum(int n, const double* weight, double scale, const ColorOf& color_of) {
  glm::dvec3 rgb(0.0);
  for (int i = 0; i < n; ++i) {
    if (weight[i] != 0.0) rgb += weight[i] * scale * glm::dvec3(color_of(i));
  }
  return rgb;
}

class ABufferTile {
 public:
  explicit ABufferTile(int tile_px);

  void begin_tile(const PixelRect& rect);
  /// Makes pixels [x0, x1) of row y ready for add() (at most two blocks: x1 - x0 <= 8):
  /// leaves the whole-tile state and writes out the state of uniform blocks.
  inline void prepare_row(int x0, int x1, int y);
  /// Coverage 8.8 (kCoverageOne = full) of triangle `t` at pixel (x, y) of this tile, which
  /// prepare_row() has made ready; `centre_z` is t->depth_at(x + 0.5, y + 0.5), bit for bit.
  inline void add(int x, int y, const TriangleSetup* t, std::uint32_t coverage, double centre_z);
  /// Whole-tile fast path for triangle `t` (its pixels `r` clipped to the tile): when it
  /// covers every pixel of the tile and every pixel still shows one opaque triangle (or the
  /// background) and nothing else, the new plane is compared with that one once, at the
  /// tile's corners (their difference is affine, so extreme there), instead of pixel by
  /// pixel. Returns false when it cannot decide (not covering, planes too close or crossing,
  /// or the tile no longer uniform); the caller then adds the triangle pixel by pixel, which
  /// gives what this would have.
  bool add_covering_tile(const TriangleSetup& t, const PixelRect& r);
  /// The same per block of 8x8 pixels: for every block of the tile that meets `r` and that
  /// `t` covers completely, while the block still shows one opaque triangle. Returns whether
  /// any block was decided; the caller skips their pixels (block_decided).
  bool add_covering_blocks(const TriangleSetup& t, const PixelRect& r);
  bool block_decided(int x, int y) const { return decided_[block_of(x, y)] == decided_stamp_; }
  /// Whether add() would drop every fragment of opaque triangle `t` in the pixels `r` (at
  /// most kMaxHiddenTestPx of them) as hidden, with no other effect: the same tests on the
  /// same bits (a proven layer's hidden_from, the list's occluder depth, the opaque plane's
  /// quick order), so that skipping the triangle leaves the tile as drawing it would.
  /// Pixels where a fragment would change state (a log at its limit hands over to the list,
  /// an empty log over a started list turns off) answer no.
  bool hides_rect(const TriangleSetup& t, const PixelRect& r) const;
  static constexpr int kMaxHiddenTestPx = 64;
  /// A fragment of a BLEND triangle (AlphaMode::Blend), which prepare_row() has made
  /// ready: kept in the pixel's own transparent list, apart from the opaque fragments, and
  /// composited in depth order at the resolve (abuffer_transparency.cpp).
  void add_transparent(int x, int y, const TriangleSetup* t, std::uint32_t coverage,
                       double centre_z);
  /// Resolves every pixel and writes the tile into the frame; counts each pixel's path.
  void resolve(const FrameTarget& target);

  std::size_t scratch_bytes() const;
  std::uint64_t overflow_count() const { return overflows_; }
  /// Pixels per resolve path since the last call (resolve() counts every pixel once).
  CoverageResolvePaths take_resolve_paths() {
    const CoverageResolvePaths paths = paths_;
    paths_ = {};
    return paths;
  }

 private:
  /// What the transparent fragments in front leave of each opaque contributor of a pixel
  /// (a triangle, or null for the background): the mean transmittance over the samples where
  /// it is the nearest opaque surface; `fallback` (the pixel's mean) for one that owns none.
  /// Per channel: a transmissive fragment's filter tints what it passes.
  struct Transmittance {
    int n = 0;
    const TriangleSetup* who[kMaskSamples + 1];
    glm::dvec3 keep[kMaskSamples + 1];
    glm::dvec3 fallback{1.0};
    glm::dvec3 of(const TriangleSetup* t) const {
      for (int k = 0; k < n; ++k) {
        if (who[k] == t) return keep[k];
      }
      return fallback;
    }
  };
  /// rgb += w x c, times what `tr` (when given) keeps of contributor t: the opaque resolve's
  /// one weighted sum, with the same operations as without transparency where tr is null.
  static void add_kept(double rgb[3], double w, const Transmittance* tr, const TriangleSetup* t,
                       glm::vec3 c) {
    if (tr == nullptr) {
      rgb[0] += w * c.r;
      rgb[1] += w * c.g;
      rgb[2] += w * c.b;
      return;
    }
    const glm::dvec3 keep = tr->of(t);
    rgb[0] += w * keep.r * c.r;
    rgb[1] += w * keep.g * c.g;
    rgb[2] += w * keep.b * c.b;
  }
  /// One triangle's piece of a pixel: 16 bytes, so a tile's lists stay in cache.
  struct Fragment {
    const TriangleSetup* triangle;  ///< when merged: the piece whose plane stands for all
    std::uint32_t next;             ///< index into pool_, or kEnd
    /// 8.8, 1/255 units (kCoverageBits); kMergedFlag: see merged_; kOpenFlag, kClosedFlag:
    /// member of the pixel's open or closed set.
    std::uint32_t coverage;
  };
  /// What a fragment that stands for several triangles of one surface keeps (overflow only).
  static constexpr int kMaxMergedPieces = 6;
  struct MergedPiece {
    SampleMask mask;       ///< 256-sample mask: the union of the pieces'
    glm::vec3 color;       ///< coverage-weighted mean colour (linear)
    std::uint32_t weight;  ///< summed coverage behind `color` (unclamped)
    /// The triangles it stands for, so that overlap tests stay exact.
    std::uint8_t pieces;
    const TriangleSetup* piece[kMaxMergedPieces];
  };
  /// The triangles fragment `f` stands for, in `out`: one, or a merged fragment's pieces.
  int fragment_pieces(std::uint32_t f, const TriangleSetup* const*& out) const {
    if (!(pool_[f].coverage & kMergedFlag)) {
      out = &pool_[f].triangle;
      return 1;
    }
    const MergedPiece& m = merged_piece(f);
    out = m.piece;
    return m.pieces;
  }
  static constexpr std::uint32_t kMergedFlag = 0x80000000u;
  static constexpr std::uint32_t kOpenFlag = 0x40000000u;
  static constexpr std::uint32_t kClosedFlag = 0x20000000u;
  static constexpr std::uint32_t kCoverageBits = 0x1fffffffu;
  static constexpr std::uint32_t kEnd = 0xffffffffu;

  inline DepthOrder order_against_opaque(const TriangleSetup& t, double t_centre_z,
                                         std::size_t pixel, int x, int y) const;
  /// Whether the pixel's fragment list has begun (a fragment, or a layer state), which turns
  /// an empty log off when a partial fragment arrives (log_fragment, hides_pixel).
  bool list_started(std::size_t pixel) const {
    return head_[pixel] != kEnd || layer_[pixel] != Layer::Empty;
  }
  /// Whether add() would drop the fragment of `t` at pixel (x, y) as hidden (hides_rect).
  bool hides_pixel(const TriangleSetup& t, int x, int y) const;
  /// add() for a pixel whose log is not Off: logs the fragment, drops it (hidden), or returns
  /// false for the list to take it (after turning the log Off and handing its fragments on).
  inline bool log_fragment(std::size_t pixel, int x, int y, const TriangleSetup& t,
                           std::uint32_t coverage, double centre_z);
  /// add() for a pixel whose log is Off: the list.
  inline void add_to_list(std::size_t pixel, int x, int y, const TriangleSetup* t,
                          std::uint32_t coverage, double centre_z);
  /// Turns the pixel's log Off and adds its fragments to the list, in arrival order: the
  /// state the list would have had from the start (abuffer_logged.cpp).
  void hand_log_to_list(std::size_t pixel, int x, int y);
  /// Resolves a pixel with a non-empty log into color_ and depth_ (abuffer_logged.cpp).
  void resolve_logged(std::size_t pixel, int x, int y, glm::vec3 background);
  /// A proven layer: its areas add, as a disjoint open set's sums do.
  void resolve_proven(std::size_t pixel, int x, int y);
  /// Any other log: each fragment's 256-sample mask, nearest first; the samples a nearer
  /// fragment holds are hidden (per sample by the planes where depth ranges overlap), and a
  /// fragment weighs its exact area times the share of its samples it keeps.
  void resolve_masked(std::size_t pixel, int x, int y, glm::vec3 background);
  /// A log of at most kMaxClippedLog untextured fragments: each one's exact visible area
  /// (visible_parts.hpp) over the opaque surface or the background; false (nothing written)
  /// for any other log. Beyond a few fragments the clipping's pairs (O(n^2)) cost more than
  /// the masks, whose estimate is good where fragments are many and small.
  bool resolve_clipped_log(std::size_t pixel, int x, int y, glm::vec3 background);
  static constexpr int kMaxClippedLog = 6;
  static constexpr int kBlockPx = kAbufferBlockPx;
  std::size_t block_of(int x, int y) const {
    return std::size_t((y - rect_.y0) / kBlockPx) * block_stride_ + (x - rect_.x0) / kBlockPx;
  }
  /// Pixels of block `b`, clipped to the tile.
  PixelRect block_rect(std::size_t b) const;
  /// Leaves the whole-tile state: every block shows the tile's uniform triangle.
  void split_tile();
  /// Leaves the block state: writes the block's opaque triangle into its pixels.
  void materialize_block(std::size_t b);
  inline void add_fragment(std::size_t pixel, int x, int y, const TriangleSetup* t,
                           std::uint32_t coverage, double centre_z);
  /// What drop_hidden did with a full list and a new fragment `t`.
  enum class Compaction {
    NewHidden,  ///< t is hidden: nothing more to do
    Room,       ///< hidden fragments left the list, which has room for t again
    Full,       ///< too little left it (or the list is not deep enough to try): samples
  };
  /// A mixed list at its limit whose areas add up to kCompactionDepth pixels or more (a
  /// stack of layers, most of which cannot show): the fragments that the others and the
  /// opaque surface hide all over their part of the pixel, by exact clipping, leave it.
  Compaction drop_hidden(std::size_t pixel, int x, int y, const TriangleSetup& t);
  static constexpr double kCompactionDepth = 4.0;
  /// The list is full: the overflow policy; true when `t` was absorbed, false when
  /// drop_hidden made room for it.
  bool overflow_fragment(std::size_t pixel, int x, int y, const TriangleSetup* t,
                         std::uint32_t coverage, double centre_z);
  /// Whether `t` overlaps no fragment of the pixel's open set (an empty set takes anything).
  inline bool joins_open_set(std::size_t pixel, const TriangleSetup& t) const;
  /// Adds fragment `t` to the open set's running sums (restarting them for an empty set).
  inline void add_to_sums(std::size_t pixel, int x, int y, const TriangleSetup& t,
                          std::uint32_t coverage, double centre_z);
  /// The open set's areas fill the pixel: it becomes the closed set (the pixel's occluder),
  /// the fragments it hides leave the list, and a new open set is started from the rest.
  void complete_open_set(std::size_t pixel, int x, int y);
  /// Whether `behind(m)` holds for every triangle m of the pixel's closed set that `t`
  /// overlaps. The closed set covers the pixel, so every point of t's part of it lies in such
  /// an m: t is hidden there when it is behind each of them.
  template <class Behind>
  bool behind_closed_set(std::size_t pixel, const TriangleSetup& t, Behind behind) const;
  /// Whether the newest stored fragment is a single triangle that contains `t` and is nearer
  /// than or level with it all over the pixel (so t, being later, shows nowhere): many copies
  /// of one triangle.
  bool hidden_by_container(std::size_t pixel, int x, int y, const TriangleSetup& t) const;
  /// Removes the fragments for which `drop(fragment)` holds from the pixel's list.
  template <class Drop>
  void remove_fragments(std::size_t pixel, Drop drop);
  /// Turns a pixel's list into 256 sub-pixel samples (see PixelSamples) and frees it; the
  /// caller then sets the pixel's depth bound (bound_by_samples).
  void to_samples(std::size_t pixel, int x, int y);
  /// Draws triangle `t` into a sampled pixel's samples: nearest wins, equal depth keeps the
  /// earlier triangle. Returns whether it won any sample.
  bool add_to_samples(std::size_t pixel, int x, int y, const TriangleSetup& t);
  /// Lowers the pixel's occluder_z_ to (just behind) its farthest sample depth.
  void bound_by_samples(std::size_t pixel);
  /// A sampled pixel's colour: the mean of its samples' winners' colours (and its depth).
  glm::vec3 resolve_samples(std::size_t pixel, int x, int y, glm::vec3 background, float& depth,
                            const Transmittance* tr = nullptr);
  /// Merges triangle `t`'s piece (coverage, sample mask, colour at the pixel centre) into
  /// fragment `f`, which has room for another piece.
  void merge_into(std::uint32_t f, const TriangleSetup& t, std::uint32_t coverage, int x, int y);
  /// Overflow of a pixel, by a fragment that joins its open set: merges it into an open
  /// member, keeping the pieces and the exact sums; false when no member has room for another
  /// piece.
  bool merge_into_open_set(std::size_t pixel, int x, int y, const TriangleSetup& t,
                           std::uint32_t coverage, double centre_z);
  /// The merged data of fragment `f` (which has kMergedFlag).
  const MergedPiece& merged_piece(std::uint32_t f) const { return merged_[merged_slot_[f]]; }
  /// Each fragment's visible weight from the 256 samples (estimated[i]: a share of its
  /// samples, not an exact area); returns how many samples the opaque surface or the
  /// background behind keeps.
  int sample_weights(int x, int y, const TriangleSetup* opaque, int n,
                     const TriangleSetup* const* tri, const std::uint32_t* cov,
                     const MergedPiece* const* merged, double* weight, bool* estimated) const;
  /// Whether fragment i keeps its exact area: in front of the opaque surface, and every
  /// other fragment either misses it (a separating edge) or lies behind it all over the
  /// pixel. `suspect` (or -1): a fragment to test first, one that took a sample of it.
  static bool shows_whole(int x, int y, const TriangleSetup* opaque, int n,
                          const TriangleSetup* const* tri, const MergedPiece* const* merged, int i,
                          int suspect);
  /// resolve() without the check that every pixel was counted once.
  void resolve_tile(const FrameTarget& target);
  /// Whether no two fragments of the pixel's list (with `only` != 0: of those with that flag)
  /// overlap, by the exact test on every pair of their triangles other than pairs of one
  /// convex surface and facing, which the open set takes as disjoint without a test
  /// (one_convex_facing): the invariant of an open set and of a one-layer pixel, checked by
  /// COVRAST_CHECK.
  bool pairwise_disjoint(std::size_t pixel, std::uint32_t only) const;
  /// Writes the pixels `r` that show `opaque` (null: the background) alone into the frame.
  void resolve_opaque_block(const TriangleSetup* opaque, const PixelRect& r,
                            const FrameTarget& target);
  /// With `tr`, every opaque contributor's weight is multiplied by tr->of(contributor): the
  /// opaque part of a pixel behind transparent fragments (null: the opaque resolve as is).
  glm::vec3 resolve_pixel(std::size_t pixel, int x, int y, glm::vec3 background, float& depth,
                          const Transmittance* tr = nullptr);
  /// resolve_pixel's parts (abuffer_resolve.cpp): the list's fragments that the opaque
  /// surface does not hide (their nearest centre depth lowers `depth`); their colour when
  /// their exact areas add; whether the front layer's do; their colour from visible weights.
  struct ListFragments;
  void gather_list(std::size_t pixel, int x, int y, ListFragments& l, float& depth) const;
  static glm::vec3 list_layer_color(const ListFragments& l, const bool* member, glm::vec3 behind,
                                    float depth, const Transmittance* tr, int x, int y);
  static bool front_layer_alone(const ListFragments& l, bool* in_front);
  static glm::vec3 list_weighted_color(const ListFragments& l, const double* weight,
                                       glm::vec3 behind, const Transmittance* tr, int x, int y);
  /// The clipped path's colours: one triangle crossing the opaque plane in the pixel, with
  /// visible weight `weight`; each textured side shows what shows of it
  /// (shade_fragment_visible), in l and in `behind`.
  static void show_crossing_sides(ListFragments& l, const TriangleSetup& opaque, int x, int y,
                                  double weight, const Transmittance* tr, glm::vec3& behind);
  /// A pixel with transparent fragments: the opaque resolve seen through them plus their own
  /// weighted colours (abuffer_transparency.cpp).
  glm::vec3 resolve_transparent(std::size_t pixel, int x, int y, glm::vec3 background,
                                float& depth);
  /// resolve_transparent's parts (abuffer_transparency.cpp): each transparent fragment's
  /// shown share (S_j, summed) and each opaque contributor's keep_o from the 256 samples
  /// (`z_opaque`, `id`: the nearest opaque surface at each); S_j of the fragments that own no
  /// sample, at one point inside them.
  struct Clear;
  static void transmittance_by_samples(std::vector<Clear>& clear, int x, int y,
                                       const double* z_opaque, const TriangleSetup* const* id,
                                       Transmittance& tr);
  void sliver_transmittance(std::size_t pixel, int x, int y, std::vector<Clear>& clear,
                            const Transmittance& tr) const;
  /// The common case of resolve_transparent: every transparent fragment covers the pixel,
  /// lies in front of every opaque contributor all over it, and no two of them cross there.
  /// Then `transmit` = prod_j pass_j and `light` = sum_j alpha_j c_j prod_{i < j} pass_i,
  /// nearest first, pass_j = (1 - alpha_j) + alpha_j filter_j (composite.hpp); false otherwise.
  bool uniform_transparency(std::size_t pixel, int x, int y, glm::dvec3& transmit,
                            glm::dvec3& light) const;
  /// The pixel's opaque resolve with each contributor weighted by tr.of(contributor).
  glm::vec3 opaque_through(std::size_t pixel, int x, int y, glm::vec3 background, float& depth,
                           const Transmittance& tr);
  /// Per sample of a pixel, the nearest opaque depth and its triangle (null: background).
  void opaque_samples(std::size_t pixel, int x, int y, double* z, const TriangleSetup** id) const;

  int stride_;
  int capacity_;  ///< fragments per pixel before the overflow policy, <= kMaxFragmentsPerPixel
  int mixed_capacity_;  ///< the same for a pixel whose fragments are not one disjoint set
  PixelRect rect_;
  /// While tile_uniform_: every pixel's opaque triangle is uniform_ (null = background), no
  /// pixel has fragments, and neither the blocks' nor the pixels' state is written.
  bool tile_uniform_ = true;
  const TriangleSetup* uniform_ = nullptr;
  /// Per 8x8 block, the same one level down: while block_uniform_, every pixel of the block
  /// shows block_opaque_ and has no fragments, and its pixel state is not written.
  int block_stride_;
  std::vector<std::uint8_t> block_uniform_;
  std::vector<const TriangleSetup*> block_opaque_;
  std::vector<std::uint32_t> decided_;  ///< per block, the stamp of the draw that decided it
  std::uint32_t decided_stamp_ = 0;
  std::vector<const TriangleSetup*> opaque_;  ///< per pixel, null = background
  std::vector<double> opaque_z_;              ///< per pixel, the opaque plane at the centre
  std::vector<std::uint32_t> head_;           ///< per pixel, first fragment (newest last)
  std::vector<std::uint32_t> tail_;           ///< per pixel, last fragment
  std::vector<std::uint8_t> count_;           ///< per pixel, fragments in the list
  /// Per pixel: Empty (no fragments), One (every fragment is in the open set, or in the
  /// closed set and nothing else is stored: they are pairwise disjoint and layer_sums_
  /// describes them all), Mixed, or Sampled (the list overflowed into samples_; no list and
  /// no sets are kept).
  enum class Layer : std::uint8_t { Empty, One, Mixed, Sampled };
  /// Running sums of the pixel's open set, or of its closed set while that is all there is.
  struct LayerSums {
    std::uint32_t coverage;  ///< sum of the fragments' 8.8 coverage
    double rgb[3];           ///< sum of coverage * linear colour, in list order
    float depth;             ///< nearest centre depth
    double far;              ///< farthest depth any member reaches in the pixel
    /// surface * 2 + front_facing when every member is of that one convex surface and facing
    /// (their overlap tests are then known: none), else kNoConvexKey.
    std::uint32_t convex_key;
  };
  static constexpr std::uint32_t kNoConvexKey = 0xffffffffu;
  static std::uint32_t convex_key(const TriangleSetup& t) {
    return t.convex_surface ? t.surface * 2 + (t.front_facing ? 1u : 0u) : kNoConvexKey;
  }
  /// Colour of a layer in front of everything else (abuffer_resolve.cpp).
  static glm::vec3 front_layer_color(const LayerSums& sums, glm::vec3 behind);
  /// The log's layer sums (PixelLog::layer_color: shaded now, in arrival order) as the
  /// list's LayerSums.
  LayerSums logged_sums(std::size_t pixel, int x, int y) const;
  std::vector<Layer> layer_;
  std::vector<LayerSums> layer_sums_;
  std::vector<std::uint8_t> open_count_;    ///< per pixel, fragments in the open set
  std::vector<std::uint8_t> closed_count_;  ///< per pixel, fragments in the closed set
  /// Per pixel, a depth at or behind which nothing is visible: the farthest depth of the
  /// closed sets so far, or (a margin behind) of a sampled pixel's samples (+inf: none).
  std::vector<double> occluder_z_;
  /// The pixels' logs (pixel_log.hpp); on unless testing::CoverageHooks::list_only.
  PixelLog log_;
  bool log_on_;
  /// Mixed pixels may be resolved by exact clipping; on unless testing::CoverageHooks::no_clipping.
  bool clipping_on_;
  std::vector<Fragment> pool_;
  std::vector<std::uint32_t> merged_slot_;  ///< per fragment, index into merged_ (when merged)
  std::vector<MergedPiece> merged_;
  /// A pixel whose list overflowed, as 256 samples at the positions of the sample masks: per
  /// sample the nearest depth so far and the triangle that has it (null: the background).
  /// MSAA-like cost per fragment, however many arrive; the pixel's tail_ holds its index.
  struct PixelSamples {
    double z[kMaskSamples];
    /// The winner's primitive index, for the tie rule (0 for the background, which a tie
    /// never takes from: a finite plane is never level with its infinite depth anyway).
    std::uint64_t primitive[kMaskSamples];
    const TriangleSetup* winner[kMaskSamples];
    /// How many of the pixel's samples the winner owns (its mask's count, kept from when it
    /// was drawn so that the resolve does not compute the mask again).
    std::uint16_t winner_owned[kMaskSamples];
  };
  std::vector<PixelSamples> samples_;
  /// Transparent fragments (BLEND triangles), per pixel a list apart from the opaque ones;
  /// transparent_head_ is valid only while any_transparent_ (set by the tile's first one),
  /// so an opaque tile never touches it.
  std::vector<Fragment> transparent_pool_;
  std::vector<std::uint32_t> transparent_head_;
  bool any_transparent_ = false;
  std::vector<glm::vec3> color_;  ///< resolved linear colour
  std::vector<float> depth_;      ///< resolved window depth
  std::uint64_t overflows_ = 0;
  CoverageResolvePaths paths_;  ///< pixels per resolve path (take_resolve_paths)
};

/// How plane `t` lies against plane `other` over pixel (x, y), from their depths at the
/// pixel's four corners (abuffer.cpp).
DepthOrder order_of(const TriangleSetup& t, const TriangleSetup& other, int x, int y);

/// order_of's answer where the planes' difference at the pixel centre and a bound on how far
/// it can move towards a corner decide it: |d(corner) - d(centre)| <= (|ddz/dx| + |ddz/dy|)
/// / 2. Crossing near ties, where order_against_opaque falls back to the exact corner
/// comparison (order_of) and hides_pixel answers no.
inline DepthOrder quick_order(const TriangleSetup& t, double t_centre_z, const TriangleSetup& o,
                              double o_centre_z) {
  const double d = t_centre_z - o_centre_z;
  const double reach = 0.5 * (std::fabs(t.dzdx - o.dzdx) + std::fabs(t.dzdy - o.dzdy));
  constexpr double kMargin = 1e-12;  // far above the rounding of z in [0, 1]
  if (d + reach < -kMargin) return DepthOrder::InFront;
  if (d - reach > kMargin) return DepthOrder::Behind;
  return DepthOrder::Crossing;
}

}  // namespace covrast::detail

// The per-pixel insertion's definitions, inline: the coverage kernel's row loop calls add()
// once per pixel it touches.
#include "raster/coverage/abuffer_add.hpp"
