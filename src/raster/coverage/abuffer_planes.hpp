// Raster stage, coverage mode: a triangle's depth plane and its part of one pixel, as the
// A-buffer's insertion and resolve (abuffer*.cpp) both evaluate them. Every function here
// computes its numbers from the same operations wherever it is called (no contraction:
// -ffp-contract=off), so that two comparisons of one plane never see different bits.
#pragma once

#include "core/convex_polygon.hpp"
#include "core/triangle_setup.hpp"
#include "raster/coverage/sample_mask.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

namespace covrast::detail {

/// Window depth of a triangle's plane at the four corners of pixel (x, y), always from the
/// same operations so that every comparison below sees the same numbers.
struct CornerDepths {
  double z[4];
  double min() const { return std::min(std::min(z[0], z[1]), std::min(z[2], z[3])); }
  double max() const { return std::max(std::max(z[0], z[1]), std::max(z[2], z[3])); }
};

inline CornerDepths corner_depths(const TriangleSetup& t, int x, int y) {
  const double z = t.depth_at(x, y);
  return {{z, z + t.dzdx, z + t.dzdy, (z + t.dzdx) + t.dzdy}};
}

struct DepthRange {
  double min;
  double max;
};
inline constexpr double kFar = std::numeric_limits<double>::infinity();

inline DepthRange depth_range(const TriangleSetup& t, int x, int y) {
  CornerDepths c = corner_depths(t, x, y);
  return {c.min(), c.max()};
}

/// A triangle's depth over a pixel from its depth at the pixel centre: z(centre) -+
/// (|dz/dx| + |dz/dy|) / 2.
inline DepthRange range_around(const TriangleSetup& t, double centre_z) {
  const double reach = 0.5 * (std::fabs(t.dzdx) + std::fabs(t.dzdy));
  return DepthRange{centre_z - reach, centre_z + reach};
}

/// Whether `far` is behind `near` all over pixel (x, y): farther or level at its four corners
/// (the planes are affine), and not the same plane drawn earlier (equal depth keeps the
/// earlier triangle, as the samples do).
inline bool behind_all_over(const TriangleSetup& far, const TriangleSetup& near, int x, int y) {
  const CornerDepths f = corner_depths(far, x, y), n = corner_depths(near, x, y);
  int level = 0;
  for (int k = 0; k < 4; ++k) {
    if (f.z[k] < n.z[k]) return false;
    level += f.z[k] == n.z[k];
  }
  return level < 4 || near.primitive < far.primitive;
}

/// A convex polygon in pixel coordinates: the pixel square clipped by up to six lines (each
/// line adds at most one vertex).
using ClipPolygon = Polygon<10>;

/// Keeps the part of `poly` where the affine function f(x, y) = c + a x + b y is >= 0.
inline void clip_to_line(ClipPolygon& poly, double c, double a, double b) {
  ClipPolygon out;
  clip_polygon(
      poly, [&](double px, double py) { return c + a * px + b * py; }, out);
  poly = out;
}

/// Keeps the part of `poly` inside triangle `t` (its three edges).
inline void clip_by_triangle(ClipPolygon& poly, const TriangleSetup& t) {
  // Inside edge i -> j (positive doubled area, y down):
  // (xj - xi)(py - yi) - (yj - yi)(px - xi) >= 0.
  const double s = 1.0 / kSubpixelOne;
  for (int i = 0; i < 3 && poly.n > 0; ++i) {
    const int j = (i + 1) % 3;
    const double xi = t.x_fx8[i] * s, yi = t.y_fx8[i] * s;
    const double dx = t.x_fx8[j] * s - xi, dy = t.y_fx8[j] * s - yi;
    clip_to_line(poly, dy * xi - dx * yi, -dy, dx);
  }
}

/// The part of pixel (x, y) inside triangle `t`: the pixel square clipped by its three edges.
inline ClipPolygon part_in_pixel(const TriangleSetup& t, int x, int y) {
  ClipPolygon poly;
  const double px[4] = {double(x), double(x + 1), double(x + 1), double(x)};
  const double py[4] = {double(y), double(y), double(y + 1), double(y + 1)};
  for (int k = 0; k < 4; ++k) {
    poly.x[k] = px[k];
    poly.y[k] = py[k];
  }
  poly.n = 4;
  clip_by_triangle(poly, t);
  return poly;
}

/// The vertex average of a convex polygon (a point inside it) [pixels]; false when empty.
inline bool inner_point(const ClipPolygon& poly, double& px, double& py) {
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

/// Whether point (px, py) [pixels] lies in `t`, edges included, in double from the snapped
/// vertices: the one-point visibility test of fragments too thin to own a sample.
inline bool covers_point(const TriangleSetup& t, double px, double py) {
  const double s = 1.0 / kSubpixelOne;
  for (int i = 0; i < 3; ++i) {
    const int j = i == 2 ? 0 : i + 1;
    const double xi = t.x_fx8[i] * s, yi = t.y_fx8[i] * s;
    if ((t.x_fx8[j] * s - xi) * (py - yi) - (t.y_fx8[j] * s - yi) * (px - xi) < 0.0) return false;
  }
  return true;
}

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

/// Whether fragment i is the nearest at point p of its part of the pixel among the fragments
/// that cover p (nearer, or level and earlier, than each). Samples cannot tell it for a
/// fragment too thin to own one: two such slivers folded over one another along a shared
/// edge own the same (no) samples and each would show.
template <class Merged>
bool nearest_at_point(int n, const TriangleSetup* const* tri, const Merged* const* merged, int i,
                      double px, double py) {
  const double z = tri[i]->depth_at(px, py);
  // Nearer first: the depth is two products, the cover test three edge functions, and in
  // a mixed pixel most fragments lie behind the sliver.
  auto hides = [&](const TriangleSetup& o) {
    const double oz = o.depth_at(px, py);
    if (!(oz < z || (oz == z && o.primitive < tri[i]->primitive))) return false;
    return covers_point(o, px, py);
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

}  // namespace covrast::detail
