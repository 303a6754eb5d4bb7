#include "scene/scene_keys.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <span>
#include <string_view>

namespace covrast::detail {
namespace {

using json = nlohmann::json;
using Keys = std::span<const std::string_view>;

// The keys each object of the scene format reads (docs/scene-format.md, one table each).
constexpr std::array<std::string_view, 11> kTopKeys = {
    "width",       "height",   "background", "camera",    "meshes", "lights",
    "environment", "tone_map", "exposure",   "animation", "time"};
constexpr std::array<std::string_view, 9> kCameraKeys = {
    "eye", "target", "up", "fovy_deg", "near", "far", "projection", "ymag", "gltf"};
constexpr std::array<std::string_view, 8> kLightKeys = {
    "type",     "color", "intensity",      "direction",
    "position", "range", "inner_cone_deg", "outer_cone_deg"};
constexpr std::array<std::string_view, 4> kEnvironmentKeys = {"file", "builtin", "rotation_deg",
                                                              "intensity"};
constexpr std::array<std::string_view, 7> kMeshKeys = {"obj",      "gltf",    "color",  "model",
                                                       "material", "normals", "variant"};
constexpr std::array<std::string_view, 26> kMaterialKeys = {"model",
                                                            "base_color",
                                                            "metallic",
                                                            "roughness",
                                                            "emissive",
                                                            "shininess",
                                                            "specular",
                                                            "double_sided",
                                                            "alpha_mode",
                                                            "alpha_cutoff",
                                                            "base_alpha",
                                                            "ior",
                                                            "specular_factor",
                                                            "clearcoat",
                                                            "clearcoat_roughness",
                                                            "sheen_color",
                                                            "sheen_roughness",
                                                            "iridescence",
                                                            "iridescence_ior",
                                                            "iridescence_thickness_nm",
                                                            "anisotropy",
                                                            "anisotropy_rotation_deg",
                                                            "transmission",
                                                            "thickness",
                                                            "attenuation_color",
                                                            "attenuation_distance"};

/// Levenshtein distance (insertions, deletions, substitutions), one row at a time.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1] ? 1 : 0)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

/// The known key nearest to `key`, when it is near enough to be a slip: at most 2 edits and
/// fewer than half the key's length, or else the first known key that starts with it (a
/// shortened name: "fov" for "fovy_deg").
std::string_view nearest(std::string_view key, Keys known) {
  std::string_view best;
  std::size_t best_distance = 3;
  for (const std::string_view k : known) {
    const std::size_t d = edit_distance(key, k);
    if (d < best_distance && 2 * d < key.size()) {
      best = k;
      best_distance = d;
    }
  }
  if (best.empty() && key.size() >= 3) {
    for (const std::string_view k : known) {
      if (k.starts_with(key)) return k;
    }
  }
  return best;
}

void check_object(const json& object, Keys known, const std::string& path, const std::string& file,
                  std::vector<std::string>& warnings) {
  if (!object.is_object()) return;  // the loader reports a wrong type where it reads it
  for (const auto& [key, value] : object.items()) {
    if (key.starts_with('_') || key == "extras") continue;
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    std::string warning =
        file + ": " + (path.empty() ? key : path + "." + key) + ": unknown key, ignored";
    if (const std::string_view guess = nearest(key, known); !guess.empty()) {
      warning += " (did you mean '" + std::string(guess) + "'?)";
    }
    warnings.push_back(std::move(warning));
  }
}

/// Calls each(element, "key[i]") for every element of the array root[key].
template <class Each>
void each_element(const json& root, const char* key, Each each) {
  const auto it = root.find(key);
  if (it == root.end() || !it->is_array()) return;
  for (std::size_t i = 0; i < it->size(); ++i) {
    each((*it)[i], std::string(key) + "[" + std::to_string(i) + "]");
  }
}

}  // namespace

std::vector<std::string> unknown_scene_keys(const json& root, const std::string& file) {
  std::vector<std::string> warnings;
  check_object(root, kTopKeys, "", file, warnings);
  if (!root.is_object()) return warnings;
  if (const auto it = root.find("camera"); it != root.end()) {
    check_object(*it, kCameraKeys, "camera", file, warnings);
  }
  if (const auto it = root.find("environment"); it != root.end()) {
    check_object(*it, kEnvironmentKeys, "environment", file, warnings);
  }
  each_element(root, "lights", [&](const json& light, const std::string& path) {
    check_object(light, kLightKeys, path, file, warnings);
  });
  each_element(root, "meshes", [&](const json& mesh, const std::string& path) {
    check_object(mesh, kMeshKeys, path, file, warnings);
    if (!mesh.is_object()) return;
    if (const auto it = mesh.find("material"); it != mesh.end()) {
      check_object(*it, kMaterialKeys, path + ".material", file, warnings);
    }
  });
  return warnings;
}

}  // namespace covrast::detail
