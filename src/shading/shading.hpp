// Shading shared by every raster mode: flat, unlit colour, perspective-correct
// interpolation of vertex colours in linear light, and for lit triangles (those with a
// ShadingRecord) the lighting of docs/shading.md at the interpolated position and normal.
#pragma once

#include "core/triangle_setup.hpp"

#include <algorithm>

namespace covrast::detail {

struct FragmentFootprint;

/// The lit colour of `t` at the perspective-correct barycentric weights mu0..mu2 (summing
/// to 1): base colour, position and normal interpolated with them (the normal renormalised),
/// then the material's lighting (shading/shading.cpp). Out of line: it is the slow path.
/// `footprint`: where the textures are averaged (sample_surface,
/// shading/shading_inputs.hpp). `filter`, when given, receives the share of the light behind
/// that the surface passes, per channel (KHR_materials_transmission; 0 for other surfaces).
glm::vec3 shade_lit(const TriangleSetup& t, double mu0, double mu1, double mu2,
                    const FragmentFootprint* footprint = nullptr, glm::vec3* filter = nullptr);

/// The perspective-correct barycentric weights mu0..mu2 of `t` at (x_px, y_px). With
/// `clamp_inside`, the screen barycentrics are clamped to [0, 1] first, so a point outside the
/// triangle takes the weights of the nearest part of it and attributes never extrapolate.
///   lambda_i = E_jk(p) / E_jk(v_i)   (screen-space barycentrics)
///   mu_i = lambda_i / w_i / sum_j (lambda_j / w_j)   (perspective-correct)
/// Returns false where they are degenerate (sum not > 0); mu is then (1, 0, 0).
inline bool perspective_weights(const TriangleSetup& t, double x_px, double y_px, bool clamp_inside,
                                double mu[3]) {
  const double s = 1.0 / kSubpixelOne;
  double x0 = t.x_fx8[0] * s, y0 = t.y_fx8[0] * s;
  double x1 = t.x_fx8[1] * s, y1 = t.y_fx8[1] * s;
  double x2 = t.x_fx8[2] * s, y2 = t.y_fx8[2] * s;
  double area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
  double l0 = ((x2 - x1) * (y_px - y1) - (y2 - y1) * (x_px - x1)) / area;
  double l1 = ((x0 - x2) * (y_px - y2) - (y0 - y2) * (x_px - x2)) / area;
  double l2 = ((x1 - x0) * (y_px - y0) - (y1 - y0) * (x_px - x0)) / area;
  if (clamp_inside) {
    l0 = std::max(l0, 0.0);
    l1 = std::max(l1, 0.0);
    l2 = std::max(l2, 0.0);
  }
  double p0 = l0 * t.inv_w[0], p1 = l1 * t.inv_w[1], p2 = l2 * t.inv_w[2];
  double sum = p0 + p1 + p2;
  if (!(sum > 0.0)) {
    mu[0] = 1.0;
    mu[1] = mu[2] = 0.0;
    return false;
  }
  mu[0] = p0 / sum;
  mu[1] = p1 / sum;
  mu[2] = p2 / sum;
  return true;
}

/// Colour of `t` at (x_px, y_px), at the weights of perspective_weights (vertex 0's colour
/// where they are degenerate).
inline glm::vec3 shade(const TriangleSetup& t, double x_px, double y_px, bool clamp_inside) {
  if (t.flat_color) return t.color[0];
  double mu[3];
  if (!perspective_weights(t, x_px, y_px, clamp_inside, mu)) {
    return t.shading != nullptr ? shade_lit(t, 1.0, 0.0, 0.0) : t.color[0];
  }
  if (t.shading != nullptr) return shade_lit(t, mu[0], mu[1], mu[2]);
  return glm::vec3(float(mu[0] * t.color[0].r + mu[1] * t.color[1].r + mu[2] * t.color[2].r),
                   float(mu[0] * t.color[0].g + mu[1] * t.color[1].g + mu[2] * t.color[2].g),
                   float(mu[0] * t.color[0].b + mu[1] * t.color[1].b + mu[2] * t.color[2].b));
}

/// Alpha of a non-opaque triangle (it has a ShadingRecord) at the perspective-correct
/// weights mu0..mu2: the one place where alpha is made (docs/transparency.md),
///   alpha = base_alpha x (mu0 a0 + mu1 a1 + mu2 a2) x texture alpha (1 until textures),
/// a_i the vertex alphas (COLOR_0's fourth component). Out of line (shading/shading.cpp).
double surface_alpha(const TriangleSetup& t, double mu0, double mu1, double mu2);
/// The same with the base colour texture's alpha given (`texture_alpha`, 1 without one).
double surface_alpha_with(const TriangleSetup& t, double mu0, double mu1, double mu2,
                          double texture_alpha);

/// Colour and alpha of a shading point, and what its covered part passes of the light behind
/// it (KHR_materials_transmission's filter, per channel; 0 for every other surface). As a layer
/// (shading/composite.hpp) it adds alpha x rgb and passes (1 - alpha) + alpha x filter.
struct ShadedColor {
  glm::vec3 rgb;
  double alpha;
  glm::vec3 filter{0.0f};
  /// Of a transmissive surface: where its alpha is > 0, only the opaque scene shows through it
  /// (the layers behind it are skipped: shading/composite.hpp).
  bool transmissive = false;
};

/// Whether `t`'s surface is transmissive (its layers have a filter; shading_inputs.hpp).
bool transmits(const TriangleSetup& t);

/// Colour and alpha of `t` at (x_px, y_px), with the same weights as shade(): opaque
/// triangles are shade() and alpha 1, so their colour path is untouched; a transmissive one's
/// filter too. Out of line.
ShadedColor shade_rgba(const TriangleSetup& t, double x_px, double y_px, bool clamp_inside);

/// Whether a Mask triangle keeps the point (x_px, y_px): alpha >= cutoff. True for Opaque
/// and Blend triangles.
bool mask_keeps(const TriangleSetup& t, double x_px, double y_px, bool clamp_inside);

}  // namespace covrast::detail
