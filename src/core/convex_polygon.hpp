// Convex polygons clipped to boxes, and their areas: the part of a triangle in a pixel
// (coverage mode's texture footprint, raster/coverage/fragment_shading.cpp) and the part of
// that footprint in each texel (texture/texture.cpp). Sutherland and Hodgman, "Reentrant polygon
// clipping" (CACM 17(1), 1974), one half-plane at a time; the area by the shoelace formula.
#pragma once

#include <cmath>

namespace covrast::detail {

struct ConvexPolygon {
  /// A half-plane adds at most one vertex to a convex polygon: a triangle clipped to a box has
  /// at most 7, and such a polygon clipped to another box at most 11.
  static constexpr int kMaxVertices = 12;
  double x[kMaxVertices];
  double y[kMaxVertices];
  int n = 0;

  void add(double px, double py) {
    if (n == kMaxVertices) return;  // only for input that is not convex (NaN coordinates)
    x[n] = px;
    y[n] = py;
    ++n;
  }
};

/// The part of `in` where a x + b y + c >= 0.
inline ConvexPolygon clip_half_plane(const ConvexPolygon& in, double a, double b, double c) {
  ConvexPolygon out;
  for (int i = 0; i < in.n; ++i) {
    const int j = i + 1 == in.n ? 0 : i + 1;
    const double fi = a * in.x[i] + b * in.y[i] + c;
    const double fj = a * in.x[j] + b * in.y[j] + c;
    if (fi >= 0.0) out.add(in.x[i], in.y[i]);
    if ((fi >= 0.0) != (fj >= 0.0)) {  // the side crosses the line: its crossing
      const double s = fi / (fi - fj);
      out.add(in.x[i] + s * (in.x[j] - in.x[i]), in.y[i] + s * (in.y[j] - in.y[i]));
    }
  }
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

/// The area of `p`, either orientation: |sum_i (x_i y_j - x_j y_i)| / 2, j = i + 1.
inline double polygon_area(const ConvexPolygon& p) {
  double twice = 0.0;
  for (int i = 0; i < p.n; ++i) {
    const int j = i + 1 == p.n ? 0 : i + 1;
    twice += p.x[i] * p.y[j] - p.x[j] * p.y[i];
  }
  return std::fabs(twice) * 0.5;
}

}  // namespace covrast::detail
