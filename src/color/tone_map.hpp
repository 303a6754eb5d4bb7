// Tone mapping (docs/shading.md, "Tone mapping and exposure"): linear radiance to linear
// display values in [0, 1], applied to every shaded colour before it is composited, as the
// glTF viewers apply it in their fragment shaders. The background colour is a display colour
// (the viewers' clear colour) and is not tone-mapped. Double precision, no contraction.
//
//   none:                 x -> exposure x (today's bytes at exposure 1; the encode clamps)
//   khronos-pbr-neutral:  the Khronos PBR Neutral operator (KhronosGroup/ToneMapping,
//                         PBR_Neutral): with c = exposure x, m = min(c), f = m - 6.25 m^2 for
//                         m < 0.08 else 0.04, c -= f, p = max(c); for p < 0.76 c is the result;
//                         else with d = 0.24, p' = 1 - d^2 / (p + d - 0.76), c *= p' / p, and
//                         g = 1 - 1 / (0.15 (p - p') + 1), the result is c (1 - g) + p' g.
//   aces-hill:            Stephen Hill's fit of ACES RRT + ODT (BakingLab, ACES.hlsl):
//                         clamp(M_out RRTODT(M_in exposure x), 0, 1), RRTODT(v) = (v (v +
//                         0.0245786) - 0.000090537) / (v (0.983729 v + 0.4329510) + 0.238081);
//                         three.js multiplies its input by 1 / 0.6 first (exposure 1.667 here).
//   aces-narkowicz:       Krzysztof Narkowicz's curve, per channel: clamp(x (2.51 x + 0.03) /
//                         (x (2.43 x + 0.59) + 0.14), 0, 1) of x = exposure x.
#pragma once

#include <covrast/shading.hpp>

#include <glm/glm.hpp>

#include <cstdint>

namespace covrast::detail {

struct ToneMapping {
  ToneMap op = ToneMap::None;
  double exposure = 1.0;
  /// None at exposure 1 changes nothing: callers skip it so that the bytes stay as they were.
  bool is_identity() const { return op == ToneMap::None && exposure == 1.0; }
};

glm::dvec3 tone_map(const ToneMapping& mapping, const glm::dvec3& linear);

}  // namespace covrast::detail
