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
#include <covrast/scene.hpp>

#include "color/tone_map.hpp"
#include "shading/environment_lighting.hpp"

#include <glm/glm.hpp>

namespace covrast::detail {

/// The skybox as the scene's camera sees it: the environment's radiance along the ray through a
/// pixel's centre (orthographic: along the view direction), exposed and tone-mapped as the
/// shaded colours are. The camera's frame, the map's rotation and the tone map are set up once
/// per frame, not per pixel. `scene.environment` must be set.
class SkyView {
 public:
  SkyView(const Scene& scene, int width_px, int height_px);
  glm::dvec3 at(int x, int y) const;

 private:
  EnvironmentSky sky_;
  ToneMapping mapping_;
  bool orthographic_;
  glm::dvec3 forward_, right_, up_;
  double half_w_ = 0.0, half_h_ = 0.0;  ///< tan of the half field of view, across and down
  int width_px_, height_px_;
};

/// `frame` holds the frame over B = 0 and `over_white` (same size) the frame over B = 1.
/// Rewrites `frame` in place: the RGB colours not premultiplied, and the alpha plane.
void key_transparent(Image& frame, const Image& over_white);

/// As key_transparent, but composites the sky (display-ready: tone-mapped) where the
/// background shows; `frame` keeps no alpha plane. With `per_channel` (a scene with
/// transmissive surfaces, whose filter tints what shows through them), each channel takes its
/// own share w_c = L1_c - L0_c instead of their mean.
void key_skybox(Image& frame, const Image& over_white, const SkyView& sky, bool per_channel);

/// Whether `scene` draws a transmissive surface (a lit pbr material with transmission > 0).
bool has_transmission(const Scene& scene);

}  // namespace covrast::detail
