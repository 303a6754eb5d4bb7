// The exact visible areas of a pixel's fragments: visible_parts.hpp gives the method and the
// contract.
#include "raster/coverage/visible_parts.hpp"

#include "core/checks.hpp"
#include "core/convex_polygon.hpp"
#include "raster/coverage/sample_mask.hpp"

#include <algorithm>
#include <cmath>

namespace covrast::detail {
namespace {

/// f(u, v) = c + a u + b v in pixel-local coordinates (u, v in [0, 1] over the pixel);
/// its inside is f >= 0.
struct Line {
  double c, a, b;
  double at(double u, double v) const { return c + a * u + b * v; }
  Line flipped() const { return {-c, -a, -b}; }
};

/// A convex polygon in pixel-local coordinates (x, y in [0, 1] over the pixel). Each cut adds
/// at most one vertex.
using Piece = Polygon<16>;

/// Keeps the part of `in` inside `line` in `out`; false when it would need more vertices than
/// a piece holds.
bool clip(const Piece& in, const Line& line, Piece& out) {
  return clip_polygon(
      in, [&](double u, double v) { return line.at(u, v); }, out);
}

/// Pieces thinner than this are dropped: far below an 8.8 coverage step (1/65280), and it
/// keeps slivers cut off along a shared edge from multiplying the pieces.
constexpr double kNegligibleArea = 1e-13;

/// One fragment, prepared once per pixel.
struct Fragment {
  const TriangleSetup* tri = nullptr;
  Line edge[3];                                   ///< inside its three edges
  Piece part;                                     ///< its part of the pixel square
  double z = 0.0;                                 ///< its plane at the pixel's corner (x, y)
  double u0 = 0.0, v0 = 0.0, u1 = 0.0, v1 = 0.0;  ///< the part's bounding box
};

void prepare(const TriangleSetup& t, int x, int y, Fragment& f) {
  f.tri = &t;
  // Edge i -> k inside (y down, as clip_by_triangle): (xk - xi)(v - vi) - (yk - yi)(u - ui)
  // >= 0, vertices in pixel-local coordinates (exact: 24.8 fixed point less an integer).
  const double s = 1.0 / kSubpixelOne;
  for (int i = 0; i < 3; ++i) {
    const int k = i == 2 ? 0 : i + 1;
    const double ui = t.x_fx8[i] * s - x, vi = t.y_fx8[i] * s - y;
    const double du = t.x_fx8[k] * s - x - ui, dv = t.y_fx8[k] * s - y - vi;
    f.edge[i] = Line{dv * ui - du * vi, -dv, du};
  }
  Piece& part = f.part;
  part.n = 4;
  const double su[4] = {0.0, 1.0, 1.0, 0.0}, sv[4] = {0.0, 0.0, 1.0, 1.0};
  std::copy(su, su + 4, part.x);
  std::copy(sv, sv + 4, part.y);
  Piece cut;
  for (int i = 0; i < 3; ++i) {
    bool all_in = true;
    for (int k = 0; k < part.n && all_in; ++k) all_in = f.edge[i].at(part.x[k], part.y[k]) >= 0.0;
    if (all_in) continue;        // the edge misses what is left
    clip(part, f.edge[i], cut);  // a triangle and a square: at most 7 vertices
    part.assign(cut);
  }
  f.z = t.depth_at(x, y);
  f.u0 = f.v0 = 1.0;
  f.u1 = f.v1 = 0.0;
  for (int i = 0; i < f.part.n; ++i) {
    f.u0 = std::min(f.u0, f.part.x[i]);
    f.u1 = std::max(f.u1, f.part.x[i]);
    f.v0 = std::min(f.v0, f.part.y[i]);
    f.v1 = std::max(f.v1, f.part.y[i]);
  }
}

/// z_i - z_j over the pixel: > 0 where j lies in front of i. Its coefficients are the exact
/// negations of z_j - z_i's, so the two fragments split their overlap along one line.
Line in_front(const Fragment& i, const TriangleSetup& j, double zj) {
  return Line{i.z - zj, i.tri->dzdx - j.dzdx, i.tri->dzdy - j.dzdy};
}

/// The pieces of a fragment's visible part so far.
struct Pieces {
  Piece piece[kMaxVisiblePieces];
  int n = 0;
};

enum class Cut { Unchanged, Removed, Overflow };

/// Cuts `q` by the convex set bounded by `lines` (inside each of them is inside the set):
/// Unchanged when they have no area in common, else the parts of q outside the set are
/// appended to `out` and q is Removed; Overflow when `out` or a piece is full.
Cut cut(const Piece& q, const Line* lines, int m, Pieces& out) {
  bool inside_all = true;
  for (int k = 0; k < m; ++k) {
    bool all_in = true, all_out = true;
    for (int i = 0; i < q.n; ++i) {
      const double f = lines[k].at(q.x[i], q.y[i]);
      all_in = all_in && f >= 0.0;
      all_out = all_out && f <= 0.0;
    }
    if (all_out) return Cut::Unchanged;  // wholly outside one line: no area in common
    inside_all = inside_all && all_in;
  }
  if (inside_all) return Cut::Removed;  // hidden whole
  // What is left inside the lines so far alternates between two pieces; the part outside
  // line k is clipped straight into `out`.
  Piece buffer[2];
  const Piece* rest = &q;
  for (int k = 0; k < m; ++k) {
    if (out.n == kMaxVisiblePieces) return Cut::Overflow;
    Piece& outside = out.piece[out.n];
    if (!clip(*rest, lines[k].flipped(), outside)) return Cut::Overflow;
    if (polygon_area(outside) > kNegligibleArea) ++out.n;
    Piece& inside = buffer[k & 1];
    if (!clip(*rest, lines[k], inside)) return Cut::Overflow;
    rest = &inside;
  }
  return Cut::Removed;  // what is left lies in the set: hidden
}

/// Removes from `pieces` the set bounded by `lines`; false when the pieces overflow. Pieces
/// the set misses stay where they are (the common case: a neighbour across a shared edge).
bool remove_set(Pieces& pieces, const Line* lines, int m) {
  static thread_local Pieces added;
  added.n = 0;
  int kept = 0;
  for (int p = 0; p < pieces.n; ++p) {
    switch (cut(pieces.piece[p], lines, m, added)) {
      case Cut::Unchanged:
        if (kept != p) pieces.piece[kept].assign(pieces.piece[p]);
        ++kept;
        break;
      case Cut::Removed:
        break;
      case Cut::Overflow:
        return false;
    }
  }
  if (kept + added.n > kMaxVisiblePieces) return false;
  for (int a = 0; a < added.n; ++a) pieces.piece[kept++].assign(added.piece[a]);
  pieces.n = kept;
  return true;
}

/// Whether a and b share an edge traversed in opposite directions: same orientation (as
/// every set-up triangle has), so they lie on opposite sides of its line and their interiors
/// are disjoint. The common case of a pixel's pairs: neighbours in a tessellation.
bool across_shared_edge(const TriangleSetup& a, const TriangleSetup& b) {
  for (int i = 0; i < 3; ++i) {
    const int i1 = i == 2 ? 0 : i + 1;
    for (int k = 0; k < 3; ++k) {
      const int k1 = k == 2 ? 0 : k + 1;
      if (a.x_fx8[i] == b.x_fx8[k1] && a.y_fx8[i] == b.y_fx8[k1] && a.x_fx8[i1] == b.x_fx8[k] &&
          a.y_fx8[i1] == b.y_fx8[k]) {
        return true;
      }
    }
  }
  return false;
}

bool boxes_overlap(const Fragment& a, const Fragment& b) {
  return a.u0 < b.u1 && b.u0 < a.u1 && a.v0 < b.v1 && b.v0 < a.v1;
}

/// Whether plane difference `d` (z_i - z_j) leaves i in front of j all over the pixel
/// (j nowhere strictly in front): d <= 0 at the four corners.
bool never_in_front(const Line& d) {
  return d.at(0, 0) <= 0.0 && d.at(1, 0) <= 0.0 && d.at(0, 1) <= 0.0 && d.at(1, 1) <= 0.0;
}

/// Whether `d` is the zero plane (the two planes are the same).
bool same_plane(const Line& d) { return d.c == 0.0 && d.a == 0.0 && d.b == 0.0; }

/// Whether t's plane is finite over pixel (x, y): its slopes and its depth at the corner.
bool finite_plane(const TriangleSetup& t, int x, int y) {
  return std::isfinite(t.dzdx) && std::isfinite(t.dzdy) && std::isfinite(t.depth_at(x, y));
}

/// One pixel's fragments, prepared, and the order the walk takes them in.
struct PixelFragments {
  int n = 0;
  Fragment f[kMaxVisibleFragments];
  int order[kMaxVisibleFragments];    ///< indices into f, nearest first
  double near[kMaxVisibleFragments];  ///< the nearest depth over the pixel, in `order`
  double far[kMaxVisibleFragments];   ///< the farthest depth over the pixel, by index
  bool done[kMaxVisibleFragments];    ///< whether its visible area is known, by index
  const TriangleSetup* opaque = nullptr;
  double opaque_z = 0.0;  ///< the opaque plane at the pixel's corner
};

/// Fragment i's visible part: its pieces less the opaque surface and every fragment of
/// `order` (nearest first) that may lie in front of it and is not known to be hidden.
bool visible_area_of(const PixelFragments& px, const double* area, int i, Pieces& pieces,
                     double& visible) {
  const Fragment* f = px.f;
  const TriangleSetup* opaque = px.opaque;
  const TriangleSetup& ti = *f[i].tri;
  pieces.n = 0;
  if (polygon_area(f[i].part) > kNegligibleArea) pieces.piece[pieces.n++].assign(f[i].part);
  if (opaque != nullptr && pieces.n != 0) {
    const Line d = in_front(f[i], *opaque, px.opaque_z);
    const bool hidden_by_tie = same_plane(d) && opaque->primitive < ti.primitive;
    if (hidden_by_tie) pieces.n = 0;
    if (!hidden_by_tie && !never_in_front(d) && !remove_set(pieces, &d, 1)) return false;
  }
  // A point of i that some fragment hides is hidden by the nearest fragment there, which is
  // visible: fragments already found hidden need not be subtracted. Nearest first, so the
  // walk ends at the first fragment that starts behind i's farthest point.
  for (int k = 0; k < px.n && pieces.n != 0 && px.near[k] <= px.far[i]; ++k) {
    const int j = px.order[k];
    if (j == i || (px.done[j] && area[j] == 0.0) || !boxes_overlap(f[i], f[j])) continue;
    const TriangleSetup& tj = *f[j].tri;
    if (across_shared_edge(ti, tj)) continue;
    Line set[4] = {f[j].edge[0], f[j].edge[1], f[j].edge[2], in_front(f[i], tj, f[j].z)};
    int m = 4;
    if (same_plane(set[3])) {
      if (tj.primitive > ti.primitive) continue;  // level: the earlier shows
      m = 3;
    } else if (never_in_front(set[3])) {
      continue;
    }
    if (!remove_set(pieces, set, m)) return false;
  }
  visible = 0.0;
  for (int p = 0; p < pieces.n; ++p) visible += polygon_area(pieces.piece[p]);
  return true;
}

}  // namespace

bool visible_areas(int n, const TriangleSetup* const* tri, const TriangleSetup* opaque, int x,
                   int y, double* area) {
  COVRAST_CHECK(n <= kMaxVisibleFragments, "visible_areas takes at most its limit");
  static thread_local PixelFragments px;
  static thread_local Pieces pieces;
  double near_of[kMaxVisibleFragments];
  // A plane that is not finite (set-up of a degenerate triangle far out in the guard band)
  // orders nothing: the samples decide, as they do for every comparison with it.
  if (opaque != nullptr && !finite_plane(*opaque, x, y)) return false;
  px.n = n;
  for (int i = 0; i < n; ++i) {
    if (!finite_plane(*tri[i], x, y)) return false;
    prepare(*tri[i], x, y, px.f[i]);
    const Line z{px.f[i].z, tri[i]->dzdx, tri[i]->dzdy};
    const double c[4] = {z.at(0, 0), z.at(1, 0), z.at(0, 1), z.at(1, 1)};
    near_of[i] = std::min(std::min(c[0], c[1]), std::min(c[2], c[3]));
    px.far[i] = std::max(std::max(c[0], c[1]), std::max(c[2], c[3]));
    if (!std::isfinite(near_of[i]) || !std::isfinite(px.far[i])) return false;
    px.order[i] = i;
    px.done[i] = false;
    area[i] = 0.0;
  }
  // Nearest first; equal nearest depth in primitive order, so the order is a function of
  // the fragments alone.
  std::sort(px.order, px.order + n, [&](int a, int b) {
    if (near_of[a] != near_of[b]) return near_of[a] < near_of[b];
    return tri[a]->primitive < tri[b]->primitive;
  });
  for (int k = 0; k < n; ++k) px.near[k] = near_of[px.order[k]];
  px.opaque = opaque;
  px.opaque_z = opaque != nullptr ? opaque->depth_at(x, y) : 0.0;
  // Once the visible parts found fill the pixel, the fragments after them are hidden.
  constexpr double kFilled = 1.0 - 1e-9;
  double covered = 0.0;
  for (int k = 0; k < n && covered < kFilled; ++k) {
    const int i = px.order[k];
    if (!visible_area_of(px, area, i, pieces, area[i])) return false;
    px.done[i] = true;
    covered += area[i];
    COVRAST_CHECK(area[i] <= polygon_area(px.f[i].part) * (1.0 + 1e-9) + 1e-12,
                  "a visible part lies inside the fragment's part of the pixel");
  }
  COVRAST_CHECK(covered <= 1.0 + 1e-9, "the visible parts are disjoint: they fit in the pixel");
  return true;
}

}  // namespace covrast::detail
