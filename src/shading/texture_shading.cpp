// The textures of a surface at one shading point (docs/textures.md): each slot's UV set,
// interpolated perspective-correctly with the same weights mu as every other attribute, its
// exact screen-space derivatives (below) for the level of detail, KHR_texture_transform,
// and what each glTF slot does with its texel. Every mode reaches this through shade_lit,
// so a point is textured alike in every mode, tile and thread.
#include "shading/shading.hpp"
#include "shading/shading_inputs.hpp"
#include "texture/level_cuts.hpp"
#include "texture/texture_sampling.hpp"

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

/// The UV of a slot at weights mu (transformed).
glm::dvec2 slot_uv(const TextureSlot& slot, const glm::vec2* uv, const double mu[3]) {
  glm::dvec2 q(0.0);
  for (int k = 0; k < 3; ++k) q += mu[k] * glm::dvec2(uv[k]);
  return transform_uv(slot.transform, q);
}

/// The points of a 4x4 grid of pixel (x, y) ((i + 1/2) / 4, as ssaa:4 places its samples)
/// that lie in `t`, edges included, as perspective-correct weights; returns their count.
int grid_points_in(const TriangleSetup& t, int x, int y, double mu[16][3]) {
  int count = 0;
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) {
      double* m = mu[count];
      // Unclamped weights are all >= 0 exactly where the point is in the triangle.
      if (perspective_weights(t, x + (i + 0.5) / 4.0, y + (j + 0.5) / 4.0, false, m) &&
          m[0] >= 0.0 && m[1] >= 0.0 && m[2] >= 0.0) {
        ++count;
      }
    }
  }
  return count;
}

/// The fragment's part of its pixel in a slot's (transformed) UVs.
ConvexPolygon slot_polygon(const TextureSlot& slot, const glm::vec2* uv,
                           const FragmentFootprint& footprint) {
  ConvexPolygon polygon;
  for (int i = 0; i < footprint.vertex_count; ++i) {
    const glm::dvec2 q = slot_uv(slot, uv, footprint.vertex_mu[i]);
    polygon.add(q.x, q.y);
  }
  return polygon;
}

/// A slot averaged over the fragment at level of detail `lod`: its exact mean over the
/// triangle's part of the pixel mapped into the texture (area_average); where that
/// declines (a part over more than 64 texels of a level), the mean of the lookups at the
/// grid points in the triangle; with none, the lookup at `centre` (the slot's UV there).
glm::dvec4 footprint_average(const TriangleSetup& t, const TextureSlot& slot, const glm::vec2* uv,
                             const FragmentFootprint& footprint, const glm::dvec2& centre,
                             double lod) {
  if (footprint.vertex_count >= 3) {
    if (const auto mean = area_average(*slot.texture, slot.sampler,
                                       slot_polygon(slot, uv, footprint), lod, footprint.cuts)) {
      return *mean;
    }
  }
  double mu[16][3];
  const int count = grid_points_in(t, footprint.x, footprint.y, mu);
  if (count == 0) return sample_texture(*slot.texture, slot.sampler, centre, lod);
  glm::dvec4 sum(0.0);
  for (int i = 0; i < count; ++i) {
    sum += sample_texture(*slot.texture, slot.sampler, slot_uv(slot, uv, mu[i]), lod);
  }
  return sum / double(count);
}

/// A slot at one shading point: its UV set, the (transformed) UV there and the level of
/// detail of the transformed derivatives.
struct SlotPoint {
  const glm::vec2* uv;
  glm::dvec2 p;
  double lod;
};

SlotPoint slot_point(const TextureSlot& slot, const TexturedCorners& corners, const double mu[3],
                     const WeightDerivatives& d) {
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
  return {uv, transform_uv(slot.transform, p), texture_lod(*slot.texture, dx, dy)};
}

/// One slot's filtered texel at its point (slot_point). With a `footprint`: its average over
/// the fragment at that level of detail (footprint_average).
glm::dvec4 lookup(const TriangleSetup& t, const TextureSlot& slot, const TexturedCorners& corners,
                  const double mu[3], const WeightDerivatives& d,
                  const FragmentFootprint* footprint) {
  const SlotPoint at = slot_point(slot, corners, mu, d);
  if (footprint == nullptr) return sample_texture(*slot.texture, slot.sampler, at.p, at.lod);
  return footprint_average(t, slot, at.uv, *footprint, at.p, at.lod);
}

/// The tangent frame at a point: T, the interpolated tangent made orthogonal to the unit
/// normal n, and B = (n x T) w; `valid` is false where there is no tangent (zero, or along n).
struct TangentFrame {
  glm::dvec3 tangent{0.0}, bitangent{0.0};
  bool valid = false;
};

TangentFrame tangent_frame(const TexturedCorners& corners, const double mu[3],
                           const glm::dvec3& n) {
  TangentFrame frame;
  glm::dvec3 tangent(0.0);
  for (int k = 0; k < 3; ++k) tangent += mu[k] * glm::dvec3(corners.tangent_world[k]);
  tangent -= n * glm::dot(n, tangent);
  const double tangent_length = glm::length(tangent);
  if (!(tangent_length > 1e-12)) return frame;
  frame.tangent = tangent / tangent_length;
  const double handedness = corners.tangent_world[0].w < 0.0f ? -1.0 : 1.0;
  frame.bitangent = glm::cross(n, frame.tangent) * handedness;
  frame.valid = true;
  return frame;
}

/// glTF 2.0, 3.9.3 normalTexture: n_ts = normalize((2 rgb - 1) x (scale, scale, 1)) in the
/// frame T, B, n (`frame`, tangent_frame of n); n when the frame is degenerate.
glm::dvec3 perturbed_normal(const glm::dvec4& texel, double scale, const TangentFrame& frame,
                            const glm::dvec3& n) {
  if (!frame.valid) return n;
  const glm::dvec3 m = frame.tangent * ((2.0 * texel.r - 1.0) * scale) +
                       frame.bitangent * ((2.0 * texel.g - 1.0) * scale) +
                       n * (2.0 * texel.b - 1.0);
  const double m_length = glm::length(m);
  return m_length > 0.0 ? m / m_length : n;
}

/// KHR_materials_anisotropy: the direction in `frame`, T, B of the interpolated normal,
///   d = R(rotation) x (1, 0)                      without a texture,
///   d = R(rotation) x normalize(2 RG - 1)         with one, and strength x its B,
/// R turning counter-clockwise from T towards B; the world direction is normalize(T d.x +
/// B d.y). No tangent frame, or a texel direction of zero length: no direction (the lobe is
/// the isotropic one there).
void sample_anisotropy(const TriangleSetup& t, const SurfaceShading& s,
                       const SurfaceTextures& slots, const TexturedCorners& corners,
                       const double mu[3], const WeightDerivatives& d,
                       const FragmentFootprint* footprint, const TangentFrame& frame,
                       SurfaceSample& out) {
  if (!s.anisotropic() || !frame.valid) return;
  glm::dvec2 direction(1.0, 0.0);
  if (slots.anisotropy != nullptr) {
    const glm::dvec4 texel = lookup(t, *slots.anisotropy, corners, mu, d, footprint);
    out.anisotropy *= texel.b;
    direction = glm::dvec2(2.0 * texel.r - 1.0, 2.0 * texel.g - 1.0);
    const double length = glm::length(direction);
    if (!(length > 0.0)) return;
    direction /= length;
  }
  const glm::dvec2 r = s.anisotropy_rotation;
  direction =
      glm::dvec2(r.x * direction.x - r.y * direction.y, r.y * direction.x + r.x * direction.y);
  const glm::dvec3 world = frame.tangent * direction.x + frame.bitangent * direction.y;
  const double world_length = glm::length(world);
  if (world_length > 0.0) out.anisotropy_direction = world / world_length;
}

/// The textures of KHR_materials_specular (strength in A, F0 colour in RGB),
/// KHR_materials_iridescence (strength in R, thickness in G: mix(minimum, maximum, G)),
/// KHR_materials_sheen (colour in RGB, roughness in A), KHR_materials_transmission (R),
/// KHR_materials_volume (thickness in G) and KHR_materials_clearcoat (weight in R, roughness in
/// G, its own normal map, which perturbs the interpolated normal, not the base's mapped one);
/// each multiplies the surface's factor.
void sample_material_extensions(const TriangleSetup& t, const SurfaceShading& s,
                                const SurfaceTextures& slots, const TexturedCorners& corners,
                                const double mu[3], const WeightDerivatives& d,
                                const FragmentFootprint* footprint, const TangentFrame& frame,
                                SurfaceSample& out) {
  if (slots.specular != nullptr)
    out.specular_weight *= lookup(t, *slots.specular, corners, mu, d, footprint).a;
  if (slots.specular_color != nullptr) {
    out.specular_color *= glm::dvec3(lookup(t, *slots.specular_color, corners, mu, d, footprint));
  }
  if (slots.clearcoat != nullptr)
    out.clearcoat *= lookup(t, *slots.clearcoat, corners, mu, d, footprint).r;
  if (slots.clearcoat_roughness != nullptr) {
    out.clearcoat_roughness *= lookup(t, *slots.clearcoat_roughness, corners, mu, d, footprint).g;
  }
  if (slots.iridescence != nullptr)
    out.iridescence *= lookup(t, *slots.iridescence, corners, mu, d, footprint).r;
  if (slots.iridescence_thickness != nullptr) {
    const double g = lookup(t, *slots.iridescence_thickness, corners, mu, d, footprint).g;
    out.iridescence_thickness_nm =
        s.iridescence_thickness_min_nm +
        (s.iridescence_thickness_nm - s.iridescence_thickness_min_nm) * g;
  }
  if (slots.sheen_color != nullptr) {
    out.sheen_color *= glm::dvec3(lookup(t, *slots.sheen_color, corners, mu, d, footprint));
  }
  if (slots.sheen_roughness != nullptr) {
    out.sheen_roughness *= lookup(t, *slots.sheen_roughness, corners, mu, d, footprint).a;
  }
  if (slots.transmission != nullptr)
    out.transmission *= lookup(t, *slots.transmission, corners, mu, d, footprint).r;
  if (slots.thickness != nullptr)
    out.thickness *= lookup(t, *slots.thickness, corners, mu, d, footprint).g;
  if (slots.clearcoat_normal != nullptr && out.clearcoat_normal != glm::dvec3(0.0)) {
    out.clearcoat_normal =
        perturbed_normal(lookup(t, *slots.clearcoat_normal, corners, mu, d, footprint),
                         slots.clearcoat_normal->scale, frame, out.clearcoat_normal);
  }
}

}  // namespace

glm::dvec4 base_color_texel(const TriangleSetup& t, double mu0, double mu1, double mu2) {
  const ShadingRecord& r = *t.shading;
  if (r.textured == nullptr || r.surface->textures->base_color == nullptr) return glm::dvec4(1.0);
  const double mu[3] = {mu0, mu1, mu2};
  return lookup(t, *r.surface->textures->base_color, *r.textured, mu,
                weight_derivatives(t, mu0, mu1, mu2), nullptr);
}

double base_color_texture_alpha(const TriangleSetup& t, double mu0, double mu1, double mu2) {
  return base_color_texel(t, mu0, mu1, mu2).a;
}

AlphaRange base_color_texture_alpha_range(const TriangleSetup& t, double mu0, double mu1,
                                          double mu2, const FragmentFootprint& footprint) {
  const ShadingRecord& r = *t.shading;
  if (r.textured == nullptr || r.surface->textures->base_color == nullptr) return {1.0, 1.0};
  const TextureSlot& slot = *r.surface->textures->base_color;
  const double mu[3] = {mu0, mu1, mu2};
  const SlotPoint at = slot_point(slot, *r.textured, mu, weight_derivatives(t, mu0, mu1, mu2));
  if (footprint.vertex_count >= 3) {
    if (const auto range = area_alpha_range(*slot.texture, slot.sampler,
                                            slot_polygon(slot, at.uv, footprint), at.lod)) {
      return *range;
    }
  }
  return {0.0, 1.0};  // texels hold alphas in [0, 1]
}

SurfaceSample sample_surface(const TriangleSetup& t, double mu0, double mu1, double mu2,
                             const glm::dvec3& normal, const FragmentFootprint* footprint) {
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
  out.anisotropy = s.anisotropy;
  out.transmission = s.transmission;
  out.thickness = s.thickness;
  const double mu[3] = {mu0, mu1, mu2};
  const WeightDerivatives d = weight_derivatives(t, mu0, mu1, mu2);
  // Slots on one UV set and texture size average over the same polygon on the same levels:
  // they share its cuts (the same bits as cutting it for each).
  FragmentFootprint shared;
  if (footprint != nullptr && footprint->cuts == nullptr && s.texture_slot_count > 1) {
    shared = *footprint;
    shared.cuts = &LevelCutsMemo::of_this_thread();
    footprint = &shared;
  }
  // One tangent frame per point, of the interpolated normal: the normal map's, the clearcoat
  // normal map's (which perturbs the interpolated normal too) and anisotropy's.
  const bool needs_frame =
      normal != glm::dvec3(0.0) &&
      (slots.normal != nullptr || slots.clearcoat_normal != nullptr || s.anisotropic());
  const TangentFrame frame = needs_frame ? tangent_frame(corners, mu, normal) : TangentFrame{};
  if (slots.base_color != nullptr) {
    out.base_color = footprint != nullptr && footprint->has_base_color
                         ? footprint->base_color
                         : lookup(t, *slots.base_color, corners, mu, d, footprint);
  }
  if (slots.metallic_roughness != nullptr) {
    const glm::dvec4 v = lookup(t, *slots.metallic_roughness, corners, mu, d, footprint);
    out.roughness *= v.g;
    out.metallic *= v.b;
  }
  if (slots.occlusion != nullptr) {
    const glm::dvec4 v = lookup(t, *slots.occlusion, corners, mu, d, footprint);
    out.occlusion = 1.0 + double(slots.occlusion->scale) * (v.r - 1.0);
  }
  if (slots.emissive != nullptr) {
    out.emissive *= glm::dvec3(lookup(t, *slots.emissive, corners, mu, d, footprint));
  }
  if (slots.normal != nullptr && normal != glm::dvec3(0.0)) {
    out.normal = perturbed_normal(lookup(t, *slots.normal, corners, mu, d, footprint),
                                  slots.normal->scale, frame, normal);
  }
  sample_material_extensions(t, s, slots, corners, mu, d, footprint, frame, out);
  sample_anisotropy(t, s, slots, corners, mu, d, footprint, frame, out);
  return out;
}

}  // namespace covrast::detail
