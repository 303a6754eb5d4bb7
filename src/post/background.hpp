// Post: the transparent and skybox backgrounds, from two renders of one frame.
//
// Every mode composites a pixel's surfaces over a uniform background colour B, and what it
// writes is linear in B: L = S + w B, with S what the surfaces leave (their weighted,
// tone-mapped colours) and w the share of the pixel through which the background shows (the
// area no surface covers, plus what transparent surfaces let through). So rendering the frame
// over B = 0 and over B = 1 gives both, per channel: S = L0 and w = L1 - L0, whatever the mode.
// From them:
//   transparent: alpha = 1 - w, colour = S / alpha (PNG stores colour not premultiplied);
//   skybox:      L = S + w K, with K the environment's radiance through the pixel's centre,
//                tone-mapped as the surfaces are.
// The two renders are 8-bit sRGB, so L0 and L1 carry the encoder's rounding: w is the mean of
// the three channels' estimates, exact (0 or 1) where the two codes are equal or 0 and 255,
// and otherwise within about half an 8-bit step near white (docs/scene-format.md gives the
// measured alpha error). FXAA filters each render on its own, so its alpha is that of the
// filtered edges.
#pragma once

#include <covrast/image.hpp>

#include <glm/glm.hpp>

#include <functional>

namespace covrast::detail {

/// `over_black` and `over_white` (same size): the frame over B = 0 and B = 1. Writes into
/// `out` (resized) the RGB colours not premultiplied and the alpha plane.
void key_transparent(const Image& over_black, const Image& over_white, Image& out);

/// As key_transparent, but composites `sky(x, y)` (linear, display-ready: tone-mapped) where
/// the background shows; `out` has no alpha plane.
void key_skybox(const Image& over_black, const Image& over_white,
                const std::function<glm::dvec3(int, int)>& sky, Image& out);

}  // namespace covrast::detail
