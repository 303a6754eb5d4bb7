// Coverage mode's shading of a fragment of a textured surface (fragment_shading.hpp).
#include "raster/coverage/fragment_shading.hpp"

#include "core/checks.hpp"
#include "core/convex_polygon.hpp"

#include <algorithm>
#include <cmath>

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

/// Bounds of a MASK triangle's alpha (base x vertex x texture) over the fragment: the
/// vertex alpha, a convex combination of the corners', between their extremes.
AlphaRange surface_alpha_range(const TriangleSetup& t, const double mu[3],
                               const FragmentFootprint& footprint) {
  const ShadingRecord& r = *t.shading;
  const auto [v_low, v_high] =
      std::minmax({r.vertex_alpha[0], r.vertex_alpha[1], r.vertex_alpha[2]});
  const AlphaRange texture = base_color_texture_alpha_range(t, mu[0], mu[1], mu[2], footprint);
  AlphaRange range{HUGE_VAL, -HUGE_VAL};
  for (const double v : {double(v_low), double(v_high)}) {
    for (const double a : {texture.low, texture.high}) {
      const double product = r.surface->base_alpha * v * a;
      range.low = std::min(range.low, product);
      range.high = std::max(range.high, product);
    }
  }
  return range;
}

/// The mean of the point shadings at up to kVisibleShadingPoints of the `count` samples of
/// `set`, the ones at positions (j + 1/2) count / picks in its sample order.
glm::dvec3 sampled_shading(const TriangleSetup& t, int x, int y, const SampleMask& set, int count) {
  const int picks = std::min(count, kVisibleShadingPoints);
  glm::dvec3 sum(0.0);
  int index = 0, picked = 0;
  int next = count / (2 * picks);  // (0 + 1/2) count / picks, rounded down
  for_each_sample(set, [&](int k) {
    if (picked < picks && index == next) {
      sum += glm::dvec3(
          shade(t, x + kSampleOffsetX[std::size_t(k)], y + kSampleOffsetY[std::size_t(k)], true));
      ++picked;
      next = (2 * picked + 1) * count / (2 * picks);
    }
    ++index;
  });
  return sum / double(picks);
}

}  // namespace

MaskVerdict mask_verdict(const TriangleSetup& t, int x, int y) {
  if (t.alpha_mode != AlphaMode::Mask) return MaskVerdict::Keep;
  const double cutoff = t.shading->surface->alpha_cutoff;
  double mu[3];
  perspective_weights(t, x + 0.5, y + 0.5, true, mu);
  const FragmentFootprint footprint = footprint_of(t, x, y);
  if (footprint.vertex_count < 3) {  // a sliver: the clamped centre's verdict
    return surface_alpha(t, mu[0], mu[1], mu[2]) >= cutoff ? MaskVerdict::Keep : MaskVerdict::Drop;
  }
  const AlphaRange range = surface_alpha_range(t, mu, footprint);
  if (range.low >= cutoff) return MaskVerdict::Keep;
  if (range.high < cutoff) return MaskVerdict::Drop;
  return MaskVerdict::Straddles;
}

MaskShare mask_share(const TriangleSetup& t, int x, int y) {
  const double cutoff = t.shading->surface->alpha_cutoff;
  MaskShare share;
  int inside = 0, passing = 0;
  double sum_x = 0.0, sum_y = 0.0;
  glm::dvec4 sum_texel(0.0);
  for (int j = 0; j < kMaskGrid; ++j) {
    for (int i = 0; i < kMaskGrid; ++i) {
      const double px = x + (i + 0.5) / kMaskGrid, py = y + (j + 0.5) / kMaskGrid;
      double m[3];
      // Unclamped weights are all >= 0 exactly where the point is in the triangle.
      if (!perspective_weights(t, px, py, false, m) || m[0] < 0.0 || m[1] < 0.0 || m[2] < 0.0) {
        continue;
      }
      ++inside;
      const glm::dvec4 texel = base_color_texel(t, m[0], m[1], m[2]);
      if (surface_alpha_with(t, m[0], m[1], m[2], texel.a) < cutoff) continue;
      ++passing;
      sum_x += px;
      sum_y += py;
      sum_texel += texel;
    }
  }
  if (passing > 0) {
    share.share = double(passing) / double(inside);
    share.x_px = sum_x / passing;
    share.y_px = sum_y / passing;
    share.base_color = sum_texel / double(passing);
  } else if (inside == 0) {  // no point in the triangle: the clamped centre's verdict
    double mu[3];
    perspective_weights(t, x + 0.5, y + 0.5, true, mu);
    share.share = surface_alpha(t, mu[0], mu[1], mu[2]) >= cutoff ? 1.0 : 0.0;
  }
  return share;
}

ShadedColor shade_fragment_rgba(const TriangleSetup& t, int x, int y) {
  if (t.alpha_mode == AlphaMode::Mask && mask_verdict(t, x, y) == MaskVerdict::Straddles) {
    const MaskShare share = mask_share(t, x, y);
    double mu[3];
    if (share.share > 0.0 && share.share < 1.0 &&
        perspective_weights(t, share.x_px, share.y_px, true, mu)) {
      // Shaded at the passing points' centroid with their mean base colour texel; the other
      // textures averaged over the fragment.
      FragmentFootprint footprint = footprint_of(t, x, y);
      footprint.has_base_color = true;
      footprint.base_color = share.base_color;
      return {shade_lit(t, mu[0], mu[1], mu[2], &footprint), share.share};
    }
    return {shade_fragment(t, x, y), share.share};
  }
  if (transmits(t)) {
    // shade_fragment's shading with the filter: the textures averaged over the fragment.
    double mu[3];
    perspective_weights(t, x + 0.5, y + 0.5, true, mu);
    ShadedColor out{glm::vec3(0.0f), surface_alpha(t, mu[0], mu[1], mu[2])};
    if (textured(t)) {
      const FragmentFootprint footprint = footprint_of(t, x, y);
      out.rgb = shade_lit(t, mu[0], mu[1], mu[2], &footprint, &out.filter);
    } else {
      out.rgb = shade_lit(t, mu[0], mu[1], mu[2], nullptr, &out.filter);
    }
    out.transmissive = true;
    return out;
  }
  const glm::vec3 rgb = shade_fragment(t, x, y);
  if (t.alpha_mode != AlphaMode::Blend) return {rgb, 1.0};
  double mu[3];
  perspective_weights(t, x + 0.5, y + 0.5, true, mu);
  return {rgb, surface_alpha(t, mu[0], mu[1], mu[2])};
}

glm::vec3 shade_fragment_visible(const TriangleSetup& t, int x, int y, const SampleMask& own,
                                 const SampleMask& kept) {
  const int own_count = own.count(), kept_count = kept.count();
  COVRAST_CHECK(kept_count > 0 && kept_count < own_count && (kept & own) == kept,
                "a partly shown fragment keeps some, not all, of its own samples");
  const SampleMask lost = own.without(kept);
  const glm::dvec3 shown_side = sampled_shading(t, x, y, kept, kept_count);
  const glm::dvec3 hidden_side = sampled_shading(t, x, y, lost, own_count - kept_count);
  const double hidden_share = double(own_count - kept_count) / own_count;
  const glm::dvec3 visible =
      glm::dvec3(shade_fragment(t, x, y)) + hidden_share * (shown_side - hidden_side);
  return glm::vec3(glm::max(visible, glm::dvec3(0.0)));
}

glm::vec3 shade_fragment_averaged(const TriangleSetup& t, int x, int y) {
  double mu[3];
  if (!perspective_weights(t, x + 0.5, y + 0.5, true, mu)) return shade(t, x + 0.5, y + 0.5, true);
  const FragmentFootprint footprint = footprint_of(t, x, y);
  return shade_lit(t, mu[0], mu[1], mu[2], &footprint);
}

}  // namespace covrast::detail
