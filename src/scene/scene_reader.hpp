// Scene file loader, what its parts share (scene_json.cpp reads the document and calls the
// others): SceneReader, which reads the format's values and checks each one, the mesh files a
// scene names and one scene's view of them, and the camera, lights and environment taken
// from keys or from the scene's glTF files. Private to the scene stage.
#pragma once

#include "scene/scene_internal.hpp"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace covrast::detail {

using nlohmann::json;

/// Throws InputError("file: key: message") (scene_values.cpp).
[[noreturn]] void fail(const std::string& file, const std::string& key, const std::string& message);

/// A JSON value shortened for a one-line message (scene_values.cpp).
std::string shown(const json& value);

/// Reads the values of the scene format, checking each with a one-line InputError that names
/// the file and the JSON key.
class SceneReader {
 public:
  explicit SceneReader(std::string file) : file_(std::move(file)) {}

  // Numbers, vectors, colours and matrices: scene_values.cpp.
  const json& required(const json& object, const char* key, const std::string& path) const;
  const json& require_object(const json& value, const std::string& path) const;
  double number(const json& value, const std::string& path) const;
  double number_in(const json& value, const std::string& path, double lo, double hi) const;
  int image_side(const json& root, const char* key) const;
  glm::dvec3 vec3(const json& value, const std::string& path) const;
  glm::vec3 srgb_color(const json& value, const std::string& path) const;
  glm::vec3 linear_color(const json& value, const std::string& path) const;
  glm::dvec3 direction(const json& value, const std::string& path) const;
  glm::dmat4 model_matrix(const json& value, const std::string& path) const;

  // The camera and lights: scene_camera_lights.cpp.
  Camera camera(const json& root) const;
  void projection(const json& object, Camera& camera) const;
  Light light(const json& value, const std::string& key) const;
  void spot_cone(const json& object, const std::string& key, Light& light) const;
  std::vector<Light> lights(const json& value, std::optional<std::size_t>& gltf_at) const;

  // Materials: scene_materials.cpp.
  ShadingModel shading_model(const json& value, const std::string& path) const;
  void apply_material_extensions(const json& object, const std::string& key, Material& m) const;
  void apply_material(const json& object, const std::string& key, Material& m) const;
  AlphaMode alpha_mode(const json& value, const std::string& path) const;

  // Normals: scene_meshes.cpp.
  NormalSource normal_source(const json& value, const std::string& path) const;

 private:
  static std::string number_text(double x);

  std::string file_;
};

enum class MeshFormat { Obj, Gltf };

struct CachedMesh {
  detail::LoadedMesh loaded;
  /// The file's corner normals, shared by the instances that use them; the smoothed ones,
  /// computed on first request.
  std::shared_ptr<const std::vector<glm::vec3>> file_normals;
  std::shared_ptr<const std::vector<glm::vec3>> smooth_normals;
};

/// The scene's mesh files, each read and parsed once however many instances name it
/// (instancing: one load per canonical path and format).
using MeshFiles = std::map<std::pair<std::string, MeshFormat>, CachedMesh>;

/// The mesh file an entry of "meshes" names: its format and its path as written.
struct MeshFileRef {
  MeshFormat format;
  std::string relative;
};

/// One scene's view of a MeshFileCache: loads each file on its first use in any scene, and
/// passes each file's warnings to this scene on its first use here (scene_meshes.cpp).
class SceneMeshes {
 public:
  /// `pose`: the moment glTF files are posed at (null: their static pose).
  SceneMeshes(const std::string& file, std::filesystem::path base_dir,
              std::map<std::pair<std::string, MeshFormat>, CachedMesh>& files,
              const AnimationTime* pose)
      : file_(file), base_dir_(std::move(base_dir)), files_(files), pose_(pose) {}

  /// The mesh that entry `key` names, drawn with material variant `variant` (empty: none).
  CachedMesh& get(const MeshFileRef& ref, const std::string& key, Scene& scene,
                  const std::string& variant);

 private:
  static void add_warnings(const std::filesystem::path& full, const detail::LoadedMesh& loaded,
                           Scene& scene);
  detail::LoadedMesh load(const std::filesystem::path& full, const MeshFileRef& ref,
                          const std::string& key, const std::string& variant) const;

  const std::string& file_;
  std::filesystem::path base_dir_;
  std::map<std::pair<std::string, MeshFormat>, CachedMesh>& files_;
  const AnimationTime* pose_;
  std::set<std::pair<std::string, MeshFormat>> warned_;
};

/// The scene's first glTF mesh entry: where a {"gltf": N} camera comes from.
struct FirstGltf {
  const detail::LoadedMesh* loaded = nullptr;  ///< null: no glTF mesh (yet)
  std::string relative;                        ///< the file as the scene names it
  glm::dmat4 model{1.0};                       ///< the entry's model matrix
  /// Every glTF entry (file and model matrix), where "lights": "gltf" takes lights from.
  std::vector<std::pair<const detail::LoadedMesh*, glm::dmat4>> all;
};

// scene_meshes.cpp
MeshInstance load_instance(const SceneReader& reader, const std::string& file, const json& value,
                           const std::string& key, SceneMeshes& cache, Scene& scene,
                           FirstGltf& first_gltf);

// scene_materials.cpp
std::vector<Material> instance_materials(const SceneReader& reader, const json& entry,
                                         const std::string& key, const MeshData& mesh);

// scene_camera_lights.cpp
Camera gltf_camera(const std::string& file, const json& object, const FirstGltf& first,
                   const Scene& scene);
void warn_beyond_finite_range(Scene& scene);
/// A warning for every lit instance with a KHR_materials_anisotropy material (pbr, strength >
/// 0) whose mesh has neither tangents nor UVs: no tangent frame, so it is drawn isotropic.
void warn_anisotropy_without_tangents(Scene& scene);
std::vector<Light> gltf_lights(const std::string& file, const FirstGltf& gltf);
EnvironmentLight scene_environment(const std::string& file, const json& value,
                                   const std::filesystem::path& base_dir,
                                   std::vector<std::string>& warnings);

}  // namespace covrast::detail
