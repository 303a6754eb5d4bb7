// Scene file loader, the camera, lights and environment: the "camera", "lights" and
// "environment" keys (SceneReader, scene_reader.hpp), a {"gltf": N} camera and "lights":
// "gltf" taken from the scene's glTF files, and the check that every instance stays within
// the finite range of the camera's clip space.
#include "scene/scene_reader.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace covrast::detail {

Camera SceneReader::camera(const json& root) const {
  const json& object = require_object(required(root, "camera", "camera"), "camera");
  Camera camera;
  camera.eye = vec3(required(object, "eye", "camera.eye"), "camera.eye");
  camera.target = vec3(required(object, "target", "camera.target"), "camera.target");
  camera.up = vec3(required(object, "up", "camera.up"), "camera.up");
  projection(object, camera);
  camera.near = number(required(object, "near", "camera.near"), "camera.near");
  camera.far = number(required(object, "far", "camera.far"), "camera.far");
  if (!(camera.near > 0.0 || (camera.orthographic && camera.near == 0.0))) {
    fail(file_, "camera.near",
         std::string(camera.orthographic ? "must be >= 0" : "must be > 0") + ", got " +
             shown(object["near"]));
  }
  if (!(camera.far > camera.near)) {
    fail(file_, "camera.far", "must be greater than near, got " + shown(object["far"]));
  }
  const glm::dvec3 view = camera.target - camera.eye;
  if (view == glm::dvec3(0.0)) fail(file_, "camera", "eye and target must differ");
  // |target - eye| and |up| must be finite, or the parallel test below (and the view
  // matrix) overflow and blame the wrong key.
  if (!std::isfinite(glm::length(view))) {
    fail(file_, "camera.eye",
         "too far from camera.target: |target - eye| overflows (eye " + shown(object["eye"]) + ")");
  }
  if (!std::isfinite(glm::length(camera.up))) {
    fail(file_, "camera.up", "too large: its length overflows, got " + shown(object["up"]));
  }
  // Parallel when sin(angle(view, up)) = |view x up| / (|view| |up|) is (nearly) zero.
  const double up_length = glm::length(camera.up);
  if (!(up_length > 0.0) ||
      !(glm::length(glm::cross(view, camera.up)) > 1e-6 * glm::length(view) * up_length)) {
    fail(file_, "camera.up", "must not be zero or parallel to the view direction");
  }
  return camera;
}

/// "projection": "perspective" (the default) with "fovy_deg", or "orthographic" with "ymag"
/// (half the view's height, world units).
void SceneReader::projection(const json& object, Camera& camera) const {
  if (const auto it = object.find("projection"); it != object.end()) {
    if (*it == "orthographic") {
      camera.orthographic = true;
    } else if (*it != "perspective") {
      fail(file_, "camera.projection",
           "expected \"perspective\" or \"orthographic\", got " + shown(*it));
    }
  }
  if (camera.orthographic) {
    if (object.contains("fovy_deg")) {
      fail(file_, "camera.fovy_deg", "an orthographic camera takes ymag, not fovy_deg");
    }
    camera.ymag = number(required(object, "ymag", "camera.ymag"), "camera.ymag");
    if (!(camera.ymag > 0.0)) {
      fail(file_, "camera.ymag", "must be > 0, got " + shown(object["ymag"]));
    }
    return;
  }
  if (object.contains("ymag")) fail(file_, "camera.ymag", "only for an orthographic camera");
  camera.fovy_deg = number(required(object, "fovy_deg", "camera.fovy_deg"), "camera.fovy_deg");
  if (!(camera.fovy_deg > 0.0 && camera.fovy_deg < 180.0)) {
    fail(file_, "camera.fovy_deg", "must be in (0, 180) degrees, got " + shown(object["fovy_deg"]));
  }
}

Light SceneReader::light(const json& value, const std::string& key) const {
  const json& object = require_object(value, key);
  const json& type = required(object, "type", key + ".type");
  Light light;
  if (type == "directional") {
    light.type = LightType::Directional;
  } else if (type == "point") {
    light.type = LightType::Point;
  } else if (type == "spot") {
    light.type = LightType::Spot;
  } else if (type == "ambient") {
    light.type = LightType::Ambient;
  } else {
    fail(file_, key + ".type",
         "expected \"directional\", \"point\", \"spot\" or \"ambient\", got " + shown(type));
  }
  if (const auto it = object.find("color"); it != object.end()) {
    light.color_linear = linear_color(*it, key + ".color");
  }
  if (const auto it = object.find("intensity"); it != object.end()) {
    light.intensity = number_in(*it, key + ".intensity", 0.0, 1e30);
  }
  if (light.type == LightType::Directional || light.type == LightType::Spot) {
    light.direction =
        direction(required(object, "direction", key + ".direction"), key + ".direction");
  }
  if (light.type == LightType::Point || light.type == LightType::Spot) {
    light.position = vec3(required(object, "position", key + ".position"), key + ".position");
    if (const auto it = object.find("range"); it != object.end()) {
      light.range = number(*it, key + ".range");
      if (!(light.range > 0.0)) fail(file_, key + ".range", "must be > 0, got " + shown(*it));
    }
  }
  if (light.type == LightType::Spot) spot_cone(object, key, light);
  return light;
}

/// KHR_lights_punctual: 0 <= inner < outer <= 90 degrees (defaults 0 and 45).
void SceneReader::spot_cone(const json& object, const std::string& key, Light& light) const {
  if (const auto it = object.find("inner_cone_deg"); it != object.end()) {
    light.inner_cone_deg = number_in(*it, key + ".inner_cone_deg", 0.0, 90.0);
  }
  if (const auto it = object.find("outer_cone_deg"); it != object.end()) {
    light.outer_cone_deg = number_in(*it, key + ".outer_cone_deg", 0.0, 90.0);
  }
  if (!(light.inner_cone_deg < light.outer_cone_deg)) {
    fail(file_, key + ".outer_cone_deg", "must be greater than inner_cone_deg");
  }
}

/// "lights": an array of light objects in which the string "gltf" (once) stands for the
/// lights of the scene's glTF files, or just "gltf"; `gltf_at` is where those go.
std::vector<Light> SceneReader::lights(const json& value,
                                       std::optional<std::size_t>& gltf_at) const {
  if (value == "gltf") {
    gltf_at = 0;
    return {};
  }
  if (!value.is_array()) {
    fail(file_, "lights", "expected an array or \"gltf\", got " + shown(value));
  }
  if (value.size() > kMaxSceneLights) {
    fail(file_, "lights",
         std::to_string(value.size()) + " lights, more than " + std::to_string(kMaxSceneLights) +
             " (docs/limits.md)");
  }
  std::vector<Light> result;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string key = "lights[" + std::to_string(i) + "]";
    if (value[i] == "gltf") {
      if (gltf_at) fail(file_, key, "\"gltf\" given twice");
      gltf_at = result.size();
    } else {
      result.push_back(light(value[i], key));
    }
  }
  return result;
}

namespace {

/// A far plane for a camera without one (glTF's infinite projection): beyond every mesh of
/// the scene, twice the distance from `eye` to the farthest corner of their world boxes.
double far_beyond_meshes(const Scene& scene, const glm::dvec3& eye, double near) {
  double farthest = 0.0;
  for (const MeshInstance& instance : scene.meshes) {
    const glm::dvec3 lo(instance.mesh->bounds_min), hi(instance.mesh->bounds_max);
    for (int corner = 0; corner < 8; ++corner) {
      const glm::dvec4 p(corner & 1 ? hi.x : lo.x, corner & 2 ? hi.y : lo.y,
                         corner & 4 ? hi.z : lo.z, 1.0);
      farthest = std::max(farthest, glm::length(glm::dvec3(instance.model * p) - eye));
    }
  }
  return std::max(2.0 * farthest, 2.0 * near);
}

}  // namespace

/// "camera": {"gltf": N}: camera N of the scene's first glTF mesh entry, placed at its node's
/// world transform times that entry's model matrix; it looks down its -z with +y up (glTF
/// 2.0, 3.10.1). Perspective (yfov) or orthographic (ymag); aspectRatio and xmag give way to
/// the image's size.
Camera gltf_camera(const std::string& file, const json& object, const FirstGltf& first,
                   const Scene& scene) {
  if (object.size() != 1) fail(file, "camera", "with \"gltf\" give no other camera key");
  const json& index_value = object["gltf"];
  if (!index_value.is_number_unsigned()) {
    fail(file, "camera.gltf", "expected a camera index >= 0, got " + shown(index_value));
  }
  if (first.loaded == nullptr) fail(file, "camera.gltf", "the scene has no glTF mesh");
  const auto index = index_value.get<std::uint64_t>();
  const std::string which = "camera " + std::to_string(index) + " of '" + first.relative + "'";
  const std::vector<detail::FileCamera>& cameras = first.loaded->cameras;
  if (index >= cameras.size()) {
    fail(file, "camera.gltf",
         which + " does not exist (" + std::to_string(cameras.size()) + " cameras)");
  }
  const detail::FileCamera& source = cameras[static_cast<std::size_t>(index)];
  if (!source.placed) fail(file, "camera.gltf", which + " is on no node of the file's scene");
  if (source.orthographic) {
    if (!(source.ymag > 0.0 && std::isfinite(source.ymag)) || !(source.znear >= 0.0) ||
        !(source.zfar > source.znear && std::isfinite(source.zfar))) {
      fail(file, "camera.gltf",
           which + " (orthographic) needs ymag > 0, znear >= 0 and zfar > znear");
    }
  } else if (!(source.yfov_rad > 0.0 && source.yfov_rad < std::numbers::pi) ||
             !(source.znear > 0.0) || !(source.zfar == 0.0 || source.zfar > source.znear)) {
    fail(file, "camera.gltf", which + " needs 0 < yfov < pi, znear > 0 and zfar > znear");
  }
  const glm::dmat4 world = first.model * source.world;
  Camera camera;
  camera.eye = glm::dvec3(world[3]);
  const glm::dvec3 forward = glm::dmat3(world) * glm::dvec3(0.0, 0.0, -1.0);
  camera.up = glm::dmat3(world) * glm::dvec3(0.0, 1.0, 0.0);
  const double length = glm::length(forward);
  if (!(length > 0.0) || !std::isfinite(length) ||
      !(glm::length(glm::cross(forward, camera.up)) > 1e-6 * length * glm::length(camera.up))) {
    fail(file, "camera.gltf", which + ": its node's transform is degenerate");
  }
  camera.target = camera.eye + forward / length;
  camera.orthographic = source.orthographic;
  if (source.orthographic) {
    camera.ymag = source.ymag;
  } else {
    camera.fovy_deg = glm::degrees(source.yfov_rad);
  }
  camera.near = source.znear;
  camera.far = source.zfar > 0.0 ? source.zfar : far_beyond_meshes(scene, camera.eye, camera.near);
  return camera;
}

/// A warning for every instance whose model matrix takes it out of the finite range: its
/// clip-space coordinates, clip = P V M p (docs/architecture.md) computed in double as the
/// front end does, overflow at a corner of its box, so that the clipper can only cull it.
void warn_beyond_finite_range(Scene& scene) {
  const Camera& cam = scene.camera;
  const double aspect = double(scene.width) / double(scene.height);
  const glm::dmat4 projection =
      cam.orthographic ? glm::ortho(-cam.ymag * aspect, cam.ymag * aspect, -cam.ymag, cam.ymag,
                                    cam.near, cam.far)
                       : glm::perspective(glm::radians(cam.fovy_deg), aspect, cam.near, cam.far);
  const glm::dmat4 view_projection = projection * glm::lookAt(cam.eye, cam.target, cam.up);
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const MeshInstance& instance = scene.meshes[i];
    if (instance.mesh->triangle_count() == 0) continue;
    const glm::dmat4 mvp = view_projection * instance.model;
    const glm::dvec3 lo(instance.mesh->bounds_min), hi(instance.mesh->bounds_max);
    bool finite = true;
    for (int corner = 0; corner < 8 && finite; ++corner) {
      const glm::dvec4 clip = mvp * glm::dvec4(corner & 1 ? hi.x : lo.x, corner & 2 ? hi.y : lo.y,
                                               corner & 4 ? hi.z : lo.z, 1.0);
      finite = std::isfinite(clip.x) && std::isfinite(clip.y) && std::isfinite(clip.z) &&
               std::isfinite(clip.w);
    }
    if (!finite) {
      scene.warnings.push_back(scene.source.string() + ": meshes[" + std::to_string(i) +
                               "]: the mesh lies outside the finite range (its model matrix "
                               "makes clip-space coordinates overflow): nothing of it is drawn");
    }
  }
}

/// "lights": "gltf": the KHR_lights_punctual lights of every glTF mesh entry, in entry order
/// and each file's walk order, placed at the light's node's world transform times the
/// entry's model matrix; the light shines down the node's -z. Checked as add_light checks.
std::vector<Light> gltf_lights(const std::string& file, const FirstGltf& gltf) {
  std::vector<Light> lights;
  for (const auto& [loaded, model] : gltf.all) {
    for (const detail::FileLight& source : loaded->lights) {
      const glm::dmat4 world = model * source.world;
      Light light = source.light;
      light.position = glm::dvec3(world[3]);
      light.direction = glm::dmat3(world) * glm::dvec3(0.0, 0.0, -1.0);
      const double length = glm::length(light.direction);
      if (light.type != LightType::Point && (!(length > 0.0) || !std::isfinite(length))) {
        fail(file, "lights",
             "light " + std::to_string(source.index) + " of '" + loaded->data->source + "' (node " +
                 std::to_string(source.node) + "): its transform is degenerate");
      }
      if (length > 0.0) light.direction /= length;
      lights.push_back(light);
    }
  }
  return lights;
}

/// "environment": "studio" (the built-in one), or an object with "file" (relative to the scene
/// file) or "builtin": "studio", and optionally "rotation_deg" and "intensity" (finite, >= 0).
EnvironmentLight scene_environment(const std::string& file, const json& value,
                                   const std::filesystem::path& base_dir,
                                   std::vector<std::string>& warnings) {
  const SceneReader reader(file);
  const auto builtin = [&](const json& name, const std::string& path) {
    if (!name.is_string() || name.get<std::string>() != "studio") {
      fail(file, path, "expected \"studio\" (the one built-in environment), got " + shown(name));
    }
    return studio_environment();
  };
  EnvironmentLight light;
  if (value.is_string()) {
    light.map = builtin(value, "environment");
    return light;
  }
  reader.require_object(value, "environment");
  for (const auto& [key, item] : value.items()) {
    if (key != "file" && key != "builtin" && key != "rotation_deg" && key != "intensity") {
      fail(file, "environment." + key,
           "unknown key (expected file or builtin, rotation_deg, intensity)");
    }
  }
  const auto file_it = value.find("file"), builtin_it = value.find("builtin");
  if ((file_it == value.end()) == (builtin_it == value.end())) {
    fail(file, "environment", "expected exactly one of \"file\" and \"builtin\"");
  }
  if (builtin_it != value.end()) {
    light.map = builtin(*builtin_it, "environment.builtin");
  } else {
    if (!file_it->is_string()) {
      fail(file, "environment.file", "expected a path string, got " + shown(*file_it));
    }
    const std::filesystem::path path =
        base_dir / std::filesystem::path(file_it->get<std::string>());
    light.map = std::make_shared<const EnvironmentMap>(load_environment(path, &warnings));
  }
  if (const auto it = value.find("rotation_deg"); it != value.end()) {
    light.rotation_deg = reader.number(*it, "environment.rotation_deg");
  }
  if (const auto it = value.find("intensity"); it != value.end()) {
    light.intensity = reader.number(*it, "environment.intensity");
    if (light.intensity < 0.0) {
      fail(file, "environment.intensity", "expected a number >= 0, got " + shown(*it));
    }
  }
  return light;
}

}  // namespace covrast::detail
