// Convex polygons cut by half-planes, and their areas: the one clipping loop of the coverage
// mode's geometry.
//  - the part of a triangle in a pixel (the A-buffer's planes, raster/coverage/abuffer_planes.hpp,
//    and the texture footprint, raster/coverage/fragment_shading.cpp);
//  - the exact visible parts of a pixel's fragments (raster/coverage/visible_parts.cpp);
//  - the part of a texture footprint on each texel's kink lines (texture/level_cuts.hpp).
// Sutherland and Hodgman, "Reentrant polygon clipping" (CACM 17(1), 1974), one half-plane at a
// time; the area by the shoelace formula.
//
// Each caller evaluates its affine function in its own fixed order of operations (for example
// a x + b y + c, or c + a x + b y): that order is part of its numeric contract (the bytes of
// its images), so clip_polygon takes the function, not its coefficients.
#pragma once

#include <cmath>

namespace covrast::detail {

/// A convex polygon of at most kCapacity vertices. A half-plane adds at most one vertex to a
/// convex polygon, so a caller sizes it from the number of cuts it makes.
template <int kCapacity>
struct Polygon {
  static constexpr int kMaxVertices = kCapacity;
  double x[kCapacity];
  double y[kCapacity];
  int n = 0;

  /// Appends (px, py); false, and nothing appended, when the polygon is full (input that is
  /// not convex, such as NaN coordinates, or more cuts than the capacity was sized for).
  bool add(double px, double py) {
    if (n == kCapacity) return false;
    x[n] = px;
    y[n] = py;
    ++n;
    return true;
  }

  /// Copies the vertices of `src` in use (not the whole arrays).
  template <int kOther>
  void assign(const Polygon<kOther>& src) {
    n = 0;
    for (int i = 0; i < src.n; ++i) add(src.x[i], src.y[i]);
  }
};

/// out = the part of `in` where f(x, y) >= 0, f affine. False when `out` is full first: it
/// then holds the vertices that fit, in order.
template <int kIn, int kOut, class Affine>
bool clip_polygon(const Polygon<kIn>& in, const Affine& f, Polygon<kOut>& out) {
  out.n = 0;
  double value[kIn];  // f at each vertex, once: each side reads its two ends
  for (int i = 0; i < in.n; ++i) value[i] = f(in.x[i], in.y[i]);
  for (int i = 0; i < in.n; ++i) {
    const int j = i + 1 == in.n ? 0 : i + 1;
    const double fi = value[i];
    const double fj = value[j];
    if (fi >= 0.0 && !out.add(in.x[i], in.y[i])) return false;
    if ((fi >= 0.0) != (fj >= 0.0)) {  // the side crosses the line: its crossing
      const double s = fi / (fi - fj);
      if (!out.add(in.x[i] + s * (in.x[j] - in.x[i]), in.y[i] + s * (in.y[j] - in.y[i]))) {
        return false;
      }
    }
  }
  return true;
}

/// The area of `p`, either orientation: |sum_i (x_i y_j - x_j y_i)| / 2, j = i + 1.
template <int kCapacity>
double polygon_area(const Polygon<kCapacity>& p) {
  double twice = 0.0;
  for (int i = 0; i < p.n; ++i) {
    const int j = i + 1 == p.n ? 0 : i + 1;
    twice += p.x[i] * p.y[j] - p.x[j] * p.y[i];
  }
  return std::fabs(twice) * 0.5;
}

/// The texture footprint's polygon: a triangle clipped to a box has at most 7 vertices, and
/// such a polygon clipped to another box at most 11.
using ConvexPolygon = Polygon<12>;

/// out = the part of `in` where a x + b y + c >= 0.
inline void clip_half_plane(const ConvexPolygon& in, double a, double b, double c,
                            ConvexPolygon& out) {
  clip_polygon(
      in, [&](double px, double py) { return a * px + b * py + c; }, out);
}

/// The part of `in` where a x + b y + c >= 0.
inline ConvexPolygon clip_half_plane(const ConvexPolygon& in, double a, double b, double c) {
  ConvexPolygon out;
  clip_half_plane(in, a, b, c, out);
  return out;
}

/// The part of `in` in the box [x0, x1] x [y0, y1].
inline ConvexPolygon clip_to_box(const ConvexPolygon& in, double x0, double y0, double x1,
                                 double y1) {
  ConvexPolygon p = clip_half_plane(in, 1.0, 0.0, -x0);
  p = clip_half_plane(p, -1.0, 0.0, x1);
  p = clip_half_plane(p, 0.0, 1.0, -y0);
  return clip_half_plane(p, 0.0, -1.0, y1);
}

}  // namespace covrast::detail
