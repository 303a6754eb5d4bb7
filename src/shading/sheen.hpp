// KHR_materials_sheen's BRDF (docs/shading.md, "Material extensions"), as the extension's
// specification gives it (KhronosGroup/glTF, extensions/2.0/Khronos/KHR_materials_sheen), from
// Conty Estevez and Kulla, "Production Friendly Microfacet Sheen BRDF" (SIGGRAPH 2017):
//   alpha = max(sheenRoughness^2, kMinSheenAlpha)
//   D     = (2 + 1 / alpha) (1 - (n.h)^2)^(1 / (2 alpha)) / (2 pi)          "Charlie"
//   V     = 1 / ((1 + Lambda(n.v) + Lambda(n.l)) 4 (n.v) (n.l))
//   Lambda(x) = exp(l(x)) for x < 0.5, else exp(2 l(0.5) - l(1 - x)),
//   l(x)  = a / (1 + b x^c) + d x + e, a..e lerped in (1 - alpha)^2 between the paper's fits
//   f_sheen = sheenColor D V                                                 (no Fresnel)
// and its layering by albedo scaling with the view's albedo alone (the extension's simplified
// form): f = f_sheen + f_base (1 - max(sheenColor) E(n.v)), E(mu) = int D V (n.l)+ dl.
#pragma once

#include <glm/glm.hpp>

namespace covrast::detail {

/// Smallest sheen alpha (= sheenRoughness^2): 0 would make D's exponent infinite.
inline constexpr double kMinSheenAlpha = 1e-3;

/// D V of the sheen BRDF for unit n, v, l and perceptual sheen roughness; 0 where n.l or n.v
/// is not positive.
double sheen_lobe(const glm::dvec3& n, const glm::dvec3& v, const glm::dvec3& l,
                  double sheen_roughness);

/// E(mu) = int D V (n.l)+ dl for n . v = mu: the sheen's directional albedo for a white
/// sheenColor, from a table computed once per process by quadrature (bilinear in mu and the
/// roughness).
double sheen_albedo(double mu, double sheen_roughness);

}  // namespace covrast::detail
