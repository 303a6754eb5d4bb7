// Tests of what a glTF file brings to a scene beyond its meshes (docs/scene-format.md):
// KHR_lights_punctual lights ("lights": "gltf"), orthographic cameras (glTF and scene JSON),
// rendering a mesh file without a scene file (automatic framing and the default light rig),
// and single-sided materials culled. Every file is written here.
#include <covrast/error.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "test_cli_run.hpp"
#include "test_gltf_files.hpp"
#include "test_tempdir.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using covrast::Light;
using covrast::LightType;
using covrast::test::GltfBuilder;
using nlohmann::json;

namespace {

constexpr double kPi = std::numbers::pi;

class TempDir : public covrast::test::TempDir {
 public:
  TempDir() : covrast::test::TempDir("covrast-test-gltfscene") {}
  fs::path write(const std::string& name, const std::string& contents) const {
    const fs::path file = path() / name;
    std::ofstream(file, std::ios::binary) << contents;
    return file;
  }
  covrast::Scene load(const json& scene) const {
    std::ofstream(path() / "scene.json") << scene.dump();
    return covrast::load_scene(path() / "scene.json");
  }
  std::string load_error(const json& scene) const {
    try {
      load(scene);
    } catch (const covrast::InputError& e) {
      return e.what();
    }
    FAIL("no InputError for " << scene.dump());
    return {};
  }
};

covrast::Image render(const covrast::Scene& scene, const char* mode = "coverage") {
  covrast::RenderOptions options;
  options.mode = covrast::parse_render_mode(mode);
  options.threads = 1;
  return covrast::render(scene, options).color;
}

/// The square [-1, 1]^2 at z = 0 facing +z (node 0), as a 4-vertex strip.
GltfBuilder square_file() {
  GltfBuilder b;
  const int positions = b.add_floats({-1, -1, 0, 1, -1, 0, -1, 1, 0, 1, 1, 0}, "VEC3");
  b.gltf["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", positions}}}, {"mode", 5}}}}}};
  b.gltf["scenes"] = {{{"nodes", {0}}}};
  b.gltf["nodes"] = {{{"mesh", 0}}};
  return b;
}

/// square_file with three lights: a directional one at node 1 (shining down -z), a point light
/// at node 3 = node 2's (1, 0, 0) + (0, 0, 2), and a spot at node 4 turned by -90 degrees
/// about x (shining down -y) at (0, 3, 0).
GltfBuilder lights_file() {
  GltfBuilder b = square_file();
  b.gltf["extensionsUsed"] = {"KHR_lights_punctual"};
  b.gltf["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"type", "directional"}, {"color", {1.0, 0.5, 0.25}}, {"intensity", 2.0}},
      {{"type", "point"}, {"intensity", 3.0}, {"range", 8.0}},
      {{"type", "spot"}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.6}}}}};
  const double h = std::sqrt(0.5);
  b.gltf["scenes"] = {{{"nodes", {0, 1, 2, 4}}}};
  b.gltf["nodes"] = {
      {{"mesh", 0}},
      {{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}},
      {{"translation", {1, 0, 0}}, {"children", {3}}},
      {{"translation", {0, 0, 2}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}},
      {{"translation", {0, 3, 0}},
       {"rotation", {-h, 0, 0, h}},
       {"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}}};
  return b;
}

json camera_json() {
  return {{"eye", {0, 0, 3}}, {"target", {0, 0, 0}}, {"up", {0, 1, 0}},
          {"fovy_deg", 45},   {"near", 0.5},         {"far", 20}};
}

json scene_json(const json& meshes, const json& lights) {
  json scene = {{"width", 24}, {"height", 24}, {"camera", camera_json()}, {"meshes", meshes}};
  if (!lights.is_null()) scene["lights"] = lights;
  return scene;
}

}  // namespace

TEST_CASE("KHR_lights_punctual lights join the scene with \"lights\": \"gltf\"", "[gltf][lights]") {
  TempDir dir;
  dir.write("lights.glb", lights_file().glb());
  // The entry moves the file by (0, 0, -1).
  const json entry = {{"gltf", "lights.glb"},
                      {"model", {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, -1}, {0, 0, 0, 1}}},
                      {"material", {{"model", "lambert"}}}};
  const json ambient = {{"type", "ambient"}, {"intensity", 0.1}};
  const covrast::Scene scene = dir.load(scene_json(json::array({entry}), {ambient, "gltf"}));
  REQUIRE(scene.lit);
  REQUIRE(scene.lights.size() == 4);
  CHECK(scene.lights[0].type == LightType::Ambient);  // the file's lights where "gltf" stands
  const Light& sun = scene.lights[1];
  CHECK(sun.type == LightType::Directional);
  CHECK(sun.direction == glm::dvec3(0, 0, -1));
  CHECK(sun.color_linear == glm::vec3(1.0f, 0.5f, 0.25f));
  CHECK(sun.intensity == 2.0);
  const Light& bulb = scene.lights[2];
  CHECK(bulb.type == LightType::Point);
  CHECK(bulb.position == glm::dvec3(1, 0, 1));  // (1, 0, 0) + (0, 0, 2) + (0, 0, -1)
  CHECK(bulb.range == 8.0);
  CHECK(bulb.intensity == 3.0);
  const Light& spot = scene.lights[3];
  CHECK(spot.type == LightType::Spot);
  CHECK(spot.position.y == Approx(3.0));
  CHECK(spot.position.z == Approx(-1.0));
  CHECK(spot.direction.x == Approx(0.0).margin(1e-12));
  CHECK(spot.direction.y == Approx(-1.0));
  CHECK(spot.direction.z == Approx(0.0).margin(1e-7));
  CHECK(spot.inner_cone_deg == Approx(0.2 * 180 / kPi));
  CHECK(spot.outer_cone_deg == Approx(0.6 * 180 / kPi));
  CHECK(spot.range == 0.0);

  // The same lights written in the scene give the same image.
  json explicit_lights = {
      ambient,
      {{"type", "directional"},
       {"direction", {0, 0, -1}},
       {"color", {1.0, 0.5, 0.25}},
       {"intensity", 2.0}},
      {{"type", "point"}, {"position", {1, 0, 1}}, {"intensity", 3.0}, {"range", 8.0}}};
  const covrast::Scene without_spot = dir.load(scene_json(json::array({entry}), explicit_lights));
  covrast::Scene from_file = scene;
  from_file.lights.pop_back();  // the spot, whose rotation is not exact in JSON numbers
  const covrast::Image image = render(from_file);
  CHECK(image.rgb == render(without_spot).rgb);
  // Lit: the sun alone gives (1, 0.5, 0.25) x 2 + 0.1 at least: red saturates at the centre.
  CHECK(int(image.pixel(12, 12)[0]) == 255);

  // Without "gltf" the file's lights are not used; a scene without "lights" stays unlit.
  CHECK(dir.load(scene_json(json::array({entry}), json::array({ambient}))).lights.size() == 1);
  CHECK_FALSE(dir.load(scene_json(json::array({entry}), nullptr)).lit);
  // "lights": "gltf" alone; twice the file, twice its lights.
  CHECK(dir.load(scene_json(json::array({entry, entry}), "gltf")).lights.size() == 6);
}

TEST_CASE("bad KHR_lights_punctual content is an InputError naming node and light",
          "[gltf][lights]") {
  TempDir dir;
  const auto error_of = [&](GltfBuilder b) {
    dir.write("bad.glb", b.glb());
    return dir.load_error(scene_json({{{"gltf", "bad.glb"}}}, "gltf"));
  };
  GltfBuilder b = lights_file();
  b.gltf["nodes"][1]["extensions"]["KHR_lights_punctual"]["light"] = 7;
  CHECK_THAT(error_of(b), Contains("bad.glb: node 1: light 7 does not exist (3 lights)"));
  b = lights_file();
  b.gltf["extensions"]["KHR_lights_punctual"]["lights"][2]["spot"]["innerConeAngle"] = 0.6;
  CHECK_THAT(error_of(b), Contains("bad.glb: node 4: light 2: cone angles must satisfy"));
  b = lights_file();
  b.gltf["extensions"]["KHR_lights_punctual"]["lights"][1]["intensity"] = -1;
  CHECK_THAT(error_of(b), Contains("node 3: light 1: intensity must be finite and >= 0"));
  b = lights_file();
  b.gltf["extensions"]["KHR_lights_punctual"]["lights"][0]["type"] = "area";
  CHECK_THAT(error_of(b), Contains("node 1: light 0: type must be"));
  b = lights_file();
  b.gltf["nodes"][4]["scale"] = {0, 0, 0};
  CHECK_THAT(error_of(b), Contains("scene.json: lights: light 2 of '"));
  dir.write("ok.glb", lights_file().glb());
  CHECK_THAT(dir.load_error(scene_json({{{"gltf", "ok.glb"}}}, {"gltf", "gltf"})),
             Contains("scene.json: lights[1]: \"gltf\" given twice"));
  CHECK_THAT(dir.load_error(scene_json({{{"gltf", "ok.glb"}}}, "sun")),
             Contains("scene.json: lights: expected an array or \"gltf\", got \"sun\""));
}
