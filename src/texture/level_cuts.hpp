// The geometry of an exact texture average on one mip level (texture.cpp, level_average): the
// UV polygon in cell units, the cells its bounds reach, and its pieces cut at the inner cell
// nodes, with their moments. It depends on the polygon, the level's size and the filter's
// order, never on the texels, so the slots of a fragment that share a UV set and a texture
// size (a PBR material's base colour, metallic-roughness, occlusion, emissive and normal maps)
// can cut and integrate their polygon once: LevelCutsMemo keeps the pieces for them.
#pragma once

#include "core/checks.hpp"
#include "core/convex_polygon.hpp"

#include <array>
#include <cmath>
#include <cstdint>

namespace covrast::detail {

/// A texel coordinate as a wrapped index: NaN and huge values (a UV far outside any
/// sensible range) are pinned first, so the integer conversion is defined.
inline long long texel_floor(double v) {
  constexpr double kLimit = 1e15;
  if (!(v > -kLimit)) return -static_cast<long long>(kLimit);
  if (!(v < kLimit)) return static_cast<long long>(kLimit);
  return static_cast<long long>(std::floor(v));
}

/// The cells of one level an average may reach: 8 x 8, a footprint of several texels
/// (coverage mode asks on levels whose texels are about a pixel wide).
constexpr int kMaxCells = 64;

/// The integrals over `q` of 1, a, b and a b, with a = s - s0, b = t - t0, signed by its
/// orientation (Green's theorem; Steger, "On the calculation of arbitrary moments of
/// polygons", 1996): with c_i = a_i b_j - a_j b_i, j = i + 1,
///   M_1 = sum c_i / 2,  M_a = sum (a_i + a_j) c_i / 6,  M_b = sum (b_i + b_j) c_i / 6,
///   M_ab = sum (2 a_i b_i + a_i b_j + a_j b_i + 2 a_j b_j) c_i / 24.
struct Moments {
  double m1 = 0.0, ma = 0.0, mb = 0.0, mab = 0.0;
};
Moments moments(const ConvexPolygon& q, double s0, double t0);

/// A UV polygon P on a width x height level for a filter of order 0 (NEAREST: s = u W, texel
/// i is the cell [i, i + 1]) or 1 (LINEAR: s = u W - 1/2, texel centres at the integers): P in
/// s, t, the cells its bounds reach (first i0, j0) and its moments about (i0, j0).
struct LevelPolygon {
  ConvexPolygon p;
  bool fits = false;  ///< P has 3 or more vertices and reaches at most kMaxCells cells
  long long i0 = 0, j0 = 0;
  int columns = 0, rows = 0;
  Moments whole;  ///< set() only
  /// P, its cells and its moments.
  void set(int width, int height, const ConvexPolygon& uv, int order);
  /// P and its cells only (what the texels read need).
  void set_cells(int width, int height, const ConvexPolygon& uv, int order);
};

/// S_ps = P n {s >= i0 + ps} (0 < ps < columns) into `column`; false when it has fewer
/// than 3 vertices.
inline bool cut_column(const LevelPolygon& at, int ps, ConvexPolygon& column) {
  COVRAST_CHECK(at.fits && ps > 0 && ps < at.columns, "a column cut inside the cells");
  clip_half_plane(at.p, 1.0, 0.0, -double(at.i0 + ps), column);  // straight into `column`
  return column.n >= 3;
}

/// The moments of `column` (S_ps; P for ps = 0) n {t >= j0 + pt} about (i0 + ps, j0 + pt)
/// into `piece`, for (ps, pt) not (0, 0); false when that has fewer than 3 vertices.
inline bool cut_piece(const LevelPolygon& at, const ConvexPolygon& column, int ps, int pt,
                      Moments& piece) {
  COVRAST_CHECK(at.fits && ps < at.columns && pt < at.rows && (ps > 0 || pt > 0),
                "a piece cut inside the cells, not the whole polygon");
  const double s0 = double(at.i0 + ps), t0 = double(at.j0 + pt);
  if (pt == 0) {
    piece = moments(column, s0, t0);
    return true;
  }
  const ConvexPolygon cut = clip_half_plane(column, 0.0, 1.0, -t0);
  if (cut.n < 3) return false;
  piece = moments(cut, s0, t0);
  return true;
}

/// The pieces level_average integrates, S_ps = P n {s >= i0 + ps} and S_ps n {t >= j0 + pt},
/// cut as they are asked for and not kept: the loop asks for column(ps), then for its pieces
/// piece(ps, pt) (0 <= pt < rows), before the next column.
class DirectCuts {
 public:
  DirectCuts(int width, int height, const ConvexPolygon& uv, int order) {
    at_.set(width, height, uv, order);
  }
  const LevelPolygon& at() const { return at_; }
  /// S_ps for 0 < ps < columns; nullptr when the cut leaves fewer than 3 vertices.
  const ConvexPolygon* column(int ps) {
    column_index_ = ps;
    return cut_column(at_, ps, column_) ? &column_ : nullptr;
  }
  /// The moments of S_ps n {t >= j0 + pt} about (i0 + ps, j0 + pt), not both 0 (that is
  /// at().whole), S_ps not empty; nullptr when the piece has fewer than 3 vertices.
  const Moments* piece(int ps, int pt) {
    COVRAST_CHECK(ps == 0 || ps == column_index_, "a piece of the column cut last");
    return cut_piece(at_, ps == 0 ? at_.p : column_, ps, pt, piece_) ? &piece_ : nullptr;
  }

 private:
  LevelPolygon at_;
  int column_index_ = 0;
  ConvexPolygon column_;
  Moments piece_;
};

/// The same pieces, kept once cut, so that whoever asks for a piece again (another texture
/// on the same polygon and level size) gets the same bits without cutting again.
class LevelCuts {
 public:
  void reset(int width, int height, const ConvexPolygon& uv, int order);
  bool matches(int width, int height, const ConvexPolygon& uv, int order) const;
  const LevelPolygon& at() const { return at_; }
  const ConvexPolygon* column(int ps) {
    const std::uint8_t state = column_state_[std::size_t(ps)];
    if (state == kUnknown) return cut_and_keep_column(ps);
    return state == kCut ? &column_[std::size_t(ps)] : nullptr;
  }
  const Moments* piece(int ps, int pt) {
    const std::size_t k = std::size_t(ps * at_.rows + pt);
    const std::uint8_t state = piece_state_[k];
    if (state == kUnknown) return cut_and_keep_piece(ps, pt);
    return state == kCut ? &piece_[k] : nullptr;
  }

 private:
  enum : std::uint8_t { kUnknown, kEmpty, kCut };
  const ConvexPolygon* cut_and_keep_column(int ps);
  const Moments* cut_and_keep_piece(int ps, int pt);
  // The key: what the geometry is a function of.
  ConvexPolygon uv_;
  int width_ = 0, height_ = 0, order_ = 0;
  LevelPolygon at_;
  std::array<std::uint8_t, kMaxCells> column_state_{};
  std::array<std::uint8_t, kMaxCells> piece_state_{};
  std::array<Moments, kMaxCells> piece_;
  std::array<ConvexPolygon, kMaxCells> column_;
};

/// The cuts of the last few (polygon, level size, order) a thread asked for. Each entry is a
/// pure function of its key, so a hit returns the bits a fresh cut would.
class LevelCutsMemo {
 public:
  /// This thread's memo (built once per thread: 60 KB).
  static LevelCutsMemo& of_this_thread();
  /// The cuts of `uv` on a width x height level for a filter of `order`; the reference stays
  /// valid until the next call on this memo.
  LevelCuts& get(int width, int height, const ConvexPolygon& uv, int order);
  /// Calls of get that found their cuts, and that cut anew.
  long long hits() const { return hits_; }
  long long misses() const { return misses_; }

 private:
  // A fragment asks for two levels per slot (a trilinear blend), the same two for every slot
  // on its UV set and texture size; four entries also hold a second size or filter.
  static constexpr int kEntries = 4;
  std::array<LevelCuts, kEntries> entries_;
  int next_ = 0;  ///< the oldest entry; the newest is just before it
  long long hits_ = 0, misses_ = 0;
};

}  // namespace covrast::detail
