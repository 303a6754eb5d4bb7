// The textures of a surface at one shading point (docs/textures.md): each slot's UV set,
// interpolated perspective-correctly with the same weights mu as every other attribute, its
// exact screen-space derivatives (below) for the level of detail, KHR_texture_transform,
// and what each glTF slot does with its texel. Every mode reaches this through shade_lit,
// so a point is textured alike in every mode, tile and thread.
#include "core/shading_inputs.hpp"
#include "core/texture_sampling.hpp"

#include <cmath>

namespace covrast::detail {

// Exact derivatives of the perspective-correct weights. With the screen-space barycentrics
// l_i(x, y) = a_i x + b_i y + c_i (affine; a_i, b_i below, from the snapped vertices as in
// shade()), q_i = l_i w'_i (w'_i = 1 / w_i), S = sum_j q_j and mu_i = q_i / S, each mu_i is
// the rational function (a x + b y + c) / (d x + e y + f) of the issue, and
//   d(mu_i)/dx = (w'_i a_i - mu_i sum_j w'_j a_j) / S        (the same with b for y).
// S is recovered from the weights alone: l_i = mu_i S / w'_i and sum_i l_i = 1 give
//   S = 1 / sum_i (mu_i / w'_i),
// so the derivatives are those of the mapping at the very point shade() evaluated (for a
// clamped point, at the clamped point), with no neighbouring pixels involved.
WeightDerivatives weight_derivatives(const TriangleSetup& t, double mu0, double mu1, double mu2) {
  const double s = 1.0 / kSubpixelOne;
  const double x0 = t.x_fx8[0] * s, y0 = t.y_fx8[0] * s;
  const double x1 = t.x_fx8[1] * s, y1 = t.y_fx8[1] * s;
  const double x2 = t.x_fx8[2] * s, y2 = t.y_fx8[2] * s;
  const double area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
  const double a[3] = {-(y2 - y1) / area, -(y0 - y2) / area, -(y1 - y0) / area};
  const double b[3] = {(x2 - x1) / area, (x0 - x2) / area, (x1 - x0) / area};
  const double w[3] = {t.inv_w[0], t.inv_w[1], t.inv_w[2]};
  const double mu[3] = {mu0, mu1, mu2};
  const double inv_sum = mu0 / w[0] + mu1 / w[1] + mu2 / w[2];  // = 1 / S
  const double sum_a = w[0] * a[0] + w[1] * a[1] + w[2] * a[2];
  const double sum_b = w[0] * b[0] + w[1] * b[1] + w[2] * b[2];
  WeightDerivatives d{};
  for (int i = 0; i < 3; ++i) {
    d.dx[i] = (w[i] * a[i] - mu[i] * sum_a) * inv_sum;
    d.dy[i] = (w[i] * b[i] - mu[i] * sum_b) * inv_sum;
  }
  return d;
}

namespace {

/// One slot's filtered texel: its UV set at the point, transformed, with the level of detail
/// of the transformed derivatives. A NEAREST-filtered slot with `taps`: the mean of the
/// lookups at the taps' weights, at that level of detail.
glm::dvec4 lookup(const TextureSlot& slot, const TexturedCorners& corners, const double mu[3],
                  const WeightDerivatives& d, const FootprintTaps* taps) {
  // check_scene refuses other sets; a scene built without it must still not read out of bounds.
  const glm::vec2* uv = corners.uv[slot.texcoord == 1 ? 1 : 0];
  glm::dvec2 p(0.0), dx(0.0), dy(0.0);
  for (int k = 0; k < 3; ++k) {
    p += mu[k] * glm::dvec2(uv[k]);
    dx += d.dx[k] * glm::dvec2(uv[k]);
    dy += d.dy[k] * glm::dvec2(uv[k]);
  }
  dx = transform_duv(slot.transform, dx);
  dy = transform_duv(slot.transform, dy);
  const double lod = texture_lod(*slot.texture, dx, dy);
  const TextureFilter filter = lod > 0.0 ? slot.sampler.min : slot.sampler.mag;
  if (taps == nullptr || taps->count == 0 || filter != TextureFilter::Nearest) {
    return sample_texture(*slot.texture, slot.sampler, transform_uv(slot.transform, p), lod);
  }
  glm::dvec4 sum(0.0);
  for (int i = 0; i < taps->count; ++i) {
    glm::dvec2 q(0.0);
    for (int k = 0; k < 3; ++k) q += taps->mu[i][k] * glm::dvec2(uv[k]);
    sum += sample_texture(*slot.texture, slot.sampler, transform_uv(slot.transform, q), lod);
  }
  return sum / double(taps->count);
}

/// glTF 2.0, 3.9.3 normalTexture: n_ts = normalize((2 rgb - 1) x (scale, scale, 1)) in the
/// frame T (the tangent made orthogonal to n), B = (n x T) w, n; the interpolated normal when
/// the frame is degenerate (no tangent).
glm::dvec3 perturbed_normal(const glm::dvec4& texel, double scale, const TexturedCorners& corners,
                            const double mu[3], const glm::dvec3& n) {
  glm::dvec3 tangent(0.0);
  for (int k = 0; k < 3; ++k) tangent += mu[k] * glm::dvec3(corners.tangent_world[k]);
  tangent -= n * glm::dot(n, tangent);
  const double tangent_length = glm::length(tangent);
  if (!(tangent_length > 1e-12)) return n;
  tangent /= tangent_length;
  const double handedness = corners.tangent_world[0].w < 0.0f ? -1.0 : 1.0;
  const glm::dvec3 bitangent = glm::cross(n, tangent) * handedness;
  const glm::dvec3 m = tangent * ((2.0 * texel.r - 1.0) * scale) +
                       bitangent * ((2.0 * texel.g - 1.0) * scale) + n * (2.0 * texel.b - 1.0);
  const double m_length = glm::length(m);
  return m_length > 0.0 ? m / m_length : n;
}

/// The textures of KHR_materials_specular (strength in A, F0 colour in RGB),
/// KHR_materials_iridescence (strength in R, thickness in G: mix(minimum, maximum, G)),
/// KHR_materials_sheen (colour in RGB, roughness in A) and KHR_materials_clearcoat (weight in R,
/// roughness in G, its own normal map, which perturbs the interpolated normal, not the base's
/// mapped one); each multiplies the surface's factor.
void sample_material_extensions(const SurfaceShading& s, const SurfaceTextures& slots,
                                const TexturedCorners& corners, const double mu[3],
                                const WeightDerivatives& d, const FootprintTaps* taps,
                                SurfaceSample& out) {
  if (slots.specular != nullptr)
    out.specular_weight *= lookup(*slots.specular, corners, mu, d, taps).a;
  if (slots.specular_color != nullptr) {
    out.specular_color *= glm::dvec3(lookup(*slots.specular_color, corners, mu, d, taps));
  }
  if (slots.clearcoat != nullptr) out.clearcoat *= lookup(*slots.clearcoat, corners, mu, d, taps).r;
  if (slots.clearcoat_roughness != nullptr) {
    out.clearcoat_roughness *= lookup(*slots.clearcoat_roughness, corners, mu, d, taps).g;
  }
  if (slots.iridescence != nullptr)
    out.iridescence *= lookup(*slots.iridescence, corners, mu, d, taps).r;
  if (slots.iridescence_thickness != nullptr) {
    const double g = lookup(*slots.iridescence_thickness, corners, mu, d, taps).g;
    out.iridescence_thickness_nm =
        s.iridescence_thickness_min_nm +
        (s.iridescence_thickness_nm - s.iridescence_thickness_min_nm) * g;
  }
  if (slots.sheen_color != nullptr) {
    out.sheen_color *= glm::dvec3(lookup(*slots.sheen_color, corners, mu, d, taps));
  }
  if (slots.sheen_roughness != nullptr) {
    out.sheen_roughness *= lookup(*slots.sheen_roughness, corners, mu, d, taps).a;
  }
  if (slots.clearcoat_normal != nullptr && out.clearcoat_normal != glm::dvec3(0.0)) {
    out.clearcoat_normal =
        perturbed_normal(lookup(*slots.clearcoat_normal, corners, mu, d, taps),
                         slots.clearcoat_normal->scale, corners, mu, out.clearcoat_normal);
  }
}

}  // namespace

double base_color_texture_alpha(const TriangleSetup& t, double mu0, double mu1, double mu2) {
  const ShadingRecord& r = *t.shading;
  if (r.textured == nullptr || r.surface->textures->base_color == nullptr) return 1.0;
  const double mu[3] = {mu0, mu1, mu2};
  return lookup(*r.surface->textures->base_color, *r.textured, mu,
                weight_derivatives(t, mu0, mu1, mu2), nullptr)
      .a;
}

SurfaceSample sample_surface(const TriangleSetup& t, double mu0, double mu1, double mu2,
                             const glm::dvec3& normal, const FootprintTaps* taps) {
  const ShadingRecord& r = *t.shading;
  const SurfaceShading& s = *r.surface;
  const SurfaceTextures& slots = *s.textures;
  const TexturedCorners& corners = *r.textured;
  SurfaceSample out;
  out.metallic = s.metallic;
  out.roughness = s.roughness;
  out.emissive = s.emissive;
  out.normal = normal;
  out.specular_weight = s.specular_weight;
  out.specular_color = s.specular_color;
  out.clearcoat = s.clearcoat;
  out.clearcoat_roughness = s.clearcoat_roughness;
  out.clearcoat_normal = normal;
  out.sheen_color = s.sheen_color;
  out.sheen_roughness = s.sheen_roughness;
  out.iridescence = s.iridescence;
  out.iridescence_thickness_nm = s.iridescence_thickness_nm;
  const double mu[3] = {mu0, mu1, mu2};
  const WeightDerivatives d = weight_derivatives(t, mu0, mu1, mu2);
  if (slots.base_color != nullptr) out.base_color = lookup(*slots.base_color, corners, mu, d, taps);
  if (slots.metallic_roughness != nullptr) {
    const glm::dvec4 v = lookup(*slots.metallic_roughness, corners, mu, d, taps);
    out.roughness *= v.g;
    out.metallic *= v.b;
  }
  if (slots.occlusion != nullptr) {
    const glm::dvec4 v = lookup(*slots.occlusion, corners, mu, d, taps);
    out.occlusion = 1.0 + double(slots.occlusion->scale) * (v.r - 1.0);
  }
  if (slots.emissive != nullptr) {
    out.emissive *= glm::dvec3(lookup(*slots.emissive, corners, mu, d, taps));
  }
  if (slots.normal != nullptr && normal != glm::dvec3(0.0)) {
    out.normal = perturbed_normal(lookup(*slots.normal, corners, mu, d, taps), slots.normal->scale,
                                  corners, mu, normal);
  }
  sample_material_extensions(s, slots, corners, mu, d, taps, out);
  return out;
}

}  // namespace covrast::detail
