// Coverage mode's shading of a fragment of a textured surface (fragment_shading.hpp).
#include "raster/coverage/fragment_shading.hpp"

#include "core/convex_polygon.hpp"

namespace covrast::detail {

namespace {

/// Pixel (x, y) and the triangle's part of it, as the weights of the part's vertices (none
/// when the part has no area: a fragment of rounding's worth).
FragmentFootprint footprint_of(const TriangleSetup& t, int x, int y) {
  FragmentFootprint footprint;
  footprint.x = x;
  footprint.y = y;
  // Most fragments cover their pixel: the part is the pixel, its corners' unclamped weights
  // all >= 0, and there is nothing to clip.
  static constexpr double kCorner[4][2] = {{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}};
  bool whole = true;
  for (int i = 0; i < 4 && whole; ++i) {
    double* mu = footprint.vertex_mu[i];
    whole = perspective_weights(t, x + kCorner[i][0], y + kCorner[i][1], false, mu) &&
            mu[0] >= 0.0 && mu[1] >= 0.0 && mu[2] >= 0.0;
  }
  if (whole) {
    footprint.vertex_count = 4;
    return footprint;
  }
  // Relative to the pixel's corner: small numbers, so the clip keeps its bits.
  ConvexPolygon triangle;
  for (int k = 0; k < 3; ++k) {
    triangle.add(t.x_fx8[k] * (1.0 / kSubpixelOne) - x, t.y_fx8[k] * (1.0 / kSubpixelOne) - y);
  }
  const ConvexPolygon part = clip_to_box(triangle, 0.0, 0.0, 1.0, 1.0);
  if (part.n < 3 || part.n > FragmentFootprint::kMaxVertices || !(polygon_area(part) > 1e-12)) {
    return footprint;
  }
  for (int i = 0; i < part.n; ++i) {
    // Clamped: the clip's vertices lie on the triangle up to rounding.
    if (!perspective_weights(t, x + part.x[i], y + part.y[i], true, footprint.vertex_mu[i])) {
      return footprint;
    }
  }
  footprint.vertex_count = part.n;
  return footprint;
}

}  // namespace

glm::vec3 shade_fragment_averaged(const TriangleSetup& t, int x, int y) {
  double mu[3];
  if (!perspective_weights(t, x + 0.5, y + 0.5, true, mu)) return shade(t, x + 0.5, y + 0.5, true);
  const FragmentFootprint footprint = footprint_of(t, x, y);
  return shade_lit(t, mu[0], mu[1], mu[2], &footprint);
}

}  // namespace covrast::detail
