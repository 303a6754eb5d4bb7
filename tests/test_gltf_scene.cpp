// Tests of what a glTF file brings to a scene beyond its meshes (docs/scene-format.md):
// KHR_lights_punctual lights ("lights": "gltf"), orthographic cameras (glTF and scene JSON),
// rendering a mesh file without a scene file (automatic framing and the default light rig),
// and single-sided materials culled. Every file is written here.
#include <covrast/error.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include "color/srgb8.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "test_cli_run.hpp"
#include "test_gltf_files.hpp"
#include "test_meshes.hpp"
#include "test_sphere_scene.hpp"
#include "test_tempdir.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using covrast::Light;
using covrast::LightType;
using covrast::test::GltfBuilder;
using covrast::test::render_mode;
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
  const covrast::Image image = render_mode(from_file, "coverage", 1);
  CHECK(image.rgb == render_mode(without_spot, "coverage", 1).rgb);
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

namespace {

/// An orthographic camera at (0, 0, 5) looking at the origin with ymag 2:
/// the 40 x 20 image spans x in [-4, 4] and y in [-2, 2], 0.2 world units per pixel.
json ortho_camera() {
  return {
      {"eye", {0, 0, 5}}, {"target", {0, 0, 0}}, {"up", {0, 1, 0}}, {"projection", "orthographic"},
      {"ymag", 2},        {"near", 1},           {"far", 10}};
}

/// A quad over x in [-1, 1.4], y in [-0.6, 1], tilted in depth (z from -1 to 1 along x), so
/// that only a parallel projection gives it straight pixel-aligned edges.
const char* kTiltedQuad = "v -1 -0.6 -1\nv 1.4 -0.6 1\nv 1.4 1 1\nv -1 1 -1\nf 1 2 3 4\n";

}  // namespace

TEST_CASE("an orthographic camera covers exactly the predicted pixels", "[camera][ortho]") {
  TempDir dir;
  dir.write("quad.obj", kTiltedQuad);
  const json scene_json = {{"width", 40},
                           {"height", 20},
                           {"camera", ortho_camera()},
                           {"meshes", {{{"obj", "quad.obj"}, {"color", {1, 1, 1}}}}}};
  const covrast::Scene scene = dir.load(scene_json);
  REQUIRE(scene.camera.orthographic);
  REQUIRE(scene.camera.ymag == 2.0);
  // x = -1 .. 1.4 is columns (x + 4) / 0.2 = 15 .. 27, y = 1 .. -0.6 rows (2 - y) / 0.2 = 5 .. 13.
  for (const char* mode : {"coverage", "aliased", "ssaa:4", "reference"}) {
    const covrast::Image image = render_mode(scene, mode, 1);
    int wrong = 0;
    for (int y = 0; y < 20; ++y) {
      for (int x = 0; x < 40; ++x) {
        const bool inside = x >= 15 && x < 27 && y >= 5 && y < 13;
        wrong += image.pixel(x, y)[1] != (inside ? 255 : 0);
      }
    }
    INFO(mode);
    CHECK(wrong == 0);
  }
}

TEST_CASE("orthographic shading sees every point from the same direction", "[camera][ortho]") {
  TempDir dir;
  dir.write("quad.obj", "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n");
  json scene_json = {{"width", 40},
                     {"height", 20},
                     {"camera", ortho_camera()},
                     {"meshes",
                      {{{"obj", "quad.obj"},
                        {"color", {0.5, 0.5, 0.5}},
                        {"material", {{"model", "blinn-phong"}, {"shininess", 4}}}}}},
                     {"lights", {{{"type", "directional"}, {"direction", {-0.3, -0.2, -1}}}}}};
  // A plane, a directional light and parallel view rays: n, l and v are the same everywhere,
  // so every covered pixel has one colour (a perspective view varies the highlight).
  const auto colours = [&](const json& s) {
    const covrast::Image image = render_mode(dir.load(s), "aliased", 1);
    std::vector<int> seen;
    for (int y = 0; y < 20; ++y) {
      for (int x = 0; x < 40; ++x) {
        const int c = image.pixel(x, y)[0] << 16 | image.pixel(x, y)[1] << 8 | image.pixel(x, y)[2];
        if (c != 0 && std::find(seen.begin(), seen.end(), c) == seen.end()) seen.push_back(c);
      }
    }
    return seen;
  };
  CHECK(colours(scene_json).size() == 1);
  scene_json["camera"] = {{"eye", {0, 0, 2}}, {"target", {0, 0, 0}}, {"up", {0, 1, 0}},
                          {"fovy_deg", 90},   {"near", 0.5},         {"far", 10}};
  CHECK(colours(scene_json).size() > 10);
}

TEST_CASE("a glTF orthographic camera renders as the same scene camera", "[camera][ortho]") {
  TempDir dir;
  dir.write("quad.obj", kTiltedQuad);
  GltfBuilder b = square_file();
  b.gltf["cameras"] = {{{"type", "orthographic"},
                        {"orthographic", {{"xmag", 9}, {"ymag", 2}, {"znear", 1}, {"zfar", 10}}}}};
  b.gltf["scenes"] = {{{"nodes", {0, 1}}}};
  b.gltf["nodes"] = {{{"mesh", 0}, {"scale", {0.01, 0.01, 0.01}}},
                     {{"translation", {0, 0, 5}}, {"camera", 0}}};
  dir.write("camera.glb", b.glb());
  const json meshes = {{{"obj", "quad.obj"}, {"color", {1, 1, 1}}}, {{"gltf", "camera.glb"}}};
  const covrast::Scene from_file =
      dir.load({{"width", 40}, {"height", 20}, {"camera", {{"gltf", 0}}}, {"meshes", meshes}});
  CHECK(from_file.camera.orthographic);
  CHECK(from_file.camera.ymag == 2.0);
  CHECK(from_file.camera.eye == glm::dvec3(0, 0, 5));
  CHECK(from_file.camera.near == 1.0);
  CHECK(from_file.camera.far == 10.0);
  const covrast::Scene written =
      dir.load({{"width", 40}, {"height", 20}, {"camera", ortho_camera()}, {"meshes", meshes}});
  CHECK(render_mode(from_file, "coverage", 1).rgb == render_mode(written, "coverage", 1).rgb);

  b.gltf["cameras"][0]["orthographic"]["ymag"] = 0;
  dir.write("camera.glb", b.glb());
  CHECK_THAT(dir.load_error(
                 {{"width", 40}, {"height", 20}, {"camera", {{"gltf", 0}}}, {"meshes", meshes}}),
             Contains("camera.gltf: camera 0 of 'camera.glb' (orthographic) needs ymag > 0"));
}

TEST_CASE("bad orthographic camera keys are InputErrors", "[camera][ortho]") {
  TempDir dir;
  const auto error_of = [&](const json& patch) {
    json camera = ortho_camera();
    camera.merge_patch(patch);
    return dir.load_error(
        {{"width", 8}, {"height", 8}, {"camera", camera}, {"meshes", json::array()}});
  };
  CHECK_THAT(error_of({{"projection", "fisheye"}}),
             Contains("camera.projection: expected \"perspective\" or \"orthographic\""));
  CHECK_THAT(error_of({{"fovy_deg", 40}}),
             Contains("camera.fovy_deg: an orthographic camera takes ymag"));
  CHECK_THAT(error_of({{"ymag", nullptr}}), Contains("camera.ymag: missing"));
  CHECK_THAT(error_of({{"ymag", 0}}), Contains("camera.ymag: must be > 0, got 0"));
  CHECK_THAT(error_of({{"near", -1}}), Contains("camera.near: must be >= 0, got -1"));
  CHECK_THAT(error_of({{"projection", "perspective"}, {"fovy_deg", 40}}),
             Contains("camera.ymag: only for an orthographic camera"));
  CHECK(
      dir.load({{"width", 8}, {"height", 8}, {"camera", ortho_camera()}, {"meshes", json::array()}})
          .camera.orthographic);
}

namespace {

/// A closed cube [-1, 1]^3 moved by (2, 1, 0), as OBJ quads (counter-clockwise from outside).
const char* kCubeObj =
    "v 1 0 -1\nv 3 0 -1\nv 3 2 -1\nv 1 2 -1\nv 1 0 1\nv 3 0 1\nv 3 2 1\nv 1 2 1\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";

}  // namespace

namespace {

/// Irradiance of the studio environment on a surface facing n, summed texel by texel:
/// sum_t L_t max(0, n . d_t) Omega_t (docs/environments.md).
glm::dvec3 studio_irradiance(const glm::dvec3& n) {
  glm::dvec3 e(0.0);
  covrast::test::for_each_texel(*covrast::studio_environment(),
                                [&](const glm::dvec3& d, double omega, const glm::dvec3& l) {
                                  e += l * (std::max(0.0, glm::dot(n, d)) * omega);
                                });
  return e;
}

}  // namespace

TEST_CASE("a mesh file without a scene: framed from +z and lit by the studio environment",
          "[cli][automatic]") {
  TempDir dir;
  const fs::path cube = dir.write("cube.obj", kCubeObj);
  const covrast::Scene scene = covrast::load_mesh_scene(cube, 64, 48);
  CHECK(scene.width == 64);
  CHECK(scene.height == 48);
  // Centre (2, 1, 0), bounding sphere radius sqrt(3); the vertical half angle (20 degrees) is
  // the smaller one: distance = 1.05 sqrt(3) / sin(20 deg).
  const double distance = 1.05 * std::sqrt(3.0) / std::sin(20.0 * kPi / 180.0);
  CHECK(scene.camera.target == glm::dvec3(2, 1, 0));
  CHECK(scene.camera.eye.x == 2.0);
  CHECK(scene.camera.eye.y == 1.0);
  CHECK(scene.camera.eye.z == Approx(distance).epsilon(1e-12));
  CHECK(scene.camera.fovy_deg == 40.0);
  CHECK(scene.camera.near == Approx(distance - 1.5 * std::sqrt(3.0)));
  CHECK(scene.camera.far == Approx(distance + 1.5 * std::sqrt(3.0)));
  // No lights: the built-in studio environment, unturned, at intensity 1.
  REQUIRE(scene.lit);
  CHECK(scene.lights.empty());
  REQUIRE(scene.environment.has_value());
  CHECK(scene.environment->map == covrast::studio_environment());
  CHECK(scene.environment->rotation_deg == 0.0);
  CHECK(scene.environment->intensity == 1.0);
  // A tall image: the horizontal half angle is the smaller one.
  const covrast::Scene tall = covrast::load_mesh_scene(cube, 20, 80);
  const double half_h = std::atan(std::tan(20.0 * kPi / 180.0) * 0.25);
  CHECK(tall.camera.eye.z == Approx(1.05 * std::sqrt(3.0) / std::sin(half_h)).epsilon(1e-12));

  // Through the command line: the cube lies inside the image, with background all round it,
  // and its front face (facing the camera, lambert) is base x E(+z) / pi.
  const auto result = covrast::test::run_cli_in(
      dir.path(), {"render", "cube.obj", "-o", "out.png", "--size", "64x48"}, true);
  REQUIRE(result.exit_code == 0);
  const covrast::Image image = covrast::read_png(dir / "out.png");
  REQUIRE(image.width == 64);
  REQUIRE(image.height == 48);
  int border_not_background = 0;
  for (int x = 0; x < 64; ++x) {
    for (int y = 0; y < 48; ++y) {
      if (x != 0 && x != 63 && y != 0 && y != 47) continue;
      const std::uint8_t* p = image.pixel(x, y);
      border_not_background += p[0] != 46 || p[1] != 46 || p[2] != 51;  // sRGB (0.18, 0.18, 0.2)
    }
  }
  CHECK(border_not_background == 0);
  const glm::dvec3 front =
      glm::dvec3(scene.meshes[0].color_linear) * studio_irradiance({0.0, 0.0, 1.0}) / kPi;
  for (int c = 0; c < 3; ++c) {
    CHECK(std::abs(int(image.pixel(32, 24)[c]) -
                   int(covrast::detail::encode_srgb8(float(front[c])))) <= 1);
  }
  const auto missing =
      covrast::test::run_cli_in(dir.path(), {"render", "gone.glb", "-o", "x.png"}, true);
  CHECK(missing.exit_code == 2);
  CHECK_THAT(missing.err, Contains("gone.glb: cannot open: No such file or directory"));
}

TEST_CASE("a glTF file without a scene: its camera and its lights when it has them",
          "[cli][automatic]") {
  TempDir dir;
  GltfBuilder b = lights_file();
  b.gltf["cameras"] = {
      {{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.5}, {"zfar", 50}}}}};
  b.gltf["nodes"].push_back({{"translation", {0, 0, 7}}, {"camera", 0}});
  b.gltf["scenes"][0]["nodes"].push_back(5);
  const covrast::Scene scene = covrast::load_mesh_scene(dir.write("lit.glb", b.glb()));
  CHECK(scene.width == 640);
  CHECK(scene.height == 360);
  CHECK(scene.camera.eye == glm::dvec3(0, 0, 7));
  CHECK(scene.camera.fovy_deg == Approx(0.5 * 180 / kPi));
  REQUIRE(scene.lights.size() == 3);  // the file's, no rig
  CHECK(scene.lights[1].type == LightType::Point);
  CHECK(scene.lights[1].position == glm::dvec3(1, 0, 2));
  CHECK_FALSE(scene.environment.has_value());
  // Without lights and camera: the studio environment, and the framing camera.
  const covrast::Scene plain =
      covrast::load_mesh_scene(dir.write("plain.glb", square_file().glb()));
  CHECK(plain.lights.empty());
  CHECK(plain.environment.has_value());
  CHECK(plain.camera.target == glm::dvec3(0, 0, 0));
  CHECK(plain.camera.eye.z == Approx(1.05 * std::sqrt(2.0) / std::sin(20.0 * kPi / 180.0)));
  CHECK_THROWS_WITH(covrast::load_mesh_scene(dir.write("a.stl", "solid")),
                    Contains("a.stl: unknown mesh format"));
}

namespace {

/// Two squares side by side facing +z: x in [-2, -0.5] with material 0, x in [0.5, 2] with
/// material 1.
GltfBuilder two_squares(bool double_sided_0, bool double_sided_1) {
  GltfBuilder b;
  const int left = b.add_floats({-2, -1, 0, -0.5f, -1, 0, -2, 1, 0, -0.5f, 1, 0}, "VEC3");
  const int right = b.add_floats({0.5f, -1, 0, 2, -1, 0, 0.5f, 1, 0, 2, 1, 0}, "VEC3");
  b.gltf["materials"] = {{{"doubleSided", double_sided_0}}, {{"doubleSided", double_sided_1}}};
  b.single_mesh({{{"attributes", {{"POSITION", left}}}, {"mode", 5}, {"material", 0}},
                 {{"attributes", {{"POSITION", right}}}, {"mode", 5}, {"material", 1}}});
  return b;
}

/// How many pixels are not background in the left and the right half of the image.
std::pair<int, int> covered_halves(const covrast::Image& image) {
  std::pair<int, int> count{0, 0};
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.pixel(x, y);
      if (p[0] != 0 || p[1] != 0 || p[2] != 0) (x < image.width / 2 ? count.first : count.second)++;
    }
  }
  return count;
}

}  // namespace

TEST_CASE("back faces of single-sided glTF materials are culled in every mode",
          "[gltf][single_sided]") {
  TempDir dir;
  dir.write("one.glb", two_squares(false, false).glb());
  dir.write("mixed.glb", two_squares(false, true).glb());
  dir.write("both.glb", two_squares(true, true).glb());
  const auto scene = [&](const char* file, double eye_z, const json& extra, bool lit) {
    json entry = {{"gltf", file}, {"color", {1, 1, 1}}};
    entry.update(extra);
    json camera = camera_json();
    camera["eye"] = {0, 0, eye_z};
    json s = {{"width", 40}, {"height", 20}, {"camera", camera}, {"meshes", json::array({entry})}};
    if (lit) s["lights"] = {{{"type", "ambient"}, {"intensity", 1}}};
    return dir.load(s);
  };
  const json mirror = {{"model", {{-1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}}};
  for (const char* mode :
       {"coverage", "coverage-blend", "aliased", "msaa:4", "ssaa:4", "reference"}) {
    for (const bool lit : {false, true}) {
      INFO(mode << (lit ? " lit" : " unlit"));
      // From the front both squares show; from behind single-sided ones vanish.
      const auto front =
          covered_halves(render_mode(scene("one.glb", 3, json::object(), lit), mode, 1));
      CHECK(front.first > 50);
      CHECK(front.second > 50);
      CHECK(covered_halves(render_mode(scene("one.glb", -3, json::object(), lit), mode, 1)) ==
            std::pair<int, int>{0, 0});
      // Per material: seen from behind (x flips on screen) only the double-sided right square
      // shows, now in the left half.
      const auto mixed =
          covered_halves(render_mode(scene("mixed.glb", -3, json::object(), lit), mode, 1));
      CHECK(mixed == std::pair<int, int>{front.second, 0});
      CHECK(covered_halves(render_mode(scene("both.glb", -3, json::object(), lit), mode, 1)) ==
            std::pair<int, int>{front.second, front.first});
      // A mirroring model matrix keeps the front facing +z (clockwise on screen now).
      CHECK(covered_halves(render_mode(scene("one.glb", 3, mirror, lit), mode, 1)) ==
            std::pair<int, int>{front.second, front.first});
      CHECK(covered_halves(render_mode(scene("one.glb", -3, mirror, lit), mode, 1)) ==
            std::pair<int, int>{0, 0});
      // The scene may make them double-sided.
      const json both_sides = {{"material", {{"double_sided", true}}}};
      CHECK(covered_halves(render_mode(scene("one.glb", -3, both_sides, lit), mode, 1)).first > 50);
    }
  }
}
