// Geometry stage, shading set-up (frontend.hpp): the frame's lights and each instance's
// materials in the form shade() evaluates them (shading/shading_inputs.hpp), the per-corner
// shading inputs of each lit triangle the front end sets up (world positions and normals,
// UVs and tangents, vertex alphas), and its ShadingRecord.
#include "geometry/frontend.hpp"

#include <array>
#include <cmath>

namespace covrast::detail {

namespace {

/// A scene light in the form shade() evaluates (shading/shading_inputs.hpp); ambient lights
/// are summed into the context instead.
PunctualLight punctual_light(const Light& light) {
  PunctualLight p;
  p.radiance = glm::dvec3(light.color_linear) * light.intensity;
  p.position = light.position;
  p.inv_range = light.range > 0.0 ? 1.0 / light.range : 0.0;
  switch (light.type) {
    case LightType::Point:
      p.kind = PunctualLight::Kind::Point;
      break;
    case LightType::Spot: {
      p.kind = PunctualLight::Kind::Spot;
      p.spot_axis = glm::normalize(light.direction);
      const double cos_outer = std::cos(glm::radians(light.outer_cone_deg));
      const double cos_inner = std::cos(glm::radians(light.inner_cone_deg));
      p.cone_scale = 1.0 / std::max(0.001, cos_inner - cos_outer);
      p.cone_offset = -cos_outer * p.cone_scale;
      break;
    }
    default:
      p.kind = PunctualLight::Kind::Directional;
      p.to_light = -glm::normalize(light.direction);
      break;
  }
  return p;
}

/// The texture slots a material shows: all of them when it is lit, only the base colour's
/// when unlit (ShadingModel::Unlit, or a scene without lights).
SurfaceTextures surface_slots(const Material& m, bool lit) {
  const auto slot = [](const TextureSlot& t) { return t ? &t : nullptr; };
  SurfaceTextures out;
  out.base_color = slot(m.base_color_texture);
  if (!lit || m.model == ShadingModel::Unlit) return out;
  out.metallic_roughness = slot(m.metallic_roughness_texture);
  out.normal = slot(m.normal_texture);
  out.occlusion = slot(m.occlusion_texture);
  out.emissive = slot(m.emissive_texture);
  if (m.model != ShadingModel::Pbr) return out;
  out.specular = slot(m.specular_texture);
  out.specular_color = slot(m.specular_color_texture);
  out.clearcoat = slot(m.clearcoat_texture);
  out.clearcoat_roughness = slot(m.clearcoat_roughness_texture);
  out.clearcoat_normal = slot(m.clearcoat_normal_texture);
  out.sheen_color = slot(m.sheen_color_texture);
  out.sheen_roughness = slot(m.sheen_roughness_texture);
  out.iridescence = slot(m.iridescence_texture);
  out.iridescence_thickness = slot(m.iridescence_thickness_texture);
  out.anisotropy = slot(m.anisotropy_texture);
  out.transmission = slot(m.transmission_texture);
  out.thickness = slot(m.thickness_texture);
  return out;
}

}  // namespace

bool GeometryFrontEnd::shows_textures(const Scene& scene) {
  for (const MeshInstance& instance : scene.meshes) {
    for (const Material& m : instance.materials) {
      if (surface_slots(m, scene.lit).count() > 0) return true;
    }
  }
  return false;
}

namespace {

SurfaceShading surface_shading(const Material& m, const ShadingContext* context) {
  SurfaceShading s;
  s.model = m.model;
  s.metallic = m.metallic;
  s.roughness = m.roughness;
  s.emissive = glm::dvec3(m.emissive_linear);
  s.specular = glm::dvec3(m.specular_linear);
  s.shininess = m.shininess;
  s.double_sided = m.double_sided;
  s.alpha_mode = m.alpha_mode;
  s.alpha_cutoff = m.alpha_cutoff;
  s.base_alpha = m.base_alpha;
  s.context = context;
  // KHR_materials_ior: f0 = ((ior - 1) / (ior + 1))^2, and glTF's own 0.04 for its default 1.5
  // (the formula gives 0.04000000000000001 there, which would change every default material).
  const double ior = m.ior;
  s.ior_f0 = m.ior == 1.5f ? 0.04 : ((ior - 1.0) / (ior + 1.0)) * ((ior - 1.0) / (ior + 1.0));
  s.specular_weight = m.specular_factor;
  s.specular_color = glm::dvec3(m.specular_color_factor);
  s.clearcoat = m.clearcoat;
  s.clearcoat_roughness = m.clearcoat_roughness;
  s.sheen_color = glm::dvec3(m.sheen_color_factor);
  s.sheen_roughness = m.sheen_roughness;
  s.iridescence = m.iridescence;
  s.iridescence_ior = m.iridescence_ior;
  s.iridescence_thickness_nm = m.iridescence_thickness_max_nm;
  s.iridescence_thickness_min_nm = m.iridescence_thickness_min_nm;
  s.anisotropy = m.anisotropy;
  s.anisotropy_rotation =
      glm::dvec2(std::cos(double(m.anisotropy_rotation)), std::sin(double(m.anisotropy_rotation)));
  s.transmission = m.transmission;
  s.ior = m.ior;
  s.thickness = m.thickness;
  s.attenuation_color = glm::dvec3(m.attenuation_color);
  s.attenuation_distance = m.attenuation_distance;
  return s;
}

}  // namespace

void GeometryFrontEnd::prepare_environment() {
  if (!lit_context_ || environment_) return;
  if (scene_.environment && scene_.environment->map && scene_.environment->map->width > 0 &&
      scene_.environment->map->height > 0) {
    environment_.emplace(*scene_.environment);
    context_.environment = &*environment_;
  }
}

void GeometryFrontEnd::prepare_lighting() {
  context_.eye_world = eye_;
  if (scene_.camera.orthographic) {
    // Parallel rays: every point sees the camera in the same direction.
    context_.orthographic = true;
    context_.to_eye = glm::normalize(scene_.camera.eye - scene_.camera.target);
  }
  lit_context_ = true;
  for (const Light& light : scene_.lights) {
    if (light.type == LightType::Ambient) {
      context_.ambient += glm::dvec3(light.color_linear) * light.intensity;
    } else {
      context_.lights.push_back(punctual_light(light));
    }
  }
  surfaces_.resize(scene_.meshes.size());
  textures_.resize(scene_.meshes.size());
  lit_.assign(scene_.meshes.size(), false);
  alpha_.assign(scene_.meshes.size(), false);
  for (std::size_t i = 0; i < scene_.meshes.size(); ++i) {
    const std::vector<Material>& materials = scene_.meshes[i].materials;
    // All slots first: surfaces_ point into textures_[i], which must not move afterwards.
    for (const Material& m : materials) textures_[i].push_back(surface_slots(m, scene_.lit));
    for (std::size_t k = 0; k < materials.size(); ++k) {
      SurfaceShading surface = surface_shading(materials[k], &context_);
      if (!scene_.lit) surface.model = ShadingModel::Unlit;  // textured in a scene without lights
      // KHR_materials_volume's thickness is in the mesh's units: scaled by the instance's
      // (uniform) scale, |det(model)|^(1/3).
      surface.thickness *=
          std::cbrt(std::abs(glm::determinant(glm::dmat3(scene_.meshes[i].model))));
      // An anisotropic pbr surface needs the tangent frame that textured triangles carry,
      // whether or not it has textures.
      surface.texture_slot_count = textures_[i][k].count();
      if (surface.texture_slot_count > 0 || surface.anisotropic()) {
        surface.textures = &textures_[i][k];
      }
      surfaces_[i].push_back(surface);
      if ((scene_.lit && materials[k].model != ShadingModel::Unlit) || surface.textures) {
        lit_[i] = true;
      }
      if (materials[k].alpha_mode != AlphaMode::Opaque || surface.transmissive()) alpha_[i] = true;
    }
    if (surfaces_[i].empty()) surfaces_[i].push_back(surface_shading(Material{}, &context_));
    if (lit_[i]) vertices_[i].position_world.resize(scene_.meshes[i].mesh->positions.size());
  }
}

void GeometryFrontEnd::shade_vertices(std::size_t instance, std::size_t local,
                                      const glm::dmat3& normal_matrix, const glm::dmat3& linear,
                                      double det_sign, const SurfaceShading& surface,
                                      ShadeVertex out[3]) const {
  const MeshInstance& inst = scene_.meshes[instance];
  const std::uint32_t* idx = inst.mesh->indices.data() + local * 3;
  const std::vector<glm::vec3>& world = vertices_[instance].position_world;
  // Face normal: the file's counter-clockwise side, cross(p1 - p0, p2 - p0) in world space,
  // turned back by a mirroring model matrix (which reverses the world winding).
  const glm::dvec3 w0(world[idx[0]]), w1(world[idx[1]]), w2(world[idx[2]]);
  const glm::dvec3 face = glm::cross(w1 - w0, w2 - w0) * det_sign;
  const double face_length = glm::length(face);
  const glm::dvec3 face_unit = face_length > 0.0 ? face / face_length : glm::dvec3(0.0);
  const glm::vec3* corners =
      inst.corner_normals != nullptr ? inst.corner_normals->data() + local * 3 : nullptr;
  vertex_alphas(instance, local, out);
  for (int k = 0; k < 3; ++k) {
    out[k].position_world = world[idx[k]];
    glm::dvec3 n = face_unit;
    if (corners != nullptr && corners[k] != glm::vec3(0.0f)) {
      // Normals are covectors: n_world = M^-T n_object, renormalised.
      const glm::dvec3 m = normal_matrix * glm::dvec3(corners[k]);
      const double length = glm::length(m);
      if (length > 0.0) n = m / length;
    }
    out[k].normal_world = glm::vec3(n);
  }
  if (surface.textures != nullptr) texture_vertices(inst, local, linear, det_sign, surface, out);
}

// Tangents (glTF 2.0, 3.7.2.1 TANGENT): the file's are vectors, t_world = M t, and their
// bitangent sign turns with a mirroring M (cross(M n, M t) = det(M) M^-T cross(n, t)).
// Without them, the triangle's own from the normal texture's UV set (world positions p_k,
// UVs (u_k, v_k)): with e1 = p1 - p0, e2 = p2 - p0 and the UV differences (du1, dv1),
// (du2, dv2), T = (e1 dv2 - e2 dv1) / r and B = (e2 du1 - e1 du2) / r, r = du1 dv2 - du2 dv1
// (Lengyel, "Computing Tangent Space Basis Vectors", 2001); w = sign((n x T) . B), with n the
// face normal.
void GeometryFrontEnd::texture_vertices(const MeshInstance& inst, std::size_t local,
                                        const glm::dmat3& linear, double det_sign,
                                        const SurfaceShading& surface, ShadeVertex out[3]) const {
  const MeshData& mesh = *inst.mesh;
  for (int set = 0; set < kMaxTexcoordSets; ++set) {
    const std::vector<glm::vec2>& uvs = mesh.corner_texcoords[set];
    for (int k = 0; k < 3; ++k) {
      out[k].uv[set] = uvs.empty() ? glm::vec2(0.0f) : uvs[local * 3 + std::size_t(k)];
    }
  }
  for (int k = 0; k < 3; ++k) out[k].tangent_world = glm::vec4(0.0f);
  // The tangent frame of the normal maps and of anisotropy (one frame serves them all),
  // computed from the UV set of the normal texture, else the clearcoat normal texture's, else
  // the anisotropy texture's, else set 0.
  const SurfaceTextures& slots = *surface.textures;
  const TextureSlot* normal_map = slots.normal != nullptr ? slots.normal : slots.clearcoat_normal;
  if (normal_map == nullptr && !surface.anisotropic()) return;
  if (!mesh.corner_tangents.empty()) {
    for (int k = 0; k < 3; ++k) {
      const glm::vec4& t = mesh.corner_tangents[local * 3 + std::size_t(k)];
      const glm::dvec3 t_world = linear * glm::dvec3(t);
      out[k].tangent_world = glm::vec4(glm::vec3(t_world), float(t.w * det_sign));
    }
    return;
  }
  const int set = normal_map != nullptr         ? normal_map->texcoord
                  : slots.anisotropy != nullptr ? slots.anisotropy->texcoord
                                                : 0;
  const glm::dvec3 e1 = glm::dvec3(out[1].position_world) - glm::dvec3(out[0].position_world);
  const glm::dvec3 e2 = glm::dvec3(out[2].position_world) - glm::dvec3(out[0].position_world);
  const glm::dvec2 d1 = glm::dvec2(out[1].uv[set]) - glm::dvec2(out[0].uv[set]);
  const glm::dvec2 d2 = glm::dvec2(out[2].uv[set]) - glm::dvec2(out[0].uv[set]);
  const double r = d1.x * d2.y - d2.x * d1.y;
  if (!(std::abs(r) > 0.0)) return;  // degenerate UVs: no tangent, no normal map
  const glm::dvec3 tangent = (e1 * d2.y - e2 * d1.y) / r;
  const glm::dvec3 bitangent = (e2 * d1.x - e1 * d2.x) / r;
  const glm::dvec3 face = glm::cross(e1, e2) * det_sign;
  const float w = glm::dot(glm::cross(face, tangent), bitangent) < 0.0 ? -1.0f : 1.0f;
  for (int k = 0; k < 3; ++k) out[k].tangent_world = glm::vec4(glm::vec3(tangent), w);
}

void GeometryFrontEnd::set_up_shading(const ShadeVertex* shade, const SurfaceShading& lit,
                                      const LazyShade* lazy, bool front, Sink& sink,
                                      TriangleSetup& t) const {
  // Computed only now, for triangles that survived every cull (half of a closed mesh's
  // are hidden back faces).
  ShadeVertex computed[3];
  if (lazy != nullptr) {
    shade_vertices(lazy->instance, lazy->local, *lazy->normal_matrix, *lazy->linear, lazy->det_sign,
                   lit, computed);
    shade = computed;
  }
  ShadingRecord& record = sink.shading->emplace_back();
  // A back face (the file's counter-clockwise front turned away: clockwise on screen, or
  // counter-clockwise under a mirroring model matrix) of a double-sided material is lit
  // from the viewer's side: its normals flip (glTF 2.0, 3.9.5 doubleSided).
  const float sign = lit.double_sided && front == sink.mirrored ? -1.0f : 1.0f;
  const ShadeVertex* ordered[3] = {&shade[0], front ? &shade[2] : &shade[1],
                                   front ? &shade[1] : &shade[2]};
  for (int k = 0; k < 3; ++k) {
    record.position_world[k] = ordered[k]->position_world;
    record.normal_world[k] = sign * ordered[k]->normal_world;
    record.vertex_alpha[k] = ordered[k]->alpha;
  }
  record.surface = &lit;
  record.textured = nullptr;
  if (lit.textures != nullptr) {
    // The tangent turns with the normal (xyz and the bitangent sign): the whole frame of a
    // back face is the front's mirrored, so its perturbed normal is the front's negated.
    TexturedCorners& corners = sink.textured->emplace_back();
    for (int k = 0; k < 3; ++k) {
      for (int set = 0; set < kMaxTexcoordSets; ++set) corners.uv[set][k] = ordered[k]->uv[set];
      corners.tangent_world[k] = sign * ordered[k]->tangent_world;
    }
    record.textured = &corners;
  }
  // A transmissive surface is a transparent layer: what is behind it must stay to show through.
  t.alpha_mode = lit.transmissive() ? AlphaMode::Blend : lit.alpha_mode;
  t.shading = &record;
  t.flat_color = false;
}

void GeometryFrontEnd::vertex_alphas(std::size_t instance, std::size_t local,
                                     ShadeVertex out[3]) const {
  const MeshData& mesh = *scene_.meshes[instance].mesh;
  const std::uint32_t* idx = mesh.indices.data() + local * 3;
  for (int k = 0; k < 3; ++k) {
    out[k].alpha = idx[k] < mesh.color_alphas.size() ? mesh.color_alphas[idx[k]] : 1.0f;
  }
}

}  // namespace covrast::detail
