// KHR_materials_iridescence's thin-film Fresnel term (docs/shading.md, "Material extensions"),
// as the extension's specification gives it (KhronosGroup/glTF,
// extensions/2.0/Khronos/KHR_materials_iridescence): the approximation by Belcour and Barla,
// "A Practical Extension to Microfacet Theory for the Modeling of Varying Iridescence"
// (SIGGRAPH 2017) of the reflectance of a thin dielectric film (ior eta2, thickness d) over a
// base of Fresnel reflectance F0, seen at cos theta1 from a medium of ior eta1:
//   cos theta2 = sqrt(1 - (eta1 / eta2)^2 (1 - cos^2 theta1))    (1: total internal reflection)
//   R12 = Schlick(((eta2 - eta1) / (eta2 + eta1))^2, cos theta1),  T121 = 1 - R12
//   eta3 = (1 + sqrt(F0)) / (1 - sqrt(F0)),  R23 = Schlick(((eta3 - eta2) / (eta3 + eta2))^2,
//   cos theta2); phases 0 or pi per interface; OPD = 2 eta2 d cos theta2
//   I = R12 + Rs + sum_{m=1,2} 2 C_m S(m OPD, m phi),  Rs = T121^2 R23 / (1 - R12 R23),
//   C_m = (Rs - T121) sqrt(R12 R23)^m,  S the sensitivity of the CIE XYZ matching functions
//   in Fourier space (Gaussian fits) taken to linear Rec. 709 RGB; F = max(I, 0).
#pragma once

#include <glm/glm.hpp>

namespace covrast::detail {

/// The thin film's Fresnel reflectance (linear RGB) for a film of ior `film_ior` and
/// `thickness_nm` over a base of normal-incidence reflectance `base_f0` (each channel clamped
/// to 0.9999, an ior of infinity otherwise), seen at `cos_theta1` from a medium of ior
/// `outside_ior`.
glm::dvec3 iridescent_fresnel(double outside_ior, double film_ior, const glm::dvec3& base_f0,
                              double thickness_nm, double cos_theta1);

}  // namespace covrast::detail
