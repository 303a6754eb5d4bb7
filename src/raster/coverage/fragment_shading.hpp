// How coverage mode shades a fragment (one triangle in one pixel): once, at the pixel centre
// clamped into the triangle, as msaa does, except for textures, which are averaged over the
// fragment's part of the pixel.
//
// Why the exception: shading once stands in for the pixel's average when what is shaded
// varies slowly across the pixel. A texture looked up at its level of detail does not: its
// texels are about as wide as the pixel. NEAREST is piecewise constant in them, so the
// pixel's average can be any blend of two texels while one lookup gives one of them; LINEAR
// bends at every texel centre, so its value at the pixel centre misses the pixel's mean
// wherever a texel stands out from its neighbours. The reference and ssaa, which shade every
// sample, average them. One lookup put a pixel of the Duck's eye ring (NEAREST_MIPMAP_LINEAR)
// 75/255 from the reference and a dot of NegativeScaleTest's label (LINEAR) 76/255, where
// 256-sample supersampling was 29/255 and 10/255 off at worst.
#pragma once

#include "raster/coverage/sample_mask.hpp"
#include "shading/shading.hpp"
#include "shading/shading_inputs.hpp"

namespace covrast::detail {

/// The shading of a fragment of a textured surface: the clamped centre's weights for
/// everything else, and for each texture its exact mean over the triangle's part of the pixel
/// mapped into the texture, at the centre's level of detail (texture/texture_sampling.hpp
/// area_average; the reference's and ssaa's samples use the level of the pixel's footprint
/// too). Where that declines (a part over more than 64 texels of a level), the
/// mean of the lookups at the points of a 4x4 grid of the pixel ((i + 1/2) / 4, as ssaa:4
/// places its samples) that lie in the triangle; with none of them in it, the centre's
/// lookup. Out of line: it is the slow path.
glm::vec3 shade_fragment_averaged(const TriangleSetup& t, int x, int y);

/// Whether a MASK triangle keeps its fragment in pixel (x, y) (any other keeps it): Keep or
/// Drop where its alpha over the fragment is surely on one side of the cutoff (bounds from
/// the texels the base colour's lookups read there, the vertex alphas and the factor; for a
/// fragment without area, the clamped centre's alpha), Straddles otherwise.
enum class MaskVerdict { Keep, Drop, Straddles };
MaskVerdict mask_verdict(const TriangleSetup& t, int x, int y);

/// The points per side of the grid at which mask_share tests the alpha of a fragment that
/// straddles the cutoff: 16 x 16, ssaa:16's samples.
constexpr int kMaskGrid = 8;

/// The share of a MASK fragment's part of the pixel where the alpha passes: of the points of
/// a kMaskGrid x kMaskGrid grid of pixel (x, y) ((i + 1/2) / kMaskGrid) in the triangle, those
/// where the alpha, looked up there as the reference and ssaa look it up, passes; and their
/// centroid. With none of them in the triangle (a sliver), the clamped centre's verdict. The
/// reference tests every one of its samples; one verdict per fragment (msaa, coverage-blend)
/// cuts texture-driven edges a pixel at a time.
struct MaskShare {
  double share = 0.0;
  double x_px = 0.0, y_px = 0.0;  ///< the passing points' centroid (share > 0)
  glm::dvec4 base_color{1.0};     ///< their mean base colour texel (share > 0)
};
MaskShare mask_share(const TriangleSetup& t, int x, int y);

/// The colour and alpha coverage mode gives the fragment of a MASK or BLEND triangle (the
/// A-buffer's transparent list holds both). BLEND: the colour of shade_fragment, the surface
/// alpha at the clamped centre. MASK: where it straddles the cutoff, mask_share's share as
/// alpha, and the shading at its centroid with its mean base colour texel; else opaque. A
/// transmissive surface's fragment (a BLEND layer) carries its filter too.
ShadedColor shade_fragment_rgba(const TriangleSetup& t, int x, int y);

/// Kept and lost samples at which shade_fragment_visible shades, at most, each.
inline constexpr int kVisibleShadingPoints = 4;
/// The least share of the pixel [pixels] a textured fragment's hidden samples must stand for
/// (its weight in the pixel times lost / own) for the resolve to move its colour towards what
/// shows: below it the move is under 1% of the difference between the two sides.
inline constexpr double kVisibleShadingMinShare = 0.01;

/// Whether `t` has texture slots: its coverage shading averages them (shade_fragment).
inline bool textured(const TriangleSetup& t) {
  return t.shading != nullptr && t.shading->surface->texture_slot_count > 0;
}

/// Whether the resolve gives fragment `t` shade_fragment_visible's colour: it is textured, it
/// keeps `kept_count` of its `own_count` samples (some, not all), and the lost ones stand for
/// at least kVisibleShadingMinShare of the pixel at its weight `weight` [pixels].
inline bool shows_side(const TriangleSetup& t, double weight, int own_count, int kept_count) {
  return textured(t) && kept_count > 0 && kept_count < own_count &&
         weight * double(own_count - kept_count) / own_count >= kVisibleShadingMinShare;
}

/// The colour of a textured fragment of which a nearer one hides some samples: shade_fragment
/// over its whole part, moved towards its shown side. With W the mean over the part and V, H
/// the means over the shown and the hidden side, in proportions k and h of its samples (k + h
/// = 1), W = k V + h H, so
///   V = W + h (V - H),
/// and V - H is estimated from the point shadings (as the reference shades its samples) at up
/// to kVisibleShadingPoints of the `kept` samples and as many of the lost ones (`own` without
/// `kept`), evenly spaced in sample order; clamped at 0. Exact where the shading is constant
/// on each side; W, not a mean of points, carries the texture's exact average. Without it a
/// partly hidden fragment shows the texture of its hidden side too: the helmet's visor rim
/// over a dark band, the Duck's eye ring (docs/coverage.md, section 3).
/// Requires 0 < count(kept) < count(own), kept within own.
glm::vec3 shade_fragment_visible(const TriangleSetup& t, int x, int y, const SampleMask& own,
                                 const SampleMask& kept);

/// The colour coverage mode gives the fragment of `t` in pixel (x, y).
inline glm::vec3 shade_fragment(const TriangleSetup& t, int x, int y) {
  if (textured(t)) return shade_fragment_averaged(t, x, y);
  return shade(t, x + 0.5, y + 0.5, true);
}

}  // namespace covrast::detail
