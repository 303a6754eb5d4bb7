// Texture sampling shared by every raster mode (docs/textures.md): wrap modes, nearest and
// bilinear texel filters, the level of detail from exact screen-space UV derivatives, and
// trilinear filtering between mip levels. Everything in double precision, IEEE, no
// contraction, so a texel lookup is the same in every mode, tile and thread.
#pragma once

#include "core/convex_polygon.hpp"

#include <covrast/texture.hpp>

#include <glm/glm.hpp>

#include <optional>

namespace covrast::detail {

class LevelCutsMemo;

/// Texel index `i` (any integer) of a side of `size` texels after the wrap mode:
///   REPEAT           i mod size (non-negative remainder)
///   MIRRORED_REPEAT  k = i mod 2 size; k < size ? k : 2 size - 1 - k
///   CLAMP_TO_EDGE    clamp(i, 0, size - 1)
int wrap_texel(long long i, int size, TextureWrap wrap);

/// The level of detail of one texture at a shading point, OpenGL 4.6 (8.14.1) / glTF's
/// isotropic rule: rho = max(|d(uv)/dx| size, |d(uv)/dy| size) with the texel-space lengths
///   |d(uv)/dx| size = sqrt((du/dx W)^2 + (dv/dx H)^2)   (same for y),
/// lod = log2(rho). -infinity for rho = 0 (a constant mapping: magnification).
double texture_lod(const Texture& texture, const glm::dvec2& duv_dx, const glm::dvec2& duv_dy);

/// The filtered linear RGBA of `texture` at `uv` for level of detail `lod`: lod <= 0 uses the
/// magnification filter on level 0; lod > 0 the minification filter, on level 0 (MipFilter::
/// None), on level round-half-down(lod) clamped to the chain (Nearest, lod - 0.5 rounded up),
/// or linear between floor(lod) and floor(lod) + 1 with weight frac(lod) (Linear). Within a
/// level, texel centres sit at (i + 0.5) / W: Nearest takes texel floor(u W), Linear the
/// bilinear blend of the four texels around u W - 0.5 (wrapped per texel).
glm::dvec4 sample_texture(const Texture& texture, const TextureSampler& sampler,
                          const glm::dvec2& uv, double lod);

/// The mean of `texture` over the polygon `uv` (in UV units) at level of detail `lod`: what
/// sample_texture averages to over the polygon's points. The levels, their filter and their
/// blend are chosen as sample_texture chooses them, and each level is integrated exactly:
///   NEAREST  sum_texels texel x area(polygon n texel) / area(polygon);
///   LINEAR   the bilinear filter integrated over the polygon's part in each cell between
///            four texel centres (its moments 1, a, b, a b), divided by area(polygon);
/// texels wrapped as sample_texture wraps them. Nothing when the polygon has no area or
/// reaches more than 64 texel cells of a level. With a `memo`, the polygon's pieces on each
/// level are cut once for every texture of that size (level_cuts.hpp): the same bits, less
/// work when several textures are averaged over one polygon.
std::optional<glm::dvec4> area_average(const Texture& texture, const TextureSampler& sampler,
                                       const ConvexPolygon& uv, double lod,
                                       LevelCutsMemo* memo = nullptr);

/// Bounds of a filtered alpha: every value lies in [low, high].
struct AlphaRange {
  double low;
  double high;
};

/// Bounds of `texture`'s filtered alpha over the polygon `uv` at level of detail `lod`: the
/// smallest and largest alpha of the texels the lookups read there (each filter, and the
/// blend of two levels, is a convex combination of them). Nothing where area_average would
/// decline.
std::optional<AlphaRange> area_alpha_range(const Texture& texture, const TextureSampler& sampler,
                                           const ConvexPolygon& uv, double lod);

/// KHR_texture_transform applied to a UV: T(offset) R(rotation) S(scale) uv.
glm::dvec2 transform_uv(const TextureTransform& transform, const glm::dvec2& uv);
/// Its linear part applied to a UV derivative: R(rotation) S(scale) d.
glm::dvec2 transform_duv(const TextureTransform& transform, const glm::dvec2& duv);

}  // namespace covrast::detail
