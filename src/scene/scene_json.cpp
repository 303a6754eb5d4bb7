// Scene file loader: parses the JSON scene format (docs/scene-format.md), validates every field
// with a one-line InputError naming the file and the JSON key, converts sRGB display colours to
// linear light, and loads each mesh file once however many instances name it.
//
// This file reads the document: the file's JSON (with its position in parse errors), the
// top-level keys in order, the choices that replace some of them (animation, time, material
// variant), and the entry points (load_scene, load_mesh_scene). The values are read in
// scene_values.cpp, the camera, lights and environment in scene_camera_lights.cpp, materials
// in scene_materials.cpp, meshes and their instances in scene_meshes.cpp (scene_reader.hpp).
#include "scene/gltf_animation.hpp"
#include "scene/scene_internal.hpp"
#include "scene/scene_keys.hpp"
#include "scene/scene_reader.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string_view>
#include <utility>

namespace covrast {
namespace {

using nlohmann::json;

using detail::CachedMesh;
using detail::fail;
using detail::FirstGltf;
using detail::gltf_camera;
using detail::gltf_lights;
using detail::load_instance;
using detail::MeshFiles;
using detail::MeshFormat;
using detail::scene_environment;
using detail::SceneMeshes;
using detail::SceneReader;
using detail::shown;
using detail::warn_anisotropy_without_tangents;
using detail::warn_beyond_finite_range;

/// 1-based line and column of byte `offset` (columns count bytes, like nlohmann's).
std::pair<std::size_t, std::size_t> line_column(std::string_view text, std::size_t offset) {
  offset = std::min(offset, text.size());
  std::size_t line = 1;
  std::size_t line_start = 0;
  for (std::size_t i = 0; i < offset; ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  }
  return {line, offset - line_start + 1};
}

/// nlohmann's message without its "[json.exception.KIND.NNN] " prefix.
std::string exception_detail(const json::exception& e) {
  std::string text = e.what();
  if (text.rfind("[json.exception.", 0) == 0) {
    if (const std::size_t end = text.find("] "); end != std::string::npos) text.erase(0, end + 2);
  }
  return text;
}

json parse_json(const std::string& text, const std::string& file) {
  // Bounded before parsing: messages print values recursively (shown()).
  if (std::size_t offset = 0; !detail::json_depth_within(text, kMaxJsonDepth, offset)) {
    const auto [line, column] = line_column(text, offset);
    throw InputError(file + ":" + std::to_string(line) + ":" + std::to_string(column) +
                     ": arrays and objects nested deeper than " + std::to_string(kMaxJsonDepth) +
                     " levels");
  }
  try {
    // Comments (// and /* */) are accepted as an extension; they change no meaning.
    return json::parse(text, nullptr, true, true);
  } catch (const json::out_of_range& e) {
    // A number beyond double's range ("1e400"): out_of_range.406, without a position (found
    // by tests/fuzz, fuzz_scene_json, and by the bad-input corpus).
    std::string detail = exception_detail(e);
    for (char& c : detail) {
      const auto byte = static_cast<unsigned char>(c);
      if (byte < 0x20 || byte >= 0x7f) c = '?';
    }
    throw InputError(file + ": " + detail);
  } catch (const json::parse_error& e) {
    // e.byte counts the bytes read including the offending one, so it sits at e.byte - 1.
    const std::size_t offset = e.byte > 0 ? e.byte - 1 : 0;
    const auto [line, column] = line_column(text, offset);
    // nlohmann's text is "[json.exception.parse_error.101] parse error at line L, column C:
    // <detail>"; keep only the detail, the position is ours.
    std::string detail = e.what();
    if (const std::size_t at = detail.find(", column "); at != std::string::npos) {
      if (const std::size_t colon = detail.find(": ", at); colon != std::string::npos) {
        detail = detail.substr(colon + 2);
      }
    }
    // The detail quotes what was read, which may be control bytes or broken UTF-8.
    for (char& c : detail) {
      const auto byte = static_cast<unsigned char>(c);
      if (byte < 0x20 || byte >= 0x7f) c = '?';
    }
    throw InputError(file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " +
                     detail);
  }
}

}  // namespace

/// The loaded mesh files, by canonical path and format.
struct MeshFileCache::Impl {
  std::map<std::pair<std::string, MeshFormat>, CachedMesh> files;
};

MeshFileCache::MeshFileCache() : impl_(std::make_unique<Impl>()) {}
MeshFileCache::~MeshFileCache() = default;
std::size_t MeshFileCache::files_loaded() const { return impl_->files.size(); }

namespace {

/// The scene file's top-level JSON object.
json read_scene_root(const std::filesystem::path& json_path, const std::string& file) {
  std::string text;
  std::string error;
  if (!detail::read_whole_file(json_path, text, error, kMaxSceneFileBytes)) {
    throw InputError(file + ": cannot open: " + error);
  }
  json root = parse_json(text, file);
  if (!root.is_object()) throw InputError(file + ": expected a JSON object at the top level");
  return root;
}

}  // namespace

std::size_t Scene::triangle_count() const {
  std::size_t total = 0;
  for (const MeshInstance& instance : meshes) {
    if (instance.mesh) total += instance.mesh->triangle_count();
  }
  return total;
}

Scene load_scene(const std::filesystem::path& json_path) {
  MeshFileCache meshes;
  return load_scene(json_path, meshes);
}

namespace {

constexpr std::pair<ToneMap, const char*> kToneMapNames[] = {
    {ToneMap::None, "none"},
    {ToneMap::KhronosPbrNeutral, "khronos-pbr-neutral"},
    {ToneMap::AcesHill, "aces-hill"},
    {ToneMap::AcesNarkowicz, "aces-narkowicz"},
};

/// The root's "animation" (an index or a name) and "time" (seconds >= 0): either makes glTF
/// files posed at that moment; neither, their static pose.
std::optional<AnimationTime> animation_time(const std::string& file, const json& root,
                                            const SceneReader& reader) {
  const auto animation = root.find("animation");
  const auto time = root.find("time");
  if (animation == root.end() && time == root.end()) return std::nullopt;
  AnimationTime pose;
  if (animation != root.end()) {
    if (animation->is_string()) {
      pose.name = animation->get<std::string>();
      if (pose.name.empty()) fail(file, "animation", "expected an index or a non-empty name");
    } else if (animation->is_number_integer() && animation->get<std::int64_t>() >= 0 &&
               animation->get<std::int64_t>() <= std::int64_t(1) << 30) {
      pose.index = int(animation->get<std::int64_t>());
    } else {
      fail(file, "animation", "expected an index >= 0 or a name, got " + shown(*animation));
    }
  }
  if (time != root.end()) {
    pose.time_s = reader.number(*time, "time");
    if (!(pose.time_s >= 0.0)) fail(file, "time", "expected seconds >= 0, got " + shown(*time));
  }
  return pose;
}

/// The root with `variant` as the "variant" of every glTF mesh entry (SceneChoices).
void set_material_variant(json& root, const std::string& file, const std::string& variant) {
  bool any = false;
  if (const auto meshes = root.find("meshes"); meshes != root.end() && meshes->is_array()) {
    for (json& entry : *meshes) {
      if (entry.is_object() && entry.contains("gltf")) {
        entry["variant"] = variant;
        any = true;
      }
    }
  }
  if (!any) {
    throw InputError(file + ": material variant '" + variant + "': the scene has no glTF meshes");
  }
}

/// The root with `pose` in the place of its "animation" and "time" keys.
void set_animation_time(json& root, const AnimationTime& pose);

/// The root with `choices` in the place of its keys (SceneChoices).
void apply_choices(json& root, const std::string& file, const SceneChoices& choices) {
  if (choices.pose) set_animation_time(root, *choices.pose);
  if (!choices.material_variant.empty()) set_material_variant(root, file, choices.material_variant);
}

void set_animation_time(json& root, const AnimationTime& pose) {
  root.erase("animation");
  if (pose.index >= 0) {
    root["animation"] = pose.index;
  } else if (!pose.name.empty()) {
    root["animation"] = pose.name;
  }
  root["time"] = pose.time_s;
}

/// load_scene's work on a parsed root: `file` names it in messages, mesh paths are relative to
/// `base_dir`, meshes come from and go to `files`. `cameras`, if given, receives the first glTF
/// entry's cameras (load_mesh_scene looks for one there).
Scene scene_from_root(const json& root, const std::string& file,
                      const std::filesystem::path& base_dir, MeshFiles& files,
                      std::vector<detail::FileCamera>* cameras) {
  const SceneReader reader(file);

  Scene scene;
  scene.warnings = detail::unknown_scene_keys(root, file);
  scene.width = reader.image_side(root, "width");
  scene.height = reader.image_side(root, "height");
  if (const auto it = root.find("background"); it != root.end()) {
    if (it->is_string() && *it == "transparent") {
      scene.background_kind = BackgroundKind::Transparent;
    } else if (it->is_string() && *it == "skybox") {
      scene.background_kind = BackgroundKind::Skybox;
    } else if (it->is_string()) {
      fail(file, "background",
           "expected [r,g,b], \"transparent\" or \"skybox\", got " + shown(*it));
    } else {
      scene.background_linear = reader.srgb_color(*it, "background");
    }
  }
  const json& camera = reader.required(root, "camera", "camera");
  const bool camera_from_gltf = camera.is_object() && camera.contains("gltf");
  if (!camera_from_gltf) scene.camera = reader.camera(root);
  std::optional<std::size_t> gltf_lights_at;
  if (const auto it = root.find("lights"); it != root.end()) {
    scene.lit = true;
    scene.lights = reader.lights(*it, gltf_lights_at);
  }
  if (const auto it = root.find("tone_map"); it != root.end()) {
    if (!it->is_string()) fail(file, "tone_map", "expected a name string, got " + shown(*it));
    try {
      scene.tone_map = parse_tone_map(it->get<std::string>());
    } catch (const InputError& e) {
      fail(file, "tone_map", e.what());
    }
  }
  if (const auto it = root.find("exposure"); it != root.end()) {
    scene.exposure = reader.number(*it, "exposure");
    if (!(scene.exposure > 0.0)) fail(file, "exposure", "expected a number > 0, got " + shown(*it));
  }
  if (const auto it = root.find("environment"); it != root.end()) {
    scene.lit = true;
    scene.environment = scene_environment(file, *it, base_dir, scene.warnings);
  }

  const json& meshes = reader.required(root, "meshes", "meshes");
  if (!meshes.is_array()) fail(file, "meshes", "expected an array, got " + shown(meshes));
  const std::optional<AnimationTime> pose = animation_time(file, root, reader);
  SceneMeshes cache(file, base_dir, files, pose ? &*pose : nullptr);
  FirstGltf first_gltf;
  std::uint64_t triangles = 0;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const std::string key = "meshes[" + std::to_string(i) + "]";
    scene.meshes.push_back(load_instance(reader, file, meshes[i], key, cache, scene, first_gltf));
    triangles += scene.meshes.back().mesh->triangle_count();
    if (triangles > kMaxSceneTriangles) {
      fail(file, key,
           "the scene's instances draw " + std::to_string(triangles) + " triangles, more than " +
               std::to_string(kMaxSceneTriangles) + " (docs/limits.md)");
    }
  }
  if (camera_from_gltf) scene.camera = gltf_camera(file, camera, first_gltf, scene);
  if (gltf_lights_at) {
    const std::vector<Light> lights = gltf_lights(file, first_gltf);
    scene.lights.insert(scene.lights.begin() + std::ptrdiff_t(*gltf_lights_at), lights.begin(),
                        lights.end());
  }
  if (cameras != nullptr && first_gltf.loaded != nullptr) *cameras = first_gltf.loaded->cameras;
  return scene;
}

}  // namespace

namespace {

Scene load_scene_posed(const std::filesystem::path& json_path, MeshFiles& files,
                       const SceneChoices* choices) {
  // Every JSON access checks its type first; this is the net under them, so that a missed
  // check is still an input error naming the file, not an internal error.
  try {
    const std::string file = json_path.string();
    json root = read_scene_root(json_path, file);
    if (choices != nullptr) apply_choices(root, file, *choices);
    Scene scene = scene_from_root(root, file, json_path.parent_path(), files, nullptr);
    scene.source = json_path;
    warn_beyond_finite_range(scene);
    warn_anisotropy_without_tangents(scene);
    return scene;
  } catch (const json::exception& e) {
    throw InputError(json_path.string() + ": " + exception_detail(e));
  }
}

}  // namespace

Scene load_scene(const std::filesystem::path& json_path, MeshFileCache& mesh_files) {
  return load_scene_posed(json_path, mesh_files.impl_->files, nullptr);
}

Scene load_scene(const std::filesystem::path& json_path, const AnimationTime& pose) {
  return load_scene(json_path, SceneChoices{pose, {}});
}

Scene load_scene(const std::filesystem::path& json_path, const SceneChoices& choices) {
  MeshFiles files;
  return load_scene_posed(json_path, files, &choices);
}

Scene load_mesh_scene(const std::filesystem::path& mesh_path, int width, int height,
                      const std::optional<AnimationTime>& pose) {
  return load_mesh_scene(mesh_path, width, height, SceneChoices{pose, {}});
}

Scene load_mesh_scene(const std::filesystem::path& mesh_path, int width, int height,
                      const SceneChoices& choices) {
  const std::string file = mesh_path.string();
  const std::string ext = detail::lower_extension(mesh_path);
  if (ext != ".obj" && ext != ".gltf" && ext != ".glb") {
    throw InputError(file + ": unknown mesh format (expected .obj, .gltf or .glb)");
  }
  std::string bytes, error;
  if (!detail::read_whole_file(mesh_path, bytes, error)) {
    throw InputError(file + ": cannot open: " + error);
  }
  const bool gltf = ext != ".obj";
  // The file as a one-entry scene, through the scene loader and its checks; the camera is a
  // placeholder until the file's own or the framing one replaces it.
  json root = {{"width", width},
               {"height", height},
               {"background", {0.18, 0.18, 0.2}},
               {"camera",
                {{"eye", {0, 0, 1}},
                 {"target", {0, 0, 0}},
                 {"up", {0, 1, 0}},
                 {"fovy_deg", 40},
                 {"near", 0.1},
                 {"far", 10}}},
               {"meshes", json::array({{{gltf ? "gltf" : "obj", mesh_path.filename().string()}}})}};
  if (gltf) root["lights"] = "gltf";
  apply_choices(root, file, choices);
  MeshFiles files;  // the second pass below takes the parsed file from here
  std::vector<detail::FileCamera> cameras;
  Scene scene = scene_from_root(root, file, mesh_path.parent_path(), files, &cameras);
  const auto placed = std::find_if(cameras.begin(), cameras.end(),
                                   [](const detail::FileCamera& c) { return c.placed; });
  if (placed != cameras.end()) {
    root["camera"] = {{"gltf", static_cast<std::uint64_t>(placed - cameras.begin())}};
    scene = scene_from_root(root, file, mesh_path.parent_path(), files, nullptr);
  } else {
    scene.camera = detail::framing_camera(scene);
  }
  // A file without lights is lit as the viewers light it: by the built-in studio environment.
  if (scene.lights.empty()) scene.environment = EnvironmentLight{studio_environment(), 0.0, 1.0};
  scene.lit = true;
  scene.source = mesh_path;
  warn_beyond_finite_range(scene);
  warn_anisotropy_without_tangents(scene);
  return scene;
}

ToneMap parse_tone_map(const std::string& name) {
  std::string names;
  for (const auto& [tone_map, known] : kToneMapNames) {
    if (name == known) return tone_map;
    names += std::string(names.empty() ? "" : ", ") + known;
  }
  throw InputError("unknown tone map '" + name + "' (expected " + names + ")");
}

const char* to_string(ToneMap tone_map) {
  for (const auto& [known, name] : kToneMapNames) {
    if (known == tone_map) return name;
  }
  return "none";
}

}  // namespace covrast
