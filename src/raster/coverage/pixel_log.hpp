// Raster stage, coverage mode: the A-buffer's per-pixel fragment log (abuffer.hpp), the cheap
// first stage of a pixel's visibility.
//
// A pixel logs its fragments (triangle, 8.8 coverage, centre depth) in arrival order, with no
// overlap test, and keeps three running values: the summed coverage, the farthest depth its
// fragments reach, and the signed sum of the keys of the triangle edges that cross the open
// pixel square. An edge's key is a 64-bit hash of its two snapped end points, signed + when
// the triangle lies on the left of the edge taken from its lesser to its greater end point
// ((x, y) order) and - when it lies on the right; the two triangles of a shared edge lie on
// opposite sides, so their keys cancel.
//
// The proof. Let c(p) be the number of logged triangles that cover point p of the pixel. c
// changes only across the edges that cross the pixel, and across an edge segment s by
// R(s) - L(s), the triangles on its right minus those on its left. A zero key sum means L(s) =
// R(s) for every segment (up to a collision of 64-bit hashes), so c is one constant k over the
// pixel, and the summed exact areas are k pixels. When the coverage sum reaches the pixel
// (>= kCoverageOne) with a zero key sum and less than 1.5 pixels of area (rounding moves each
// 8.8 value by half a unit at most), k = 1: the fragments tile the pixel without overlapping. The
// pixel is then a *proven layer*: what lies behind its farthest depth everywhere is hidden and
// never logged, and it resolves from its areas (colour = sum(coverage_i * colour_i) /
// sum(coverage_i)), exactly what the list resolve gives pairwise disjoint fragments. A pixel whose
// fragments do not prove a layer (a silhouette, two layers of a surface at a fold, a fragment in
// front of a proven layer) is *mixed*: it resolves by its fragments' 256-sample masks, front to
// back (abuffer_logged.cpp).
//
// A mixed pixel keeps looking for a layer among the fragments that arrive after it turned
// mixed, since a layer further back hides what lies behind it as well: the running sums start
// again and take each fragment as it comes (a run, in arrival order, since a mesh's
// neighbouring triangles arrive close together). A run that reaches the pixel with a zero key
// sum and less than 1.5 pixels, or of pieces of one convex facing, proves a layer by the same
// arguments as the first, and its farthest depth bounds hidden_from; a run that reaches the
// pixel without proving one starts again from its last fragment. Whatever lies behind
// hidden_from is hidden all over the pixel by the layer, so it is never logged, whichever
// state the pixel is in: on a pleated sheet seen edge-on this drops the fragments of masked
// pixels from 348k to 116k a frame.
//
// An edge crosses the open pixel when its line has pixel corners strictly on both sides and
// its bounding box meets the open square: exact in int64 (fx8 coordinates). It can count an
// edge whose segment stops short of the square, but then it counts it for both triangles of
// the edge alike, so keys still cancel; it never misses an edge that enters the square (a line
// through an interior point has corners strictly on both sides).
#pragma once

#include "core/triangle_setup.hpp"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace covrast::detail {

/// Fragments a pixel logs; one more sends it to the A-buffer's list (abuffer.hpp).
inline constexpr int kMaxLoggedFragments = 64;

/// The signed edge keys of one triangle, and which of its edges cross a pixel.
class EdgeCrossingKeys {
 public:
  /// Prepares the keys of `t` (once per triangle: the fragments of a triangle arrive together).
  void set(const TriangleSetup& t);
  const TriangleSetup* triangle() const { return triangle_; }
  void forget() { triangle_ = nullptr; }
  /// The sum of the keys of the edges that cross the open square of pixel (x, y).
  std::uint64_t crossing_sum(int x, int y) const;

 private:
  struct Edge {
    std::int64_t x0_fx8, y0_fx8, dx_fx8, dy_fx8;  ///< start point and direction
    std::int64_t min_x_fx8, max_x_fx8, min_y_fx8, max_y_fx8;
    std::uint64_t key;  ///< signed as the header explains (two's complement)
  };
  const TriangleSetup* triangle_ = nullptr;
  Edge edge_[3];
};

/// What a pixel's log shows.
enum class LogState : std::uint8_t {
  Open,    ///< fragments that have not yet reached the pixel's area
  Proven,  ///< a proven layer (the header), perhaps with nothing else
  Mixed,   ///< anything else: resolved by sample masks
  Off,     ///< the pixel uses the A-buffer's list (or has never logged)
};

/// One logged fragment: 32 bytes.
struct LoggedFragment {
  const TriangleSetup* triangle;
  double centre_z;         ///< the plane at the pixel centre, TriangleSetup::depth_at bit for bit
  float reach;             ///< depth_reach(*triangle), rounded up: the plane stays within +-reach
  std::uint32_t coverage;  ///< 8.8 (kCoverageOne = the pixel)
  std::uint32_t next;      ///< the pixel's next entry, or kLogEnd
};
inline constexpr std::uint32_t kLogEnd = 0xffffffffu;

/// The logs of one tile's pixels: per-pixel state in parallel arrays, entries in one pool.
class PixelLog {
 public:
  explicit PixelLog(std::size_t pixels);

  /// Forgets every entry (a new tile); pixels start with start_pixel.
  void clear_entries();
  /// Makes `pixel` ready: Open and empty, or Off.
  void start_pixel(std::size_t pixel, bool on) {
    state_[pixel] = on ? LogState::Open : LogState::Off;
    count_[pixel] = 0;
  }
  LogState state(std::size_t pixel) const { return state_[pixel]; }
  int count(std::size_t pixel) const { return count_[pixel]; }
  /// A depth at or behind which nothing shows (the nearest farthest depth of the layers
  /// proven so far, the first while Open, later ones by runs once Mixed; +inf: none).
  double hidden_from(std::size_t pixel) const { return hidden_from_[pixel]; }
  /// A layer's colour sums over the pixel's fragments (all of them arrived while it was Open:
  /// one arriving later turns it Mixed): sum(coverage_i * linear colour_i) in arrival order,
  /// and the nearest centre depth. The colours are shaded here, not as the fragments arrive:
  /// a pixel that turns Mixed or is handed to the list never needs them (the list shades
  /// its own), and a textured fragment's shading is the costly part of coverage mode.
  struct LayerColor {
    double rgb[3];
    float depth;
  };
  LayerColor layer_color(std::size_t pixel, int x, int y) const;
  /// While Open: whether every fragment is of one convex surface and facing
  /// (TriangleSetup::convex_surface), whose pieces do not overlap: the list's open set takes
  /// them as disjoint without a test (docs/coverage.md, section 3a, on snapped slivers).
  bool one_convex_facing(std::size_t pixel) const { return convex_[pixel] != kNotConvex; }
  /// While Open: the farthest depth a fragment reaches in the pixel.
  double farthest(std::size_t pixel) const { return far_[pixel]; }
  /// While Open or Proven: the summed coverage of every fragment.
  std::uint32_t coverage_sum(std::size_t pixel) const { return coverage_sum_[pixel]; }
  /// Appends a fragment (`reach`: how far its plane moves from centre_z within the pixel)
  /// and advances the pixel's state (the header's proof).
  void append(std::size_t pixel, int x, int y, const TriangleSetup& t, std::uint32_t coverage,
              double centre_z, double reach);
  /// Empties the pixel's log and turns it Off (its fragments go to the list).
  void turn_off(std::size_t pixel) {
    state_[pixel] = LogState::Off;
    count_[pixel] = 0;
  }
  /// Calls f(fragment) for the pixel's entries in arrival order.
  template <class F>
  void for_each(std::size_t pixel, F f) const {
    std::uint32_t e = head_[pixel];
    for (int i = 0; i < count_[pixel]; ++i, e = entries_[e].next) f(entries_[e]);
  }
  std::size_t scratch_bytes() const;

 private:
  /// The keys of the edges of `t` that cross pixel (x, y); none for a full fragment.
  std::uint64_t crossing_key(const TriangleSetup& t, std::uint32_t coverage, int x, int y);

  std::vector<LogState> state_;
  std::vector<std::uint8_t> count_;
  std::vector<std::uint32_t> head_, tail_;
  /// The running sums of a layer's proof (coverage, keys, farthest depth, convex facing):
  /// while Open, of every fragment; once Mixed, of the run since the last restart.
  std::vector<std::uint32_t> coverage_sum_;
  std::vector<float> near_z_;          ///< while Open: the nearest centre depth
  std::vector<std::uint32_t> convex_;  ///< of the same fragments: convex_key of all, or kNotConvex
  static constexpr std::uint32_t kNotConvex = 0xffffffffu;
  static std::uint32_t convex_key(const TriangleSetup& t) {
    return t.convex_surface ? t.surface * 2 + (t.front_facing ? 1u : 0u) : kNotConvex;
  }
  std::vector<std::uint64_t> key_sum_;
  std::vector<double> far_;
  std::vector<double> hidden_from_;
  /// Whether the running sums, once they reach the pixel, prove a layer.
  bool sums_prove_layer(std::size_t pixel) const;
  void restart_sums(std::size_t pixel);
  /// Once Mixed: adds a fragment to the run and lowers hidden_from when the run proves a layer.
  void prove_later_layer(std::size_t pixel, int x, int y, const TriangleSetup& t,
                         std::uint32_t coverage, double far);
  std::vector<LoggedFragment> entries_;
  EdgeCrossingKeys keys_;
};

}  // namespace covrast::detail
