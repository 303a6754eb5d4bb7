// Tests: keys of a scene file that covrast does not read (src/scene/scene_keys.cpp) are
// warnings naming their JSON path and the nearest known key; every key the format's tables in
// docs/scene-format.md list is known, so the check and the documentation cannot drift apart.
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "scene/scene_keys.hpp"
#include "test_cli_run.hpp"
#include "test_tempdir.hpp"

using covrast::detail::unknown_scene_keys;
using nlohmann::json;

namespace {

/// The keys in the first column of each table under the headings of docs/scene-format.md
/// that describe an object of the scene format, by heading.
std::map<std::string, std::vector<std::string>> documented_keys() {
  std::ifstream in(std::string(COVRAST_SOURCE_DIR) + "/docs/scene-format.md");
  REQUIRE(in.good());
  const std::map<std::string, std::string> sections = {{"## Top level", "top"},
                                                       {"## `camera`", "camera"},
                                                       {"## `lights[i]`", "light"},
                                                       {"## `meshes[i]`", "mesh"},
                                                       {"### `material`", "material"}};
  std::map<std::string, std::vector<std::string>> keys;
  const std::regex row(R"(^\| `([a-z_0-9]+)` +\|)");
  std::string section, line;
  while (std::getline(in, line)) {
    if (line.starts_with('#')) {
      const auto it = sections.find(line);
      section = it != sections.end() ? it->second : "";
      continue;
    }
    std::smatch m;
    if (!section.empty() && std::regex_search(line, m, row)) keys[section].push_back(m[1]);
  }
  return keys;
}

}  // namespace

TEST_CASE("scene keys: every key the format's tables list is known at its level", "[scene][keys]") {
  const auto keys = documented_keys();
  // The tables exist and are read (a renamed heading would otherwise pass vacuously).
  REQUIRE(keys.at("top").size() >= 11);
  REQUIRE(keys.at("camera").size() >= 8);
  REQUIRE(keys.at("light").size() >= 8);
  REQUIRE(keys.at("mesh").size() >= 7);
  REQUIRE(keys.at("material").size() >= 20);
  const auto object_of = [](const std::vector<std::string>& names) {
    json object = json::object();
    for (const std::string& name : names) object[name] = 1;
    return object;
  };
  json root = object_of(keys.at("top"));
  root["camera"] = object_of(keys.at("camera"));
  root["lights"] = json::array({object_of(keys.at("light"))});
  json mesh = object_of(keys.at("mesh"));
  mesh["material"] = object_of(keys.at("material"));
  root["meshes"] = json::array({mesh});
  // The environment's object form, given in the top-level table's text.
  root["environment"] = json{{"file", 1}, {"builtin", 1}, {"rotation_deg", 1}, {"intensity", 1}};
  CHECK(unknown_scene_keys(root, "s.json").empty());
}

TEST_CASE("scene keys: a misspelt key is a warning with its path and the nearest key",
          "[scene][keys]") {
  const json root = json::parse(R"({
    "width": 8, "height": 8, "backgroud": [1, 1, 1], "_note": "the file's own", "extras": {},
    "camera": {"eye": [0, 0, 3], "fov": 40},
    "environment": {"builtin": "studio", "rotation": 30},
    "lights": ["gltf", {"type": "point", "intensty": 2}],
    "meshes": [{"obj": "a.obj", "colour": [1, 0, 0],
                "material": {"clearcot": 0.5, "_why": "notes are fine", "sheen": 1}},
               "not an object"]
  })");
  const std::vector<std::string> expected = {
      "s.json: backgroud: unknown key, ignored (did you mean 'background'?)",
      "s.json: camera.fov: unknown key, ignored (did you mean 'fovy_deg'?)",
      "s.json: environment.rotation: unknown key, ignored (did you mean 'rotation_deg'?)",
      "s.json: lights[1].intensty: unknown key, ignored (did you mean 'intensity'?)",
      "s.json: meshes[0].colour: unknown key, ignored (did you mean 'color'?)",
      "s.json: meshes[0].material.clearcot: unknown key, ignored (did you mean 'clearcoat'?)",
      "s.json: meshes[0].material.sheen: unknown key, ignored (did you mean 'sheen_color'?)"};
  CHECK(unknown_scene_keys(root, "s.json") == expected);
  // Far from every known key: no guess.
  CHECK(unknown_scene_keys(json{{"width", 1}, {"zzz", 1}}, "s.json") ==
        std::vector<std::string>{"s.json: zzz: unknown key, ignored"});
}

TEST_CASE("scene keys: load_scene returns them as warnings, and the scene still loads",
          "[scene][keys]") {
  covrast::test::TempDir dir("covrast-test-keys");
  covrast::test::write_text(dir.path() / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  covrast::test::write_text(dir.path() / "scene.json", R"({
    "width": 16, "height": 8,
    "camera": {"eye": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0],
               "fovy_deg": 45.0, "near": 0.5, "far": 10.0},
    "meshes": [{"obj": "tri.obj", "colr": [1, 0, 0]}]
  })");
  const covrast::Scene scene = covrast::load_scene(dir.path() / "scene.json");
  REQUIRE(scene.meshes.size() == 1);
  REQUIRE(scene.warnings.size() == 1);
  CHECK(scene.warnings[0] == (dir.path() / "scene.json").string() +
                                 ": meshes[0].colr: unknown key, ignored (did you mean 'color'?)");
}
