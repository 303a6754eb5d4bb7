// How coverage mode shades a fragment (one triangle in one pixel): once, at the pixel centre
// clamped into the triangle, as msaa does, except for textures filtered NEAREST within a mip
// level, which are averaged over the fragment's part of the pixel.
//
// Why the exception: shading once stands in for the pixel's average when what is shaded
// varies smoothly across the pixel, and filtered textures do (their level of detail matches
// the pixel's footprint). A NEAREST-filtered texture is piecewise constant in texels that
// can be as wide as the pixel, so the pixel's average can be any blend of two texels while
// one lookup gives one of them. The reference and ssaa, which shade every sample, average
// them. On the Duck (glTF sample, NEAREST_MIPMAP_LINEAR) one lookup put a pixel of the eye
// ring 75/255 from the reference, where 256-sample supersampling was 29/255 off at worst.
#pragma once

#include "core/shading.hpp"
#include "core/shading_inputs.hpp"

namespace covrast::detail {

/// The shading of a fragment whose surface has a NEAREST-filtered texture: the clamped
/// centre's weights for everything else, and for those textures their exact average over the
/// triangle's part of the pixel at the centre's level of detail (the texels weighted by
/// their overlap areas with that part mapped into the texture, core/texture_sampling.hpp
/// nearest_area_average; the reference's and ssaa's samples use the level of the pixel's
/// footprint too). Where that declines (a part over more than 64 texels of a level), the
/// mean of the lookups at the points of a 4x4 grid of the pixel ((i + 1/2) / 4, as ssaa:4
/// places its samples) that lie in the triangle; with none of them in it, the centre's
/// lookup. Out of line: it is the slow path.
glm::vec3 shade_fragment_averaged(const TriangleSetup& t, int x, int y);

/// The colour coverage mode gives the fragment of `t` in pixel (x, y).
inline glm::vec3 shade_fragment(const TriangleSetup& t, int x, int y) {
  if (t.shading != nullptr && t.shading->textured != nullptr &&
      t.shading->surface->textures->nearest_filtered) {
    return shade_fragment_averaged(t, x, y);
  }
  return shade(t, x + 0.5, y + 0.5, true);
}

}  // namespace covrast::detail
