// Scene file loader: parses the JSON scene format (docs/scene-format.md), validates every field
// with a one-line InputError naming the file and the JSON key, converts sRGB display colours to
// linear light, and loads each mesh file once however many instances name it.
#include "scene/gltf_animation.hpp"
#include "scene/scene_internal.hpp"
#include "scene/scene_keys.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <string_view>
#include <utility>

namespace covrast {
namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& file, const std::string& key,
                       const std::string& message) {
  throw InputError(file + ": " + key + ": " + message);
}

/// A JSON value shortened for a one-line message.
std::string shown(const json& value) {
  constexpr std::size_t kMaxShown = 40;
  std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  if (text.size() > kMaxShown) text = text.substr(0, kMaxShown) + "...";
  return text;
}

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

class SceneReader {
 public:
  explicit SceneReader(std::string file) : file_(std::move(file)) {}

  const json& required(const json& object, const char* key, const std::string& path) const {
    const auto it = object.find(key);
    if (it == object.end()) fail(file_, path, "missing");
    return *it;
  }

  const json& require_object(const json& value, const std::string& path) const {
    if (!value.is_object()) fail(file_, path, "expected an object, got " + shown(value));
    return value;
  }

  double number(const json& value, const std::string& path) const {
    if (!value.is_number()) fail(file_, path, "expected a number, got " + shown(value));
    const double x = value.get<double>();
    if (!std::isfinite(x)) fail(file_, path, "expected a finite number, got " + shown(value));
    return x;
  }

  int image_side(const json& root, const char* key) const {
    const json& value = required(root, key, key);
    // Unsigned first: a huge unsigned value must not wrap into range as a signed one.
    bool in_range = false;
    if (value.is_number_unsigned()) {
      const auto side = value.get<unsigned long long>();
      in_range = side >= 1 && side <= static_cast<unsigned long long>(kMaxImageSide);
    } else if (value.is_number_integer()) {
      const auto side = value.get<long long>();
      in_range = side >= 1 && side <= kMaxImageSide;
    }
    if (!in_range) {
      fail(file_, key,
           "expected an integer in 1.." + std::to_string(kMaxImageSide) + ", got " + shown(value));
    }
    return static_cast<int>(value.get<long long>());
  }

  glm::dvec3 vec3(const json& value, const std::string& path) const {
    if (!value.is_array() || value.size() != 3) {
      fail(file_, path, "expected [x,y,z], got " + shown(value));
    }
    return {number(value[0], path + "[0]"), number(value[1], path + "[1]"),
            number(value[2], path + "[2]")};
  }

  /// [r,g,b] sRGB display values in 0..1 -> linear light.
  glm::vec3 srgb_color(const json& value, const std::string& path) const {
    if (!value.is_array() || value.size() != 3) {
      fail(file_, path, "expected [r,g,b], got " + shown(value));
    }
    glm::vec3 linear(0.0f);
    for (int c = 0; c < 3; ++c) {
      const std::string component_path = path + "[" + std::to_string(c) + "]";
      const double x = number(value[static_cast<std::size_t>(c)], component_path);
      if (x < 0.0 || x > 1.0) {
        fail(file_, component_path,
             "colour component must be in 0..1, got " + shown(value[static_cast<std::size_t>(c)]));
      }
      linear[c] = srgb_to_linear(static_cast<float>(x));
    }
    return linear;
  }

  Camera camera(const json& root) const {
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
           "too far from camera.target: |target - eye| overflows (eye " + shown(object["eye"]) +
               ")");
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
  void projection(const json& object, Camera& camera) const {
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
      fail(file_, "camera.fovy_deg",
           "must be in (0, 180) degrees, got " + shown(object["fovy_deg"]));
    }
  }

  /// Row-major: 4 rows of 4 numbers, or 16 numbers in row order; translation in the last
  /// column. Stored column-major (GLM): model[col][row].
  glm::dmat4 model_matrix(const json& value, const std::string& path) const {
    double rows[4][4] = {};
    if (value.is_array() && value.size() == 16) {
      for (std::size_t i = 0; i < 16; ++i) {
        rows[i / 4][i % 4] = number(value[i], path + "[" + std::to_string(i) + "]");
      }
    } else if (value.is_array() && value.size() == 4) {
      for (std::size_t r = 0; r < 4; ++r) {
        const std::string row_path = path + "[" + std::to_string(r) + "]";
        if (!value[r].is_array() || value[r].size() != 4) {
          fail(file_, row_path, "expected a row of 4 numbers, got " + shown(value[r]));
        }
        for (std::size_t c = 0; c < 4; ++c) {
          rows[r][c] = number(value[r][c], row_path + "[" + std::to_string(c) + "]");
        }
      }
    } else {
      fail(file_, path,
           "expected 4 rows of 4 numbers or 16 numbers (row-major), got " + shown(value));
    }
    if (rows[3][0] != 0.0 || rows[3][1] != 0.0 || rows[3][2] != 0.0 || rows[3][3] != 1.0) {
      fail(file_, path, "last row must be [0,0,0,1] (affine transform)");
    }
    glm::dmat4 model(1.0);
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) model[c][r] = rows[r][c];
    }
    return model;
  }

  /// A number in [lo, hi].
  double number_in(const json& value, const std::string& path, double lo, double hi) const {
    const double x = number(value, path);
    if (x < lo || x > hi) {
      fail(file_, path,
           "expected a number in " + number_text(lo) + ".." + number_text(hi) + ", got " +
               shown(value));
    }
    return x;
  }

  /// [r,g,b] of linear light, each finite and >= 0 (light colours may exceed 1).
  glm::vec3 linear_color(const json& value, const std::string& path) const {
    if (!value.is_array() || value.size() != 3) {
      fail(file_, path, "expected [r,g,b], got " + shown(value));
    }
    glm::vec3 color(0.0f);
    for (std::size_t c = 0; c < 3; ++c) {
      const std::string component_path = path + "[" + std::to_string(c) + "]";
      const double x = number(value[c], component_path);
      if (x < 0.0) fail(file_, component_path, "must be >= 0, got " + shown(value[c]));
      color[static_cast<int>(c)] = static_cast<float>(x);
    }
    return color;
  }

  /// A non-zero direction, normalised.
  glm::dvec3 direction(const json& value, const std::string& path) const {
    const glm::dvec3 d = vec3(value, path);
    const double length = glm::length(d);
    if (!(length > 0.0) || !std::isfinite(length)) fail(file_, path, "must not be zero");
    return d / length;
  }

  Light light(const json& value, const std::string& key) const {
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
  void spot_cone(const json& object, const std::string& key, Light& light) const {
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
  std::vector<Light> lights(const json& value, std::optional<std::size_t>& gltf_at) const {
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

  ShadingModel shading_model(const json& value, const std::string& path) const {
    if (value == "unlit") return ShadingModel::Unlit;
    if (value == "lambert") return ShadingModel::Lambert;
    if (value == "blinn-phong") return ShadingModel::BlinnPhong;
    if (value == "pbr") return ShadingModel::Pbr;
    fail(file_, path,
         "expected \"unlit\", \"lambert\", \"blinn-phong\" or \"pbr\", got " + shown(value));
  }

  /// The keys of the glTF material extensions (KHR_materials_ior, _specular, _clearcoat,
  /// _sheen, _iridescence).
  void apply_material_extensions(const json& object, const std::string& key, Material& m) const {
    if (const auto it = object.find("ior"); it != object.end()) {
      const double ior = number_in(*it, key + ".ior", 0.0, 1e6);
      if (ior != 0.0 && ior < 1.0) {
        fail(file_, key + ".ior", "expected 0 or a number >= 1, got " + shown(*it));
      }
      m.ior = static_cast<float>(ior);
    }
    if (const auto it = object.find("specular_factor"); it != object.end()) {
      m.specular_factor = static_cast<float>(number_in(*it, key + ".specular_factor", 0.0, 1.0));
    }
    if (const auto it = object.find("clearcoat"); it != object.end()) {
      m.clearcoat = static_cast<float>(number_in(*it, key + ".clearcoat", 0.0, 1.0));
    }
    if (const auto it = object.find("iridescence"); it != object.end()) {
      m.iridescence = static_cast<float>(number_in(*it, key + ".iridescence", 0.0, 1.0));
    }
    if (const auto it = object.find("iridescence_ior"); it != object.end()) {
      m.iridescence_ior = static_cast<float>(number_in(*it, key + ".iridescence_ior", 1.0, 10.0));
    }
    if (const auto it = object.find("iridescence_thickness_nm"); it != object.end()) {
      m.iridescence_thickness_max_nm =
          static_cast<float>(number_in(*it, key + ".iridescence_thickness_nm", 0.0, 10000.0));
    }
    if (const auto it = object.find("sheen_color"); it != object.end()) {
      m.sheen_color_factor = srgb_color(*it, key + ".sheen_color");
    }
    if (const auto it = object.find("sheen_roughness"); it != object.end()) {
      m.sheen_roughness = static_cast<float>(number_in(*it, key + ".sheen_roughness", 0.0, 1.0));
    }
    if (const auto it = object.find("clearcoat_roughness"); it != object.end()) {
      m.clearcoat_roughness =
          static_cast<float>(number_in(*it, key + ".clearcoat_roughness", 0.0, 1.0));
    }
  }

  /// Applies the keys of a scene "material" object to `m` (keys not given keep its value).
  void apply_material(const json& object, const std::string& key, Material& m) const {
    if (const auto it = object.find("model"); it != object.end()) {
      m.model = shading_model(*it, key + ".model");
    }
    if (const auto it = object.find("metallic"); it != object.end()) {
      m.metallic = static_cast<float>(number_in(*it, key + ".metallic", 0.0, 1.0));
    }
    if (const auto it = object.find("roughness"); it != object.end()) {
      m.roughness = static_cast<float>(number_in(*it, key + ".roughness", 0.0, 1.0));
    }
    if (const auto it = object.find("emissive"); it != object.end()) {
      m.emissive_linear = srgb_color(*it, key + ".emissive");
    }
    if (const auto it = object.find("shininess"); it != object.end()) {
      m.shininess = static_cast<float>(number_in(*it, key + ".shininess", 1e-3, 1e4));
    }
    if (const auto it = object.find("specular"); it != object.end()) {
      m.specular_linear =
          glm::vec3(static_cast<float>(number_in(*it, key + ".specular", 0.0, 1.0)));
    }
    apply_material_extensions(object, key, m);
    if (const auto it = object.find("double_sided"); it != object.end()) {
      if (!it->is_boolean()) {
        fail(file_, key + ".double_sided", "expected true or false, got " + shown(*it));
      }
      m.double_sided = it->get<bool>();
    }
    if (const auto it = object.find("alpha_mode"); it != object.end()) {
      m.alpha_mode = alpha_mode(*it, key + ".alpha_mode");
    }
    if (const auto it = object.find("alpha_cutoff"); it != object.end()) {
      m.alpha_cutoff = number_in(*it, key + ".alpha_cutoff", 0.0, 1.0);
    }
    if (const auto it = object.find("base_alpha"); it != object.end()) {
      m.base_alpha = number_in(*it, key + ".base_alpha", 0.0, 1.0);
    }
  }

  AlphaMode alpha_mode(const json& value, const std::string& path) const {
    if (value == "opaque") return AlphaMode::Opaque;
    if (value == "mask") return AlphaMode::Mask;
    if (value == "blend") return AlphaMode::Blend;
    fail(file_, path, "expected \"opaque\", \"mask\" or \"blend\", got " + shown(value));
  }

  NormalSource normal_source(const json& value, const std::string& path) const {
    if (value == "file") return NormalSource::File;
    if (value == "flat") return NormalSource::Flat;
    if (value == "smooth") return NormalSource::Smooth;
    fail(file_, path, "expected \"file\", \"flat\" or \"smooth\", got " + shown(value));
  }

 private:
  static std::string number_text(double x) {
    std::string text = std::to_string(x);
    while (text.back() == '0') text.pop_back();
    if (text.back() == '.') text.pop_back();
    return text;
  }

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

/// The instance's materials: the file's, or one default (lambert for OBJ, which has none in
/// covrast yet; glTF files always list theirs), with the scene's "material" keys applied.
std::vector<Material> instance_materials(const SceneReader& reader, const json& entry,
                                         const std::string& key, const MeshData& mesh) {
  std::vector<Material> materials = mesh.materials;
  if (materials.empty()) {
    Material lambert;
    lambert.model = ShadingModel::Lambert;
    materials.push_back(lambert);
  }
  if (const auto it = entry.find("material"); it != entry.end()) {
    const json& object = reader.require_object(*it, key + ".material");
    for (Material& m : materials) reader.apply_material(object, key + ".material", m);
  }
  return materials;
}

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

/// The mesh file an entry of "meshes" names: its format and its path as written.
struct MeshFileRef {
  MeshFormat format;
  std::string relative;
};

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

/// The scene's mesh files, each read and parsed once however many instances name it
/// (instancing: one load per canonical path and format).
}  // namespace

/// The loaded mesh files, by canonical path and format.
struct MeshFileCache::Impl {
  std::map<std::pair<std::string, MeshFormat>, CachedMesh> files;
};

MeshFileCache::MeshFileCache() : impl_(std::make_unique<Impl>()) {}
MeshFileCache::~MeshFileCache() = default;
std::size_t MeshFileCache::files_loaded() const { return impl_->files.size(); }

namespace {

/// One scene's view of a MeshFileCache: loads each file on its first use in any scene, and
/// passes each file's warnings to this scene on its first use here.
class SceneMeshes {
 public:
  /// `pose`: the moment glTF files are posed at (null: their static pose).
  SceneMeshes(const std::string& file, std::filesystem::path base_dir,
              std::map<std::pair<std::string, MeshFormat>, CachedMesh>& files,
              const AnimationTime* pose)
      : file_(file), base_dir_(std::move(base_dir)), files_(files), pose_(pose) {}

  /// The mesh that entry `key` names, drawn with material variant `variant` (empty: none).
  CachedMesh& get(const MeshFileRef& ref, const std::string& key, Scene& scene,
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

 private:
  /// The file's warnings (the lit ones only when the scene is lit), once per scene.
  static void add_warnings(const std::filesystem::path& full, const detail::LoadedMesh& loaded,
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

  detail::LoadedMesh load(const std::filesystem::path& full, const MeshFileRef& ref,
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

  const std::string& file_;
  std::filesystem::path base_dir_;
  std::map<std::pair<std::string, MeshFormat>, CachedMesh>& files_;
  const AnimationTime* pose_;
  std::set<std::pair<std::string, MeshFormat>> warned_;
};

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

/// The scene's first glTF mesh entry: where a {"gltf": N} camera comes from.
struct FirstGltf {
  const detail::LoadedMesh* loaded = nullptr;  ///< null: no glTF mesh (yet)
  std::string relative;                        ///< the file as the scene names it
  glm::dmat4 model{1.0};                       ///< the entry's model matrix
  /// Every glTF entry (file and model matrix), where "lights": "gltf" takes lights from.
  std::vector<std::pair<const detail::LoadedMesh*, glm::dmat4>> all;
};

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

using MeshFiles = std::map<std::pair<std::string, MeshFormat>, CachedMesh>;

constexpr std::pair<ToneMap, const char*> kToneMapNames[] = {
    {ToneMap::None, "none"},
    {ToneMap::KhronosPbrNeutral, "khronos-pbr-neutral"},
    {ToneMap::AcesHill, "aces-hill"},
    {ToneMap::AcesNarkowicz, "aces-narkowicz"},
};

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
