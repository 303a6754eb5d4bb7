// Shading inputs of lit triangles, built by the geometry front end
// (src/geometry/frontend_shading.cpp) and read by shade() in every raster mode: the frame's
// lights (ShadingContext), a surface's material (SurfaceShading, one per instance and
// material) and each set-up triangle's world-space vertices and normals (ShadingRecord).
// Unlit triangles have none of these.
// The formulas are in docs/shading.md; all arithmetic is double, IEEE, no contraction.
#pragma once

#include "color/tone_map.hpp"
#include "core/triangle_setup.hpp"
#include "texture/texture_sampling.hpp"

#include <covrast/texture.hpp>

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace covrast::detail {

/// A punctual light prepared for evaluation, world space.
struct PunctualLight {
  enum class Kind : std::uint8_t { Directional, Point, Spot };
  Kind kind = Kind::Directional;
  glm::dvec3 to_light{0.0, 0.0, 1.0};    ///< directional: unit vector towards the light
  glm::dvec3 position{0.0};              ///< point, spot [world units]
  glm::dvec3 spot_axis{0.0, 0.0, -1.0};  ///< spot: unit direction the light travels
  glm::dvec3 radiance{1.0};  ///< color x intensity (lux for directional, candela otherwise)
  double inv_range = 0.0;    ///< 1 / range [1 / world units]; 0 = no range window
  /// Spot cone (KHR_lights_punctual): attenuation = clamp(cos * scale + offset, 0, 1)^2,
  /// scale = 1 / max(0.001, cos(inner) - cos(outer)), offset = -cos(outer) * scale.
  double cone_scale = 0.0;
  double cone_offset = 1.0;
};

class EnvironmentLighting;  // shading/environment_lighting.hpp

/// The frame's lights and eye: one per front end, shared by every lit triangle.
struct ShadingContext {
  glm::dvec3 eye_world{0.0};
  /// Orthographic camera: v is `to_eye` (unit, towards the camera) at every point.
  bool orthographic = false;
  glm::dvec3 to_eye{0.0, 0.0, 1.0};
  glm::dvec3 ambient{0.0};  ///< sum of the ambient lights' color x intensity
  std::vector<PunctualLight> lights;
  /// The scene's environment, prepared (null: none); lights every lit model but Unlit.
  const EnvironmentLighting* environment = nullptr;
  /// Applied to each lit colour as it leaves shade_lit (color/tone_map.hpp).
  ToneMapping tone_mapping;
};

/// A material's non-empty texture slots (pointers into the scene's Material; null: none).
struct SurfaceTextures {
  const TextureSlot* base_color = nullptr;
  const TextureSlot* metallic_roughness = nullptr;
  const TextureSlot* normal = nullptr;
  const TextureSlot* occlusion = nullptr;
  const TextureSlot* emissive = nullptr;
  const TextureSlot* specular = nullptr;             ///< KHR_materials_specular, A
  const TextureSlot* specular_color = nullptr;       ///< KHR_materials_specular, RGB
  const TextureSlot* clearcoat = nullptr;            ///< KHR_materials_clearcoat, R
  const TextureSlot* clearcoat_roughness = nullptr;  ///< KHR_materials_clearcoat, G
  const TextureSlot* clearcoat_normal = nullptr;
  const TextureSlot* sheen_color = nullptr;            ///< KHR_materials_sheen, RGB
  const TextureSlot* sheen_roughness = nullptr;        ///< KHR_materials_sheen, A
  const TextureSlot* iridescence = nullptr;            ///< KHR_materials_iridescence, R
  const TextureSlot* iridescence_thickness = nullptr;  ///< KHR_materials_iridescence, G
  const TextureSlot* anisotropy = nullptr;  ///< KHR_materials_anisotropy: RG direction, B strength
  const TextureSlot* transmission = nullptr;  ///< KHR_materials_transmission, R
  const TextureSlot* thickness = nullptr;     ///< KHR_materials_volume, G

  /// Every slot, null where the material has none.
  std::array<const TextureSlot*, 17> all() const {
    return {base_color,
            metallic_roughness,
            normal,
            occlusion,
            emissive,
            specular,
            specular_color,
            clearcoat,
            clearcoat_roughness,
            clearcoat_normal,
            sheen_color,
            sheen_roughness,
            iridescence,
            iridescence_thickness,
            anisotropy,
            transmission,
            thickness};
  }
  /// How many slots hold a texture.
  int count() const {
    int n = 0;
    for (const TextureSlot* slot : all()) n += slot != nullptr;
    return n;
  }
};
static_assert(sizeof(SurfaceTextures) == 17 * sizeof(const TextureSlot*),
              "SurfaceTextures::all() lists every slot");

/// The fragment over which sample_surface averages its textures
/// (raster/coverage/fragment_shading.hpp makes it): pixel (x, y) and the vertices of the
/// triangle's part of it as perspective-correct weights (none when that part has no area).
struct FragmentFootprint {
  int x = 0;
  int y = 0;
  static constexpr int kMaxVertices = 7;  ///< a triangle clipped to a square
  double vertex_mu[kMaxVertices][3];
  int vertex_count = 0;
  /// A base colour texel to use instead of the average (a MASK fragment's mean over the
  /// points whose alpha passes: the texels the cutoff removes must not tint it).
  bool has_base_color = false;
  glm::dvec4 base_color{1.0};
  /// Where the slots averaged over this fragment keep their polygon's cuts for each other
  /// (set by sample_surface when it averages more than one slot); none: each cuts its own.
  LevelCutsMemo* cuts = nullptr;
};

/// One material of one mesh instance, resolved (scene overrides applied).
struct SurfaceShading {
  ShadingModel model = ShadingModel::Lambert;
  double metallic = 1.0;
  double roughness = 1.0;    ///< perceptual; the BRDF's alpha = roughness^2
  glm::dvec3 emissive{0.0};  ///< linear radiance, added
  glm::dvec3 specular{0.5};  ///< blinn-phong
  double shininess = 32.0;   ///< blinn-phong exponent
  bool double_sided = true;  ///< back faces get the flipped normal (front end)
  /// Multiplies the ambient term only (the occlusion texture sets it per shading point).
  double occlusion = 1.0;
  /// pbr: the dielectric's Fresnel reflectance at normal incidence from its ior
  /// (KHR_materials_ior; glTF's 0.04 without it).
  double ior_f0 = 0.04;
  /// pbr, KHR_materials_specular: the dielectric's specular strength and F0 colour (1: none).
  double specular_weight = 1.0;
  glm::dvec3 specular_color{1.0};
  /// pbr, KHR_materials_clearcoat: the coat's weight (0: none) and perceptual roughness.
  double clearcoat = 0.0;
  double clearcoat_roughness = 0.0;
  /// pbr, KHR_materials_sheen: the sheen's colour (0: none) and perceptual roughness.
  glm::dvec3 sheen_color{0.0};
  double sheen_roughness = 0.0;
  /// pbr, KHR_materials_iridescence: strength (0: none), the film's ior and thickness (the
  /// maximum; the thickness texture lerps from the minimum to it).
  double iridescence = 0.0;
  double iridescence_ior = 1.3;
  double iridescence_thickness_nm = 400.0;
  double iridescence_thickness_min_nm = 100.0;
  /// pbr, KHR_materials_anisotropy: strength (0: none) and (cos, sin) of the rotation from the
  /// tangent towards the bitangent.
  double anisotropy = 0.0;
  glm::dvec2 anisotropy_rotation{1.0, 0.0};
  bool anisotropic() const { return model == ShadingModel::Pbr && anisotropy > 0.0; }
  /// pbr, KHR_materials_transmission: the share of the diffuse that passes (0: none); with
  /// KHR_materials_volume the thickness [world units: the material's x the instance's scale]
  /// and the attenuation over it (distance 0: none).
  double transmission = 0.0;
  double ior = 1.5;  ///< KHR_materials_ior's, for the transmission lobe's roughness
  double thickness = 0.0;
  glm::dvec3 attenuation_color{1.0};
  double attenuation_distance = 0.0;
  /// A pbr surface with transmission (some texel may give it): its triangles are composited
  /// as transparent layers, their alpha 1 (OPAQUE) or the mask's verdict (MASK).
  bool transmissive() const { return model == ShadingModel::Pbr && transmission > 0.0; }
  /// Alpha (docs/transparency.md): base_alpha x vertex alpha x texture alpha at the point.
  AlphaMode alpha_mode = AlphaMode::Opaque;
  double alpha_cutoff = 0.5;  ///< Mask: kept where alpha >= alpha_cutoff
  double base_alpha = 1.0;    ///< the base colour factor's alpha
  const ShadingContext* context = nullptr;
  /// The textures this surface samples; null for an untextured one (no per-pixel texture
  /// work at all), and for an Unlit one without a base colour texture. An anisotropic surface
  /// has them, for the tangent frame its triangles then carry, even when no slot is set.
  const SurfaceTextures* textures = nullptr;
  /// How many slots of `textures` are set (SurfaceTextures::count): what coverage mode
  /// averages over a fragment, sharing their cuts when there are several.
  int texture_slot_count = 0;
};

/// What a textured triangle adds to its ShadingRecord, in the TriangleSetup's vertex order:
/// both UV sets, and world-space tangents with the bitangent sign in w (the file's, or the
/// triangle's own from its UV derivatives; zero when neither exists).
struct TexturedCorners {
  glm::vec2 uv[kMaxTexcoordSets][3];
  glm::vec4 tangent_world[3];
};

/// Per set-up triangle, in the TriangleSetup's vertex order (lit triangles, and every
/// non-opaque one: an unlit one has zero positions and normals and an Unlit surface). Normals are
/// unit length and already face the viewer's side for back faces of double-sided materials.
struct ShadingRecord {
  glm::vec3 position_world[3];
  glm::vec3 normal_world[3];
  float vertex_alpha[3];  ///< COLOR_0's alpha (1 without one)
  const SurfaceShading* surface;
  const TexturedCorners* textured = nullptr;  ///< null unless surface->textures
};

/// The textures' contribution at one shading point (shading/texture_shading.cpp).
struct SurfaceSample {
  glm::dvec4 base_color{1.0};        ///< multiplies the base colour; alpha for the alpha modes
  double metallic = 1.0;             ///< the surface's, times the texture's B
  double roughness = 1.0;            ///< the surface's, times the texture's G
  double occlusion = 1.0;            ///< 1 + strength (R - 1)
  glm::dvec3 emissive{0.0};          ///< the surface's, times the emissive texture
  glm::dvec3 normal{0.0};            ///< unit, world space; the normal map applied
  double specular_weight = 1.0;      ///< the surface's, times the specular texture's A
  glm::dvec3 specular_color{1.0};    ///< the surface's, times the specular colour texture
  double clearcoat = 0.0;            ///< the surface's, times the clearcoat texture's R
  double clearcoat_roughness = 0.0;  ///< the surface's, times the roughness texture's G
  /// unit, world space: the clearcoat normal texture applied, else the interpolated normal
  glm::dvec3 clearcoat_normal{0.0};
  glm::dvec3 sheen_color{0.0};   ///< the surface's, times the sheen colour texture
  double sheen_roughness = 0.0;  ///< the surface's, times the sheen roughness texture's A
  double iridescence = 0.0;      ///< the surface's, times the iridescence texture's R
  double iridescence_thickness_nm = 400.0;  ///< the maximum, or lerped by the texture's G
  double anisotropy = 0.0;                  ///< the surface's, times the texture's B
  /// unit, world space: the direction the anisotropic lobe is stretched along (zero: no
  /// tangent frame here, the lobe is the isotropic one)
  glm::dvec3 anisotropy_direction{0.0};
  double transmission = 0.0;  ///< the surface's, times the transmission texture's R
  double thickness = 0.0;     ///< the surface's, times the thickness texture's G
};

/// Samples every texture of `t`'s surface at the perspective-correct weights mu0..mu2, with
/// the level of detail from the exact screen-space derivatives of each UV set there;
/// `normal` is the interpolated unit normal (zero: none), which the normal map perturbs.
/// With a `footprint`, each slot is its average over the fragment at the level
/// of detail of mu0..mu2 (shading/texture_shading.cpp, footprint_average).
SurfaceSample sample_surface(const TriangleSetup& t, double mu0, double mu1, double mu2,
                             const glm::dvec3& normal,
                             const FragmentFootprint* footprint = nullptr);

/// The base colour texture's filtered texel at the weights mu0..mu2 (1 without one), sampled
/// exactly as sample_surface samples it; its alpha is the texture term of surface_alpha.
glm::dvec4 base_color_texel(const TriangleSetup& t, double mu0, double mu1, double mu2);
/// Its alpha.
double base_color_texture_alpha(const TriangleSetup& t, double mu0, double mu1, double mu2);

/// Bounds of that alpha over `footprint` at the level of detail of mu0..mu2 (the texels the
/// lookups there read: area_alpha_range); [0, 1] where those are too many, [1, 1] without a
/// texture.
AlphaRange base_color_texture_alpha_range(const TriangleSetup& t, double mu0, double mu1,
                                          double mu2, const FragmentFootprint& footprint);

/// d(mu_i)/dx and d(mu_i)/dy of the perspective-correct barycentric weights of `t` at the
/// point whose weights are mu0..mu2 (docs/textures.md has the derivation).
struct WeightDerivatives {
  double dx[3];
  double dy[3];
};
WeightDerivatives weight_derivatives(const TriangleSetup& t, double mu0, double mu1, double mu2);

/// Outgoing linear radiance at world point `p` with unit normal `n` (zero: no normal) and
/// base colour `base` (linear): the material's model, summed over the context's lights.
/// `clearcoat_normal` (unit, or zero) is the pbr clear coat's normal (KHR_materials_clearcoat).
/// `anisotropy_direction` (unit, or zero: isotropic) is KHR_materials_anisotropy's direction.
/// `filter`, when given, receives what the surface passes of the light behind it, per channel
/// (KHR_materials_transmission; 0 for every other surface).
glm::dvec3 shade_point(const SurfaceShading& surface, const glm::dvec3& base, const glm::dvec3& p,
                       const glm::dvec3& n, const glm::dvec3& clearcoat_normal,
                       const glm::dvec3& anisotropy_direction = glm::dvec3(0.0),
                       glm::dvec3* filter = nullptr);
inline glm::dvec3 shade_point(const SurfaceShading& surface, const glm::dvec3& base,
                              const glm::dvec3& p, const glm::dvec3& n) {
  return shade_point(surface, base, p, n, n);
}

/// The pbr material at one shading point, its Fresnel terms prepared (shading/shading.cpp):
/// c_diff = base (1 - metallic); F0 and F90 from KHR_materials_ior and _specular, lerped to the
/// metal's (base, 1) by metallic; F0_d, the F0 the diffuse weight uses (the dielectric F0's
/// largest channel, lerped alike; F0 itself when the dielectric F0 is grey).
struct PbrPoint {
  PbrPoint(const SurfaceShading& s, const glm::dvec3& base, const glm::dvec3& clearcoat_normal);
  glm::dvec3 base;
  double metallic;
  double roughness;
  glm::dvec3 c_diff, f0, f90, f0_diffuse;
  double clearcoat;
  double coat_roughness;
  glm::dvec3 coat_normal;
  glm::dvec3 sheen_color;
  double sheen_roughness;
  /// The dielectric's F0 and F90 before metallic (the thin film's base, and its mix).
  glm::dvec3 dielectric_f0;
  double dielectric_f90;
  /// KHR_materials_iridescence (set by set_iridescence): its strength, the film's Fresnel term
  /// at n . v over the dielectric and over the metal, their mix by metallic, and the same with
  /// the dielectric's reduced to its largest channel (the diffuse weight under the environment
  /// and the ambient light).
  double iridescence = 0.0;
  glm::dvec3 iridescent_dielectric{0.0}, iridescent_metal{0.0};
  glm::dvec3 iridescent{0.0}, iridescent_diffuse{0.0};
  void set_iridescence(const SurfaceShading& s, double n_dot_v);
  /// KHR_materials_anisotropy (set by set_anisotropy): its strength and the lobe's frame, the
  /// stretched direction t made orthogonal to n and b = n x t (strength 0: no frame).
  double anisotropy = 0.0;
  glm::dvec3 anisotropy_t{0.0}, anisotropy_b{0.0};
  void set_anisotropy(double strength, const glm::dvec3& direction, const glm::dvec3& n);
  /// KHR_materials_transmission (set by set_transmission): c_trans = base (1 - metallic)
  /// transmission, the part of the dielectric's diffuse that passes instead (c_diff keeps
  /// 1 - transmission of it), times KHR_materials_volume's attenuation over the thickness,
  /// attenuation_color^(thickness / attenuation_distance); and the BTDF's alpha^2, from
  /// alpha x clamp(2 ior - 2, 0, 1) (the glTF Sample Viewer's applyIorToRoughness).
  glm::dvec3 c_trans{0.0};
  double transmission_alpha2 = 0.0;
  bool transmits() const { return c_trans != glm::dvec3(0.0); }
  void set_transmission(const SurfaceShading& s, double transmission, double thickness);
};

/// The glTF 2.0 metallic-roughness BRDF f(l, v) (specification, Appendix B.3.5: Trowbridge-
/// Reitz D, Smith height-correlated V, Schlick F, Lambert diffuse (1 - F) c_diff / pi), for
/// unit n, v, l; without the n . l cosine. The second form is the core material (no extension).
/// Exposed for the tests.
glm::dvec3 pbr_brdf(const PbrPoint& m, const glm::dvec3& n, const glm::dvec3& v,
                    const glm::dvec3& l);
glm::dvec3 pbr_brdf(const glm::dvec3& base, double metallic, double roughness, const glm::dvec3& n,
                    const glm::dvec3& v, const glm::dvec3& l);
/// KHR_materials_transmission's thin-walled BTDF for a light in direction l behind the surface
/// (n . l < 0), without the cosine (shading/shading.cpp). Exposed for the tests.
glm::dvec3 transmission_btdf(const PbrPoint& m, const glm::dvec3& n, const glm::dvec3& v,
                             const glm::dvec3& l);

}  // namespace covrast::detail
