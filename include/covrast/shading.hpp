// covrast public API: the shading vocabulary that a scene states and the stages below the
// scene loader act on (how a surface reflects light, how its alpha is used, how a shaded colour
// becomes a displayable one). Included by scene.hpp; it includes nothing of covrast, so the
// shading and raster stages use these enums without the scene API.
#pragma once

#include <cstdint>

namespace covrast {

/// How a lit surface reflects light (docs/shading.md has every formula and its source).
enum class ShadingModel : std::uint8_t {
  Unlit,       ///< the base colour as is, today's flat, unlit look (KHR_materials_unlit)
  Lambert,     ///< base * (ambient + sum E_i max(0, n . l_i)), no 1/pi
  BlinnPhong,  ///< Lambert plus specular * max(0, n . h)^shininess per light
  Pbr,         ///< glTF 2.0 metallic-roughness BRDF (specification, Appendix B)
};

/// How a material's alpha (base_alpha x vertex alpha x texture alpha) is used (glTF 2.0,
/// 3.9.4 alphaMode; docs/transparency.md).
enum class AlphaMode : std::uint8_t {
  Opaque,  ///< alpha ignored: the surface hides what is behind it
  Mask,    ///< kept where alpha >= alpha_cutoff, opaque there, absent elsewhere
  Blend,   ///< composited over what is behind it with its alpha, in depth order
};

/// Tone mapping of every shaded colour (not the background colour), in linear light
/// (docs/shading.md, "Tone mapping and exposure"): None is today's output (exposure still scales).
enum class ToneMap : std::uint8_t { None, KhronosPbrNeutral, AcesHill, AcesNarkowicz };

}  // namespace covrast
