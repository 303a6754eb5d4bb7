// Building a scene in code: make_mesh, add_instance, add_light and check_scene, the in-memory
// twins of what the scene file loader (scene_json.cpp) and the OBJ parser do, with the same
// rules and a one-line InputError for each broken one.
#include "scene/scene_internal.hpp"

#include <covrast/scene.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_set>
#include <utility>

namespace covrast {
namespace {

[[noreturn]] void fail(const std::string& what, const std::string& message) {
  throw InputError(what + ": " + message);
}

std::string text(const glm::dvec3& v) {
  // Appended piece by piece: g++ 12 -O3 warns (-Wrestrict, falsely) on "(" + std::string.
  std::string out = "(";
  out += std::to_string(v.x);
  out += ", ";
  out += std::to_string(v.y);
  out += ", ";
  out += std::to_string(v.z);
  out += ")";
  return out;
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
bool finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
bool in_unit_range(const glm::vec3& v) {
  return v.x >= 0.0f && v.x <= 1.0f && v.y >= 0.0f && v.y <= 1.0f && v.z >= 0.0f && v.z <= 1.0f;
}
bool non_negative(const glm::vec3& v) {
  return finite(v) && v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f;
}

/// Every level of a code-built texture holds the storage its size needs (TextureLevel::bytes;
/// sampling reads it unchecked).
bool levels_consistent(const Texture& texture) {
  for (const TextureLevel& level : texture.levels) {
    if (level.width <= 0 || level.height <= 0 ||
        level.rgba8.size() != TextureLevel::bytes(level.width, level.height)) {
      return false;
    }
  }
  return true;
}

/// The ranges a scene file's "material" keys accept (docs/scene-format.md).
void check_material(const Material& m, const std::string& what) {
  if (!(m.metallic >= 0.0f && m.metallic <= 1.0f)) fail(what, "metallic must be in 0..1");
  if (!(m.roughness >= 0.0f && m.roughness <= 1.0f)) fail(what, "roughness must be in 0..1");
  if (!(m.shininess >= 1e-3f && m.shininess <= 1e4f)) {
    fail(what, "shininess must be in 0.001..10000");
  }
  if (!non_negative(m.emissive_linear)) fail(what, "emissive must be finite and >= 0");
  if (!non_negative(m.specular_linear)) fail(what, "specular must be finite and >= 0");
  if (!(m.ior == 0.0f || (m.ior >= 1.0f && std::isfinite(m.ior)))) {
    fail(what, "ior must be 0 or a finite number >= 1");
  }
  if (!(m.specular_factor >= 0.0f && m.specular_factor <= 1.0f)) {
    fail(what, "specular_factor must be in 0..1");
  }
  if (!non_negative(m.specular_color_factor)) {
    fail(what, "specular_color_factor must be finite and >= 0");
  }
  if (!(m.clearcoat >= 0.0f && m.clearcoat <= 1.0f)) fail(what, "clearcoat must be in 0..1");
  for (int c = 0; c < 3; ++c) {
    if (!(m.sheen_color_factor[c] >= 0.0f && m.sheen_color_factor[c] <= 1.0f)) {
      fail(what, "sheen_color_factor must be in 0..1");
    }
  }
  if (!(m.sheen_roughness >= 0.0f && m.sheen_roughness <= 1.0f)) {
    fail(what, "sheen_roughness must be in 0..1");
  }
  if (!(m.iridescence >= 0.0f && m.iridescence <= 1.0f)) fail(what, "iridescence must be in 0..1");
  if (!(m.iridescence_ior >= 1.0f && std::isfinite(m.iridescence_ior))) {
    fail(what, "iridescence_ior must be a finite number >= 1");
  }
  if (!(m.iridescence_thickness_min_nm >= 0.0f && m.iridescence_thickness_max_nm >= 0.0f &&
        std::isfinite(m.iridescence_thickness_min_nm) &&
        std::isfinite(m.iridescence_thickness_max_nm))) {
    fail(what, "iridescence thicknesses must be finite and >= 0");
  }
  if (!(m.clearcoat_roughness >= 0.0f && m.clearcoat_roughness <= 1.0f)) {
    fail(what, "clearcoat_roughness must be in 0..1");
  }
  if (!(m.anisotropy >= 0.0f && m.anisotropy <= 1.0f)) fail(what, "anisotropy must be in 0..1");
  if (!std::isfinite(m.anisotropy_rotation)) fail(what, "anisotropy_rotation must be finite");
  for (const TextureSlot* slot : m.texture_slots()) {
    if (slot->texcoord < 0 || slot->texcoord >= kMaxTexcoordSets) {
      fail(what, "a texture's texcoord must be 0 or 1");
    }
    if (slot->texture && slot->texture->levels.empty()) fail(what, "a texture has no texels");
    if (slot->texture && !levels_consistent(*slot->texture)) {
      fail(what, "a texture level's texels do not match its size (TextureLevel::bytes)");
    }
    if (!std::isfinite(slot->scale)) fail(what, "a texture's scale must be finite");
  }
  if (!(m.alpha_cutoff >= 0.0 && m.alpha_cutoff <= 1.0)) fail(what, "alpha_cutoff must be in 0..1");
  if (!(m.base_alpha >= 0.0 && m.base_alpha <= 1.0)) fail(what, "base_alpha must be in 0..1");
}

/// Finite, with the last row (0, 0, 0, 1): model[col][row] in GLM.
void check_model(const glm::dmat4& model, const std::string& what) {
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(model[c][r])) fail(what, "model matrix entries must be finite");
    }
  }
  if (model[0][3] != 0.0 || model[1][3] != 0.0 || model[2][3] != 0.0 || model[3][3] != 1.0) {
    fail(what, "model matrix: last row must be (0, 0, 0, 1) (affine transform)");
  }
}

/// The same rules as a scene file's "camera" (scene_json.cpp).
void check_camera(const Camera& camera) {
  if (!finite(camera.eye) || !finite(camera.target) || !finite(camera.up)) {
    fail("camera", "eye, target and up must be finite");
  }
  if (camera.orthographic) {
    if (!(camera.ymag > 0.0 && std::isfinite(camera.ymag))) {
      fail("camera.ymag", "must be > 0, got " + std::to_string(camera.ymag));
    }
    if (!(camera.near >= 0.0 && std::isfinite(camera.near))) {
      fail("camera.near", "must be >= 0, got " + std::to_string(camera.near));
    }
  } else {
    if (!(camera.fovy_deg > 0.0 && camera.fovy_deg < 180.0)) {
      fail("camera.fovy_deg",
           "must be in (0, 180) degrees, got " + std::to_string(camera.fovy_deg));
    }
    if (!(camera.near > 0.0 && std::isfinite(camera.near))) {
      fail("camera.near", "must be > 0, got " + std::to_string(camera.near));
    }
  }
  if (!(camera.far > camera.near && std::isfinite(camera.far))) {
    fail("camera.far", "must be greater than near, got " + std::to_string(camera.far));
  }
  const glm::dvec3 view = camera.target - camera.eye;
  if (view == glm::dvec3(0.0)) fail("camera", "eye and target must differ");
  // Parallel when sin(angle(view, up)) = |view x up| / (|view| |up|) is (nearly) zero.
  const double up_length = glm::length(camera.up);
  if (!(up_length > 0.0) ||
      !(glm::length(glm::cross(view, camera.up)) > 1e-6 * glm::length(view) * up_length)) {
    fail("camera.up", "must not be zero or parallel to the view direction, got " + text(camera.up));
  }
}

/// The array invariants the renderer relies on (make_mesh establishes them).
void check_mesh_arrays(const MeshData& mesh, const std::string& what) {
  if (mesh.indices.size() % 3 != 0) {
    fail(what, std::to_string(mesh.indices.size()) + " indices, not a multiple of 3");
  }
  for (std::size_t i = 0; i < mesh.indices.size(); ++i) {
    if (mesh.indices[i] >= mesh.positions.size()) {
      fail(what, "indices[" + std::to_string(i) + "] = " + std::to_string(mesh.indices[i]) +
                     " out of range (" + std::to_string(mesh.positions.size()) + " positions)");
    }
  }
  if (!mesh.colors_linear.empty() && mesh.colors_linear.size() != mesh.positions.size()) {
    fail(what, std::to_string(mesh.colors_linear.size()) + " colours for " +
                   std::to_string(mesh.positions.size()) + " positions");
  }
  if (!mesh.color_alphas.empty() && mesh.color_alphas.size() != mesh.positions.size()) {
    fail(what, std::to_string(mesh.color_alphas.size()) + " vertex alphas for " +
                   std::to_string(mesh.positions.size()) + " positions");
  }
  if (!mesh.corner_normals.empty() && mesh.corner_normals.size() != mesh.indices.size()) {
    fail(what, std::to_string(mesh.corner_normals.size()) + " corner normals for " +
                   std::to_string(mesh.indices.size()) + " indices (3 per triangle)");
  }
  for (int set = 0; set < kMaxTexcoordSets; ++set) {
    const std::size_t uvs = mesh.corner_texcoords[set].size();
    if (uvs != 0 && uvs != mesh.indices.size()) {
      fail(what, std::to_string(uvs) + " corner UVs of set " + std::to_string(set) + " for " +
                     std::to_string(mesh.indices.size()) + " indices (3 per triangle)");
    }
  }
  if (!mesh.corner_tangents.empty() && mesh.corner_tangents.size() != mesh.indices.size()) {
    fail(what, std::to_string(mesh.corner_tangents.size()) + " corner tangents for " +
                   std::to_string(mesh.indices.size()) + " indices (3 per triangle)");
  }
  if (!mesh.triangle_materials.empty()) {
    if (mesh.triangle_materials.size() != mesh.triangle_count()) {
      fail(what, std::to_string(mesh.triangle_materials.size()) + " triangle materials for " +
                     std::to_string(mesh.triangle_count()) + " triangles");
    }
    for (std::size_t t = 0; t < mesh.triangle_materials.size(); ++t) {
      if (mesh.triangle_materials[t] >= mesh.materials.size()) {
        fail(what, "triangle_materials[" + std::to_string(t) +
                       "] = " + std::to_string(mesh.triangle_materials[t]) + " out of range (" +
                       std::to_string(mesh.materials.size()) + " materials)");
      }
    }
  }
}

}  // namespace

std::shared_ptr<const MeshData> make_mesh(MeshArrays arrays) {
  const std::string& name = arrays.name;
  auto mesh = std::make_shared<MeshData>();
  mesh->source = name;
  for (std::size_t i = 0; i < arrays.positions.size(); ++i) {
    if (!finite(arrays.positions[i])) {
      fail(name, "positions[" + std::to_string(i) + "] is not finite");
    }
  }
  if (!arrays.colors_srgb.empty()) {
    if (arrays.colors_srgb.size() != arrays.positions.size()) {
      fail(name, std::to_string(arrays.colors_srgb.size()) + " colours for " +
                     std::to_string(arrays.positions.size()) + " positions");
    }
    mesh->colors_linear.reserve(arrays.colors_srgb.size());
    for (std::size_t i = 0; i < arrays.colors_srgb.size(); ++i) {
      const glm::vec3& c = arrays.colors_srgb[i];
      if (!in_unit_range(c)) fail(name, "colors_srgb[" + std::to_string(i) + "] not in 0..1");
      mesh->colors_linear.emplace_back(srgb_to_linear(c.r), srgb_to_linear(c.g),
                                       srgb_to_linear(c.b));
    }
  }
  for (std::size_t i = 0; i < arrays.alphas.size(); ++i) {
    if (!(arrays.alphas[i] >= 0.0f && arrays.alphas[i] <= 1.0f)) {
      fail(name, "alphas[" + std::to_string(i) + "] not in 0..1");
    }
  }
  mesh->color_alphas = std::move(arrays.alphas);
  for (std::size_t i = 0; i < arrays.corner_normals.size(); ++i) {
    if (!finite(arrays.corner_normals[i])) {
      fail(name, "corner_normals[" + std::to_string(i) + "] is not finite");
    }
  }
  for (const std::vector<glm::vec2>* uvs : {&arrays.corner_texcoords, &arrays.corner_texcoords1}) {
    for (std::size_t i = 0; i < uvs->size(); ++i) {
      if (!std::isfinite((*uvs)[i].x) || !std::isfinite((*uvs)[i].y)) {
        fail(name, "corner_texcoords[" + std::to_string(i) + "] is not finite");
      }
    }
  }
  for (std::size_t m = 0; m < arrays.materials.size(); ++m) {
    check_material(arrays.materials[m], name + ": materials[" + std::to_string(m) + "]");
  }
  mesh->positions = std::move(arrays.positions);
  mesh->indices = std::move(arrays.indices);
  mesh->corner_normals = std::move(arrays.corner_normals);
  mesh->corner_texcoords[0] = std::move(arrays.corner_texcoords);
  mesh->corner_texcoords[1] = std::move(arrays.corner_texcoords1);
  mesh->materials = std::move(arrays.materials);
  mesh->triangle_materials = std::move(arrays.triangle_materials);
  check_mesh_arrays(*mesh, name);
  analyze_mesh_topology(*mesh);
  return mesh;
}

MeshInstance& add_instance(Scene& scene, std::shared_ptr<const MeshData> mesh,
                           const InstanceDesc& desc) {
  if (!mesh) throw InputError("add_instance: no mesh");
  const std::string& name = mesh->source;
  check_model(desc.model, name);
  MeshInstance instance;
  instance.model = desc.model;
  // The colour selection of scene_json.cpp's select_color.
  if (desc.per_triangle_colors) {
    if (desc.color_srgb) fail(name, "give either color_srgb or per_triangle_colors, not both");
    instance.color_source = ColorSource::PerTriangle;
  } else if (desc.color_srgb) {
    const glm::vec3& c = *desc.color_srgb;
    if (!in_unit_range(c)) fail(name, "color_srgb not in 0..1");
    instance.color_linear =
        glm::vec3(srgb_to_linear(c.r), srgb_to_linear(c.g), srgb_to_linear(c.b));
  } else if (!mesh->colors_linear.empty()) {
    instance.color_source = ColorSource::Vertex;
  }
  // One material per mesh material, or one Lambert default (instance_materials there).
  const std::size_t material_count = std::max<std::size_t>(1, mesh->materials.size());
  if (desc.material) {
    check_material(*desc.material, name + ": material");
    instance.materials.assign(material_count, *desc.material);
  } else if (!mesh->materials.empty()) {
    instance.materials = mesh->materials;
  } else {
    Material lambert;
    lambert.model = ShadingModel::Lambert;
    instance.materials.push_back(lambert);
  }
  // Normals (select_normals there).
  const bool has_normals = !mesh->corner_normals.empty();
  instance.normals = desc.normals.value_or(has_normals ? NormalSource::File : NormalSource::Flat);
  if (instance.normals == NormalSource::File) {
    if (!has_normals) fail(name, "normals: File, but the mesh has no corner normals");
    // Aliasing: shares ownership of the mesh, points at its normals (no copy).
    instance.corner_normals =
        std::shared_ptr<const std::vector<glm::vec3>>(mesh, &mesh->corner_normals);
  } else if (instance.normals == NormalSource::Smooth) {
    instance.corner_normals =
        std::make_shared<const std::vector<glm::vec3>>(smooth_corner_normals(*mesh));
  }
  instance.mesh = std::move(mesh);
  return scene.meshes.emplace_back(std::move(instance));
}

void add_light(Scene& scene, Light light) {
  const std::string what = "lights[" + std::to_string(scene.lights.size()) + "]";
  if (!non_negative(light.color_linear)) fail(what, "colour must be finite and >= 0");
  if (!(light.intensity >= 0.0 && std::isfinite(light.intensity))) {
    fail(what, "intensity must be finite and >= 0");
  }
  if (light.type == LightType::Directional || light.type == LightType::Spot) {
    const double length = glm::length(light.direction);
    if (!(length > 0.0) || !std::isfinite(length)) fail(what, "direction must not be zero");
    light.direction /= length;
  }
  if (light.type == LightType::Point || light.type == LightType::Spot) {
    if (!finite(light.position)) fail(what, "position must be finite");
    if (!(light.range >= 0.0 && std::isfinite(light.range))) {
      fail(what, "range must be 0 (infinite) or > 0");
    }
  }
  if (light.type == LightType::Spot &&
      !(light.inner_cone_deg >= 0.0 && light.inner_cone_deg < light.outer_cone_deg &&
        light.outer_cone_deg <= 90.0)) {
    fail(what, "cone angles must satisfy 0 <= inner < outer <= 90 degrees");
  }
  scene.lit = true;
  scene.lights.push_back(light);
}

namespace {

/// An environment as load_environment makes one: a map of W x H finite texels >= 0 within the
/// limits, a finite rotation, a finite intensity >= 0.
void check_environment(const EnvironmentLight& light) {
  if (!light.map) fail("environment", "no map");
  const EnvironmentMap& map = *light.map;
  if (map.width < 1 || map.height < 1 || map.width > kMaxEnvironmentSide ||
      map.height > kMaxEnvironmentSide ||
      std::uint64_t(map.width) * std::uint64_t(map.height) > kMaxEnvironmentTexels ||
      map.radiance_linear.size() != std::size_t(map.width) * std::size_t(map.height)) {
    fail("environment", "map of " + std::to_string(map.width) + "x" + std::to_string(map.height) +
                            " with " + std::to_string(map.radiance_linear.size()) +
                            " texels: sides 1.." + std::to_string(kMaxEnvironmentSide) +
                            ", width x height texels");
  }
  for (const glm::vec3& t : map.radiance_linear) {
    if (!(t.r >= 0.0f && t.g >= 0.0f && t.b >= 0.0f) || !std::isfinite(t.r) ||
        !std::isfinite(t.g) || !std::isfinite(t.b)) {
      fail("environment", "texels must be finite and >= 0");
    }
  }
  if (!std::isfinite(light.rotation_deg)) fail("environment", "rotation must be finite");
  if (!(light.intensity >= 0.0) || !std::isfinite(light.intensity)) {
    fail("environment", "intensity must be a finite number >= 0");
  }
}

}  // namespace

void check_scene(const Scene& scene) {
  if (scene.width < 1 || scene.width > kMaxImageSide || scene.height < 1 ||
      scene.height > kMaxImageSide) {
    fail("scene", "size " + std::to_string(scene.width) + "x" + std::to_string(scene.height) +
                      " out of range: each side must be 1.." + std::to_string(kMaxImageSide));
  }
  if (!in_unit_range(scene.background_linear)) fail("background", "must be in 0..1");
  check_camera(scene.camera);
  if (!(scene.exposure > 0.0) || !std::isfinite(scene.exposure)) {
    fail("exposure", "must be a finite number > 0");
  }
  if (scene.environment) check_environment(*scene.environment);
  if (scene.background_kind == BackgroundKind::Skybox && !scene.environment) {
    fail("background", "a skybox needs an environment");
  }
  std::unordered_set<const MeshData*> analysis_checked;  // once per mesh, not per instance
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const MeshInstance& instance = scene.meshes[i];
    const std::string what = "meshes[" + std::to_string(i) + "]";
    if (!instance.mesh) fail(what, "no mesh");
    const MeshData& mesh = *instance.mesh;
    check_mesh_arrays(mesh, what + " (" + mesh.source + ")");
    if (analysis_checked.insert(&mesh).second && !detail::mesh_topology_is_current(mesh)) {
      fail(what + " (" + mesh.source + ")",
           "its positions or indices changed after analyze_mesh_topology (closed_orientation, "
           "convex or bounds no longer hold): call analyze_mesh_topology again");
    }
    check_model(instance.model, what);
    // Empty: one Material{} (MeshInstance::materials).
    if (!instance.materials.empty() &&
        instance.materials.size() != std::max<std::size_t>(1, mesh.materials.size())) {
      fail(what, std::to_string(instance.materials.size()) + " materials, the mesh needs " +
                     std::to_string(std::max<std::size_t>(1, mesh.materials.size())));
    }
    if (instance.color_source == ColorSource::Vertex && mesh.colors_linear.empty()) {
      fail(what, "vertex colours, but the mesh has none");
    }
    // No corner normals: each triangle's face normal, whatever `normals` says (MeshInstance).
    if (instance.corner_normals && instance.corner_normals->size() != mesh.indices.size()) {
      fail(what, "corner normals not 3 per triangle");
    }
  }
}

}  // namespace covrast
