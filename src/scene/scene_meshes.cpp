// Scene file loader, meshes and instances: an entry of "meshes" names its mesh file, which is
// loaded once however many instances name it (SceneMeshes, scene_reader.hpp), and gives the
// instance's colour selection, model matrix, materials and normals.
#include "scene/scene_reader.hpp"

#include <algorithm>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>

namespace covrast::detail {

NormalSource SceneReader::normal_source(const json& value, const std::string& path) const {
  if (value == "file") return NormalSource::File;
  if (value == "flat") return NormalSource::Flat;
  if (value == "smooth") return NormalSource::Smooth;
  fail(file_, path, "expected \"file\", \"flat\" or \"smooth\", got " + shown(value));
}

namespace {

/// NormalSource and the corner normals that go with it.
void select_normals(const SceneReader& reader, const std::string& file, const json& entry,
                    const std::string& key, const std::string& relative, CachedMesh& cached,
                    MeshInstance& instance) {
  const MeshData& mesh = *cached.loaded.data;
  const bool has_normals = !mesh.corner_normals.empty();
  instance.normals = has_normals ? NormalSource::File : NormalSource::Flat;
  if (const auto it = entry.find("normals"); it != entry.end()) {
    instance.normals = reader.normal_source(*it, key + ".normals");
    if (instance.normals == NormalSource::File && !has_normals) {
      fail(file, key + ".normals", "\"file\" but '" + relative + "' has no normals");
    }
  }
  if (instance.normals == NormalSource::File) {
    if (!cached.file_normals) {
      // Aliasing: shares ownership of the mesh, points at its normals (no copy).
      cached.file_normals = std::shared_ptr<const std::vector<glm::vec3>>(
          cached.loaded.data, &cached.loaded.data->corner_normals);
    }
    instance.corner_normals = cached.file_normals;
  } else if (instance.normals == NormalSource::Smooth) {
    if (!cached.smooth_normals) {
      cached.smooth_normals =
          std::make_shared<const std::vector<glm::vec3>>(smooth_corner_normals(mesh));
    }
    instance.corner_normals = cached.smooth_normals;
  }
}

/// Exactly one of "obj" and "gltf", a non-empty path string.
MeshFileRef mesh_file_ref(const std::string& file, const json& entry, const std::string& key) {
  const auto obj_it = entry.find("obj");
  const auto gltf_it = entry.find("gltf");
  if (obj_it != entry.end() && gltf_it != entry.end()) {
    fail(file, key, "give either \"obj\" or \"gltf\", not both");
  }
  if (obj_it == entry.end() && gltf_it == entry.end()) {
    fail(file, key, "needs \"obj\" or \"gltf\" (a mesh file path)");
  }
  const MeshFormat format = obj_it != entry.end() ? MeshFormat::Obj : MeshFormat::Gltf;
  const json& path_value = format == MeshFormat::Obj ? *obj_it : *gltf_it;
  const std::string path_key = key + (format == MeshFormat::Obj ? ".obj" : ".gltf");
  if (!path_value.is_string() || path_value.get<std::string>().empty()) {
    fail(file, path_key, "expected a file path string, got " + shown(path_value));
  }
  // "\u0000" would otherwise quietly name the path before it.
  if (path_value.get<std::string>().find('\0') != std::string::npos) {
    fail(file, path_key, "the path contains a NUL byte (\\u0000)");
  }
  return {format, path_value.get<std::string>()};
}

/// The instance's colour selection: "color" or material.base_color (not both), else the
/// file's vertex colours, else the file's uniform colour (glTF), else the default.
void select_color(const SceneReader& reader, const std::string& file, const json& entry,
                  const std::string& key, const std::string& relative,
                  const detail::LoadedMesh& loaded, MeshInstance& instance) {
  const bool has_vertex_colors = !loaded.data->colors_linear.empty();
  // material.base_color is the same as "color": [r,g,b] (the base colour of a lit mesh is
  // its colour selection).
  const json* base_color = nullptr;
  if (const auto it = entry.find("material"); it != entry.end() && it->is_object()) {
    if (const auto bit = it->find("base_color"); bit != it->end()) base_color = &*bit;
  }
  const auto color_it = entry.find("color");
  if (base_color != nullptr && color_it != entry.end()) {
    fail(file, key + ".material.base_color", "give either it or \"color\", not both");
  }
  if (base_color != nullptr) {
    instance.color_linear = reader.srgb_color(*base_color, key + ".material.base_color");
  } else if (color_it != entry.end()) {
    const json& color = *color_it;
    const std::string color_key = key + ".color";
    if (color.is_array()) {
      instance.color_source = ColorSource::Uniform;
      instance.color_linear = reader.srgb_color(color, color_key);
    } else if (color.is_string() && color.get<std::string>() == "per_triangle") {
      instance.color_source = ColorSource::PerTriangle;
    } else if (color.is_string() && color.get<std::string>() == "vertex") {
      if (!has_vertex_colors) {
        fail(file, color_key, "\"vertex\" but '" + relative + "' has no vertex colours");
      }
      instance.color_source = ColorSource::Vertex;
    } else {
      fail(file, color_key,
           "expected [r,g,b], \"per_triangle\" or \"vertex\", got " + shown(color));
    }
  } else if (has_vertex_colors) {
    instance.color_source = ColorSource::Vertex;
  } else if (loaded.has_uniform_color) {
    instance.color_linear = loaded.uniform_color_linear;
  }
}

}  // namespace

CachedMesh& SceneMeshes::get(const MeshFileRef& ref, const std::string& key, Scene& scene,
                             const std::string& variant) {
  const std::filesystem::path full = base_dir_ / std::filesystem::path(ref.relative);
  std::error_code ec;
  const std::filesystem::path canonical = std::filesystem::canonical(full, ec);
  if (ec) fail(file_, key, "cannot open '" + ref.relative + "': " + ec.message());
  // A glTF file posed at a moment of an animation is another mesh than its static pose.
  std::string id_path = canonical.string();
  if (pose_ != nullptr && ref.format == MeshFormat::Gltf) {
    std::ostringstream moment;
    moment.precision(17);
    moment << '\n' << pose_->index << '\n' << pose_->name << '\n' << pose_->time_s;
    id_path += moment.str();
  }
  if (!variant.empty()) id_path += "\nvariant " + variant;  // another mesh, too
  const auto id = std::make_pair(id_path, ref.format);
  auto cached = files_.find(id);
  if (cached == files_.end()) {
    CachedMesh loaded_mesh;
    loaded_mesh.loaded = load(full, ref, key, variant);
    cached = files_.emplace(id, std::move(loaded_mesh)).first;
  }
  if (warned_.insert(id).second) add_warnings(full, cached->second.loaded, scene);
  return cached->second;
}

/// The file's warnings (the lit ones only when the scene is lit), once per scene.
void SceneMeshes::add_warnings(const std::filesystem::path& full, const detail::LoadedMesh& loaded,
                               Scene& scene) {
  if (loaded.dropped_nonfinite_triangles > 0) {
    scene.warnings.push_back(full.lexically_normal().string() + ": dropped " +
                             std::to_string(loaded.dropped_nonfinite_triangles) +
                             " triangles with NaN/Inf coordinates");
  }
  for (const std::string& warning : loaded.warnings) scene.warnings.push_back(warning);
  for (const std::string& extension : loaded.extensions_used) {
    auto& used = scene.gltf_extensions_used;
    const auto at = std::lower_bound(used.begin(), used.end(), extension);
    if (at == used.end() || *at != extension) used.insert(at, extension);
  }
  // Nothing loads as empty without a word (a file of the wrong kind, wrong JSON types).
  if (loaded.data->triangle_count() == 0) {
    scene.warnings.push_back(full.lexically_normal().string() +
                             ": no triangles: the mesh draws nothing");
  }
  if (scene.lit) {
    for (const std::string& warning : loaded.lit_warnings) scene.warnings.push_back(warning);
  }
}

detail::LoadedMesh SceneMeshes::load(const std::filesystem::path& full, const MeshFileRef& ref,
                                     const std::string& key, const std::string& variant) const {
  std::string bytes;
  std::string error;
  if (!detail::read_whole_file(full, bytes, error)) {
    fail(file_, key, "cannot open '" + ref.relative + "': " + error);
  }
  const std::string display = full.lexically_normal().string();
  return ref.format == MeshFormat::Obj
             ? detail::parse_obj(bytes, display, full.parent_path())
             : detail::parse_gltf(bytes, display, full.parent_path(), pose_, variant);
}

/// Entry `key` of "meshes": its mesh (loaded through `cache`), colour, model matrix,
/// materials and normals. The first glTF entry is noted in `first_gltf`.
MeshInstance load_instance(const SceneReader& reader, const std::string& file, const json& value,
                           const std::string& key, SceneMeshes& cache, Scene& scene,
                           FirstGltf& first_gltf) {
  const json& entry = reader.require_object(value, key);
  const MeshFileRef ref = mesh_file_ref(file, entry, key);
  std::string variant;
  if (const auto it = entry.find("variant"); it != entry.end()) {
    if (!it->is_string() || it->get<std::string>().empty()) {
      fail(file, key + ".variant", "expected a material variant name, got " + shown(*it));
    }
    if (ref.format != MeshFormat::Gltf) {
      fail(file, key + ".variant", "only glTF files have material variants");
    }
    variant = it->get<std::string>();
  }
  CachedMesh& cached = cache.get(ref, key, scene, variant);
  const detail::LoadedMesh& loaded = cached.loaded;
  // Counted per instance: each instance would have drawn the dropped triangles.
  scene.dropped_nonfinite_triangles += loaded.dropped_nonfinite_triangles;

  MeshInstance instance;
  instance.mesh = loaded.data;
  select_color(reader, file, entry, key, ref.relative, loaded, instance);
  if (const auto model_it = entry.find("model"); model_it != entry.end()) {
    instance.model = reader.model_matrix(*model_it, key + ".model");
  }
  instance.materials = instance_materials(reader, entry, key, *loaded.data);
  select_normals(reader, file, entry, key, ref.relative, cached, instance);
  if (ref.format == MeshFormat::Gltf && first_gltf.loaded == nullptr) {
    first_gltf = {&loaded, ref.relative, instance.model, {}};
  }
  if (ref.format == MeshFormat::Gltf) first_gltf.all.emplace_back(&loaded, instance.model);
  return instance;
}

void warn_anisotropy_without_tangents(Scene& scene) {
  if (!scene.lit) return;
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const MeshInstance& instance = scene.meshes[i];
    const MeshData& mesh = *instance.mesh;
    bool has_uvs = false;
    for (const auto& set : mesh.corner_texcoords) has_uvs = has_uvs || !set.empty();
    if (!mesh.corner_tangents.empty() || has_uvs) continue;
    for (const Material& m : instance.materials) {
      if (m.model != ShadingModel::Pbr || !(m.anisotropy > 0.0f)) continue;
      scene.warnings.push_back(scene.source.string() + ": meshes[" + std::to_string(i) +
                               "]: anisotropy needs a tangent frame (tangents, or UVs to "
                               "compute them from) and the mesh has none: drawn isotropic");
      break;
    }
  }
}

}  // namespace covrast::detail
