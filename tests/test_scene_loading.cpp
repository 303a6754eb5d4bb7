// Tests of scene loading (include/covrast/scene.hpp, src/scene): the JSON scene format, the OBJ
// subset (index forms, fan order, vertex colours), glTF (.gltf with a data: URI and .glb written
// by hand here), instancing, the row-major model matrix, NaN/Inf triangle dropping and every
// InputError case. Each test writes its files into a fresh temporary directory.
#include <covrast/error.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <unistd.h>

#include "test_gltf_files.hpp"
#include "test_tempdir.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using covrast::ColorSource;
using covrast::InputError;
using covrast::srgb_to_linear;
using covrast::test::base64;
using covrast::test::make_glb;
using covrast::test::put_f32;
using covrast::test::put_u16;
using covrast::test::put_u8;
using nlohmann::json;

namespace {

/// A fresh directory under the system temp dir, removed again at scope exit.
class TempDir : public covrast::test::TempDir {
 public:
  TempDir() : covrast::test::TempDir("covrast-test-scene") {}

  fs::path write(const std::string& name, const std::string& contents) const {
    const fs::path file = path() / name;
    fs::create_directories(file.parent_path());
    std::ofstream out(file, std::ios::binary);
    out << contents;
    return file;
  }
  fs::path write_json(const std::string& name, const json& value) const {
    return write(name, value.dump(2));
  }
};

/// The message of the InputError that loading `scene` throws; fails the test if none is thrown.
std::string load_error(const fs::path& scene) {
  try {
    covrast::load_scene(scene);
  } catch (const InputError& e) {
    const std::string message = e.what();
    CHECK(message.find('\n') == std::string::npos);  // one line
    return message;
  }
  FAIL("expected an InputError from " << scene);
  return {};
}

glm::vec3 srgb3(float r, float g, float b) {
  return {srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b)};
}

const char* const kTriangleObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

/// A minimal valid scene as JSON, to be modified by the error tests.
json valid_scene() {
  return json::parse(R"({
    "width": 64, "height": 32,
    "camera": {"eye": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0],
               "fovy_deg": 45.0, "near": 0.5, "far": 10.0},
    "meshes": [{"obj": "tri.obj"}]
  })");
}

}  // namespace

TEST_CASE("the example scene of the format loads with every field", "[scene]") {
  TempDir dir;
  // Tetrahedron (4 triangles) and a quad + pentagon fan (2 + 3 triangles).
  dir.write("sphere.obj",
            "v 0 0 1\nv 1 0 -1\nv -1 0 -1\nv 0 1 0\nf 1 2 3\nf 1 2 4\nf 2 3 4\nf 3 1 4\n");
  dir.write("fan.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 1 0\nf 1 2 3 4\nf 1 2 3 4 5\n");
  const fs::path scene_path = dir.write("scene.json", R"({
  "width": 640, "height": 360,
  "background": [0.06, 0.12, 0.38],
  "camera": {"eye": [0.45, 0.6, 3.3], "target": [0, 0, 0], "up": [0, 1, 0],
             "fovy_deg": 45.0, "near": 0.5, "far": 10.0},
  "meshes": [
    {"obj": "sphere.obj", "color": [1.0, 0.67, 0.13]},
    {"obj": "fan.obj", "color": "per_triangle",
     "model": [[1,0,0,-1.9], [0,1,0,-1.25], [0,0,1,0.35], [0,0,0,1]]}
  ]
})");
  const covrast::Scene scene = covrast::load_scene(scene_path);
  REQUIRE(scene.source == scene_path);
  REQUIRE(scene.width == 640);
  REQUIRE(scene.height == 360);
  REQUIRE(scene.background_linear == srgb3(0.06f, 0.12f, 0.38f));
  REQUIRE(scene.camera.eye == glm::dvec3(0.45, 0.6, 3.3));
  REQUIRE(scene.camera.target == glm::dvec3(0.0));
  REQUIRE(scene.camera.up == glm::dvec3(0.0, 1.0, 0.0));
  REQUIRE(scene.camera.fovy_deg == 45.0);
  REQUIRE(scene.camera.near == 0.5);
  REQUIRE(scene.camera.far == 10.0);
  REQUIRE(scene.meshes.size() == 2);

  const covrast::MeshInstance& sphere = scene.meshes[0];
  REQUIRE(sphere.color_source == ColorSource::Uniform);
  REQUIRE(sphere.color_linear == srgb3(1.0f, 0.67f, 0.13f));
  REQUIRE(sphere.model == glm::dmat4(1.0));
  REQUIRE(sphere.mesh->triangle_count() == 4);
  REQUIRE(sphere.mesh->colors_linear.empty());

  const covrast::MeshInstance& fan = scene.meshes[1];
  REQUIRE(fan.color_source == ColorSource::PerTriangle);
  REQUIRE(fan.model[3] == glm::dvec4(-1.9, -1.25, 0.35, 1.0));
  REQUIRE(fan.mesh->triangle_count() == 5);

  REQUIRE(scene.triangle_count() == 9);
  REQUIRE(scene.dropped_nonfinite_triangles == 0);
  REQUIRE(scene.warnings.empty());
}

TEST_CASE("OBJ index forms, negative indices and fan split order", "[scene]") {
  TempDir dir;
  const fs::path obj = dir.write("forms.obj",
                                 "# every index form; vt/vn/o/g/s/usemtl/mtllib are ignored\r\n"
                                 "mtllib missing.mtl\r\n"
                                 "o thing\r\n"
                                 "g group\r\n"
                                 "s 1\r\n"
                                 "usemtl nothing\r\n"
                                 "v 0 0 0\r\n"
                                 "v 1 0 0\r\n"
                                 "v 1 1 0\r\n"
                                 "vt 0 0\r\n"
                                 "vt 1 0\r\n"
                                 "vt 1 1\r\n"
                                 "vn 0 0 1\r\n"
                                 "f -3 -2 -1\r\n"  // relative to the 3 vertices so far
                                 "v 0 1 0\r\n"
                                 "v -1 0.5 0\r\n"
                                 "v +2 -0.5 1e0\r\n"
                                 "f 1 2 3\r\n"
                                 "f 1/1 2/2 3/3\r\n"
                                 "f 1//1 2//1 3//1\r\n"
                                 "f 1/1/1 2/2/1 3/3/1   # trailing comment\r\n"
                                 "f -1 -2 -3\r\n"     // relative to 6 vertices: 6 5 4
                                 "f 1 2 3 4\r\n"      // quad
                                 "\tf 2 3 4 5 6\r\n"  // pentagon, leading tab
                                 "l 1 2\r\n");
  const auto mesh = covrast::load_mesh(obj);
  REQUIRE(mesh->source == obj.string());
  REQUIRE(mesh->positions.size() == 6);
  REQUIRE(mesh->positions[5] == glm::vec3(2.0f, -0.5f, 1.0f));
  REQUIRE(mesh->colors_linear.empty());
  const std::vector<std::uint32_t> expected = {
      0, 1, 2,                    // f -3 -2 -1
      0, 1, 2,                    // f 1 2 3
      0, 1, 2,                    // f 1/1 ...
      0, 1, 2,                    // f 1//1 ...
      0, 1, 2,                    // f 1/1/1 ...
      5, 4, 3,                    // f -1 -2 -3
      0, 1, 2, 0, 2, 3,           // quad: (0,1,2) (0,2,3)
      1, 2, 3, 1, 3, 4, 1, 4, 5,  // pentagon: (0,k,k+1) on 2 3 4 5 6
  };
  REQUIRE(mesh->indices == expected);
  REQUIRE(mesh->triangle_count() == 11);
}

TEST_CASE("OBJ forward references are resolved against the whole file", "[scene]") {
  TempDir dir;
  const fs::path obj = dir.write("forward.obj", "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
  const auto mesh = covrast::load_mesh(obj);
  REQUIRE(mesh->indices == std::vector<std::uint32_t>{0, 1, 2});
}

TEST_CASE("OBJ vertex colours are sRGB and select the colour source", "[scene]") {
  TempDir dir;
  dir.write("colored.obj", "v 0 0 0 1 0.5 0\nv 1 0 0 0 0 1\nv 0 1 0 0.2 0.4 0.6\nf 1 2 3\n");
  dir.write("tri.obj", kTriangleObj);
  const auto mesh = covrast::load_mesh(dir.path() / "colored.obj");
  REQUIRE(mesh->colors_linear.size() == 3);
  REQUIRE(mesh->colors_linear[0] == srgb3(1.0f, 0.5f, 0.0f));
  REQUIRE(mesh->colors_linear[1] == glm::vec3(0.0f, 0.0f, 1.0f));
  REQUIRE(mesh->colors_linear[2] == srgb3(0.2f, 0.4f, 0.6f));

  json scene = valid_scene();
  scene["meshes"] = json::array({
      {{"obj", "colored.obj"}},                        // absent: vertex colours
      {{"obj", "colored.obj"}, {"color", "vertex"}},   // explicit
      {{"obj", "colored.obj"}, {"color", {0, 1, 0}}},  // uniform wins
      {{"obj", "tri.obj"}},                            // absent, no colours: white
  });
  const covrast::Scene loaded = covrast::load_scene(dir.write_json("scene.json", scene));
  REQUIRE(loaded.meshes.size() == 4);
  REQUIRE(loaded.meshes[0].color_source == ColorSource::Vertex);
  REQUIRE(loaded.meshes[1].color_source == ColorSource::Vertex);
  REQUIRE(loaded.meshes[2].color_source == ColorSource::Uniform);
  REQUIRE(loaded.meshes[2].color_linear == glm::vec3(0.0f, 1.0f, 0.0f));
  REQUIRE(loaded.meshes[3].color_source == ColorSource::Uniform);
  REQUIRE(loaded.meshes[3].color_linear == glm::vec3(1.0f));
  REQUIRE(loaded.background_linear == glm::vec3(0.0f));  // default background

  scene["meshes"] = json::array({{{"obj", "tri.obj"}, {"color", "vertex"}}});
  const std::string message = load_error(dir.write_json("scene.json", scene));
  REQUIRE_THAT(message, Contains("scene.json") && Contains("meshes[0].color") &&
                            Contains("no vertex colours"));
}

TEST_CASE("instances of one file share one MeshData", "[scene]") {
  TempDir dir;
  dir.write("tri.obj", kTriangleObj);
  dir.write("sub/quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  json scene = valid_scene();
  scene["meshes"] = json::array({
      {{"obj", "tri.obj"}},
      {{"obj", "sub/quad.obj"}},
      {{"obj", "./sub/../tri.obj"}, {"color", "per_triangle"}},
      {{"obj", "sub/quad.obj"}, {"model", {1, 0, 0, 5, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}},
  });
  const covrast::Scene loaded = covrast::load_scene(dir.write_json("scene.json", scene));
  REQUIRE(loaded.meshes.size() == 4);
  REQUIRE(loaded.meshes[0].mesh == loaded.meshes[2].mesh);
  REQUIRE(loaded.meshes[1].mesh == loaded.meshes[3].mesh);
  REQUIRE(loaded.meshes[0].mesh != loaded.meshes[1].mesh);
  REQUIRE(loaded.meshes[2].color_source == ColorSource::PerTriangle);
  REQUIRE(loaded.meshes[3].model[3] == glm::dvec4(5.0, 0.0, 0.0, 1.0));
  REQUIRE(loaded.triangle_count() == 1 + 2 + 1 + 2);
}

TEST_CASE("the model matrix is row-major in the file and column-major in GLM", "[scene]") {
  TempDir dir;
  dir.write("tri.obj", kTriangleObj);
  // Rotation by +90 degrees about z (x -> y) then translation (10, 20, 30).
  const json rows = {{0, -1, 0, 10}, {1, 0, 0, 20}, {0, 0, 1, 30}, {0, 0, 0, 1}};
  const json flat = {0, -1, 0, 10, 1, 0, 0, 20, 0, 0, 1, 30, 0, 0, 0, 1};
  json scene = valid_scene();
  scene["meshes"] =
      json::array({{{"obj", "tri.obj"}, {"model", rows}}, {{"obj", "tri.obj"}, {"model", flat}}});
  const covrast::Scene loaded = covrast::load_scene(dir.write_json("scene.json", scene));
  const glm::dmat4& m = loaded.meshes[0].model;
  REQUIRE(m[3] == glm::dvec4(10.0, 20.0, 30.0, 1.0));  // translation column
  REQUIRE(m[0] == glm::dvec4(0.0, 1.0, 0.0, 0.0));     // image of x
  REQUIRE(m[1] == glm::dvec4(-1.0, 0.0, 0.0, 0.0));    // image of y
  REQUIRE(m * glm::dvec4(1.0, 0.0, 0.0, 1.0) == glm::dvec4(10.0, 21.0, 30.0, 1.0));
  REQUIRE(loaded.meshes[1].model == m);
}

TEST_CASE("an empty meshes array is a valid scene", "[scene]") {
  TempDir dir;
  json scene = valid_scene();
  scene["meshes"] = json::array();
  scene["background"] = {1, 1, 1};
  const covrast::Scene loaded = covrast::load_scene(dir.write_json("scene.json", scene));
  REQUIRE(loaded.meshes.empty());
  REQUIRE(loaded.triangle_count() == 0);
  REQUIRE(loaded.background_linear == glm::vec3(1.0f));
}

TEST_CASE("malformed JSON reports line and column", "[scene]") {
  TempDir dir;
  // Line 3 is `  "height" 360,`: the ':' is missing; nlohmann stops on the number 360,
  // whose last byte is in column 14.
  const fs::path bad = dir.write("bad.json", "{\n  \"width\": 64,\n  \"height\" 360,\n}\n");
  const std::string message = load_error(bad);
  REQUIRE_THAT(message, Contains("bad.json:3:14: "));
  REQUIRE_THAT(message, Contains("expected ':'"));

  // Truncated file: the error is at the end, on line 2.
  const fs::path truncated = dir.write("truncated.json", "{\"width\": 64,\n  \"height\": ");
  REQUIRE_THAT(load_error(truncated), Contains("truncated.json:2:"));

  const fs::path top = dir.write("array.json", "[1, 2]");
  REQUIRE_THAT(load_error(top), Contains("array.json") && Contains("object"));

  REQUIRE_THAT(load_error(dir.path() / "absent.json"),
               Contains("absent.json") && Contains("No such file or directory"));
}

TEST_CASE("bad scene fields are InputErrors naming file and key", "[scene]") {
  TempDir dir;
  dir.write("tri.obj", kTriangleObj);
  dir.write("plain.txt", "not a mesh\n");
  struct Case {
    const char* description;
    json scene;
    std::vector<std::string> expected;
  };
  std::vector<Case> cases;
  const auto with = [](const json::json_pointer& at, json value) {
    json scene = valid_scene();
    scene[at] = std::move(value);
    return scene;
  };
  const auto without = [](const json::json_pointer& parent, const std::string& key) {
    json scene = valid_scene();
    scene[parent].erase(key);
    return scene;
  };
  using P = json::json_pointer;
  cases.push_back({"width 0", with(P("/width"), 0), {"width", "16384"}});
  cases.push_back({"width negative", with(P("/width"), -5), {"width", "16384"}});
  cases.push_back({"width fractional", with(P("/width"), 640.5), {"width", "16384"}});
  cases.push_back({"width too large", with(P("/width"), 16385), {"width", "16384"}});
  cases.push_back({"width string", with(P("/width"), "640"), {"width", "16384"}});
  cases.push_back({"height huge", with(P("/height"), 1e30), {"height", "16384"}});
  cases.push_back({"height missing", without(P(""), "height"), {"height: missing"}});
  cases.push_back({"camera missing", without(P(""), "camera"), {"camera: missing"}});
  cases.push_back({"near missing", without(P("/camera"), "near"), {"camera.near: missing"}});
  cases.push_back({"eye too short", with(P("/camera/eye"), {0, 1}), {"camera.eye", "[x,y,z]"}});
  cases.push_back({"eye component", with(P("/camera/eye"), {0, "a", 1}), {"camera.eye[1]"}});
  cases.push_back({"fovy 0", with(P("/camera/fovy_deg"), 0), {"camera.fovy_deg"}});
  cases.push_back({"fovy 180", with(P("/camera/fovy_deg"), 180), {"camera.fovy_deg"}});
  cases.push_back({"near 0", with(P("/camera/near"), 0), {"camera.near"}});
  cases.push_back({"far below near", with(P("/camera/far"), 0.25), {"camera.far"}});
  cases.push_back({"eye at target", with(P("/camera/eye"), {0, 0, 0}), {"camera", "eye"}});
  cases.push_back({"up along view", with(P("/camera/up"), {0, 0, -2}), {"camera.up", "parallel"}});
  cases.push_back({"up zero", with(P("/camera/up"), {0, 0, 0}), {"camera.up"}});
  cases.push_back({"background range", with(P("/background"), {0, 1.5, 0}), {"background[1]"}});
  cases.push_back({"meshes missing", without(P(""), "meshes"), {"meshes: missing"}});
  cases.push_back({"meshes object", with(P("/meshes"), json::object()), {"meshes", "array"}});
  cases.push_back({"mesh not object", with(P("/meshes/0"), 5), {"meshes[0]", "object"}});
  cases.push_back({"no file",
                   with(P("/meshes/0"), {{"color", {1, 1, 1}}}),
                   {"meshes[0]", "\"obj\" or \"gltf\""}});
  cases.push_back({"both files", with(P("/meshes/0/gltf"), "tri.gltf"), {"meshes[0]", "not both"}});
  cases.push_back({"obj not string", with(P("/meshes/0/obj"), 3), {"meshes[0].obj"}});
  cases.push_back({"missing obj",
                   with(P("/meshes/0/obj"), "sphere.obj"),
                   {"meshes[0]: cannot open 'sphere.obj': No such file or directory"}});
  cases.push_back(
      {"obj is a directory", with(P("/meshes/0/obj"), "."), {"meshes[0]: cannot open '.'"}});
  cases.push_back({"bad color word",
                   with(P("/meshes/0/color"), "red"),
                   {"meshes[0].color", "expected [r,g,b]", "per_triangle"}});
  cases.push_back(
      {"color two numbers", with(P("/meshes/0/color"), {1, 1}), {"meshes[0].color", "[r,g,b]"}});
  cases.push_back({"color out of range",
                   with(P("/meshes/0/color"), {1, 2, 0}),
                   {"meshes[0].color[1]", "0..1"}});
  cases.push_back({"model 3 rows",
                   with(P("/meshes/0/model"), {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}),
                   {"meshes[0].model"}});
  cases.push_back(
      {"model row short",
       with(P("/meshes/0/model"), {{1, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}),
       {"meshes[0].model[0]"}});
  cases.push_back({"model projective",
                   with(P("/meshes/0/model"), {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1}),
                   {"meshes[0].model", "[0,0,0,1]"}});
  cases.push_back({"second mesh color",
                   [] {
                     json scene = valid_scene();
                     scene["meshes"].push_back({{"obj", "tri.obj"}, {"color", true}});
                     return scene;
                   }(),
                   {"meshes[1].color"}});

  for (const Case& c : cases) {
    INFO(c.description);
    const std::string message = load_error(dir.write_json("scene.json", c.scene));
    INFO(message);
    CHECK_THAT(message, Contains("scene.json: "));
    for (const std::string& part : c.expected) CHECK_THAT(message, Contains(part));
  }
}

TEST_CASE("bad OBJ content is an InputError with file and line", "[scene]") {
  TempDir dir;
  struct Case {
    const char* obj;
    std::string expected;
  };
  const Case cases[] = {
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
       "mesh.obj:4: face index 4 out of range (3 vertices)"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 0 1 2\n",
       "mesh.obj:5: face index 0 out of range (3 vertices)"},
      {"v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n",
       "mesh.obj:3: face index -3 out of range (2 vertices)"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 3 2 9/1/1\n",
       "mesh.obj:5: face index 9 out of range (3 vertices)"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", "mesh.obj:4: face needs at least 3 vertices"},
      {"v 0 x 0\n", "mesh.obj:1: bad number 'x'"},
      {"v 0 0\n", "mesh.obj:1: vertex needs x y z"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 a 3\n", "mesh.obj:4: bad face vertex 'a'"},
  };
  for (const Case& c : cases) {
    dir.write("mesh.obj", c.obj);
    INFO(c.obj);
    std::string load_mesh_message;
    try {
      covrast::load_mesh(dir.path() / "mesh.obj");
    } catch (const InputError& e) {
      load_mesh_message = e.what();
    }
    CHECK_THAT(load_mesh_message, Contains(c.expected));
    // The same through a scene.
    json scene = valid_scene();
    scene["meshes"][0]["obj"] = "mesh.obj";
    CHECK_THAT(load_error(dir.write_json("scene.json", scene)), Contains(c.expected));
  }
  REQUIRE_THROWS_AS(covrast::load_mesh(dir.path() / "nothing.obj"), InputError);
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("mesh.stl", "solid")),
                      Contains("mesh.stl") && Contains("unknown mesh format"));
}

TEST_CASE("triangles with NaN/Inf vertices are dropped and counted", "[scene]") {
  TempDir dir;
  dir.write("bad.obj",
            "v 0 0 0\n"      // 1
            "v nan 0 0\n"    // 2 NaN
            "v 1 0 0\n"      // 3
            "v 1 1 0\n"      // 4
            "v 0 -inf 0\n"   // 5 -Inf
            "v 1e39 0 0\n"   // 6 overflows float: +Inf
            "v 0 0 NaN\n"    // 7 NaN, unused
            "f 1 2 3\n"      // dropped (2)
            "f 1 3 4\n"      // kept -> 0 2 3
            "f 3 4 5\n"      // dropped (5)
            "f 1 4 6\n"      // dropped (6)
            "f 1 3 4 2\n");  // fan (1,3,4) kept -> 0 2 3, (1,4,2) dropped
  dir.write("tri.obj", kTriangleObj);
  const auto mesh = covrast::load_mesh(dir.path() / "bad.obj");
  REQUIRE(mesh->indices == std::vector<std::uint32_t>{0, 2, 3, 0, 2, 3});
  for (const glm::vec3& p : mesh->positions) {
    REQUIRE(std::isfinite(p.x));
    REQUIRE(std::isfinite(p.y));
    REQUIRE(std::isfinite(p.z));
  }

  json scene = valid_scene();
  scene["meshes"] = json::array({{{"obj", "bad.obj"}}, {{"obj", "tri.obj"}}, {{"obj", "bad.obj"}}});
  const covrast::Scene loaded = covrast::load_scene(dir.write_json("scene.json", scene));
  REQUIRE(loaded.dropped_nonfinite_triangles == 8);  // 4 per instance, 2 instances
  REQUIRE(loaded.triangle_count() == 2 + 1 + 2);
  REQUIRE(loaded.warnings.size() == 1);  // one line per file
  REQUIRE_THAT(loaded.warnings[0],
               Contains("bad.obj: dropped 4 triangles with NaN/Inf coordinates"));
}

TEST_CASE("glTF with a data: URI buffer, node hierarchy and COLOR_0", "[scene]") {
  TempDir dir;
  // Buffer: 3 float VEC3 positions (36 bytes), 3 normalized ubyte VEC4 colours (12 bytes),
  // 3 ushort indices (6 bytes) + 2 bytes padding.
  std::string buffer;
  for (const float v : {0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f}) put_f32(buffer, v);
  for (const int v : {255, 0, 0, 255, 0, 255, 0, 255, 51, 102, 255, 255}) {
    put_u8(buffer, static_cast<std::uint8_t>(v));
  }
  for (const int v : {0, 2, 1}) put_u16(buffer, static_cast<std::uint16_t>(v));
  put_u16(buffer, 0);
  REQUIRE(buffer.size() == 56);
  const json gltf = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      // Node 0: translation (1,2,3), rotation +90 degrees about z, scale (2,3,4), so its matrix
      // is T * R * S; its child node 1 translates by (0,0,1) and holds the mesh. Node 2 also
      // holds the mesh but is in no scene, so it must be ignored.
      {"nodes",
       {{{"translation", {1, 2, 3}},
         {"rotation", {0, 0, std::sqrt(0.5), std::sqrt(0.5)}},
         {"scale", {2, 3, 4}},
         {"children", {1}}},
        {{"translation", {0, 0, 1}}, {"mesh", 0}},
        {{"mesh", 0}}}},
      {"meshes",
       {{{"primitives",
          {{{"attributes", {{"POSITION", 0}, {"COLOR_0", 1}}}, {"indices", 2}, {"material", 0}},
           {{"attributes", {{"POSITION", 0}}}, {"mode", 1}}}}}}},  // lines: not drawn
      {"materials", {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 1, 1, 1}}}}}}},
      {"buffers",
       {{{"byteLength", 56}, {"uri", "data:application/octet-stream;base64," + base64(buffer)}}}},
      {"bufferViews",
       {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
        {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 12}},
        {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 6}}}},
      {"accessors",
       {{{"bufferView", 0},
         {"componentType", 5126},
         {"count", 3},
         {"type", "VEC3"},
         {"min", {0, 0, 0}},
         {"max", {1, 1, 0}}},
        {{"bufferView", 1},
         {"componentType", 5121},
         {"normalized", true},
         {"count", 3},
         {"type", "VEC4"}},
        {{"bufferView", 2}, {"componentType", 5123}, {"count", 3}, {"type", "SCALAR"}}}},
  };
  const fs::path file = dir.write_json("model.gltf", gltf);
  const auto mesh = covrast::load_mesh(file);
  // p_world = T R S (p + (0,0,1)):
  //   (0,0,0) -> (0,0,1) -> S (0,0,4) -> R (0,0,4)  -> (1,2,7)
  //   (1,0,0) -> (1,0,1) -> S (2,0,4) -> R (0,2,4)  -> (1,4,7)
  //   (0,1,0) -> (0,1,1) -> S (0,3,4) -> R (-3,0,4) -> (-2,2,7)
  const glm::vec3 expected_positions[] = {{1, 2, 7}, {1, 4, 7}, {-2, 2, 7}};
  REQUIRE(mesh->positions.size() == 3);
  for (int v = 0; v < 3; ++v) {
    for (int c = 0; c < 3; ++c) {
      REQUIRE(mesh->positions[v][c] == Approx(expected_positions[v][c]).margin(1e-6));
    }
  }
  REQUIRE(mesh->indices == std::vector<std::uint32_t>{0, 2, 1});
  // COLOR_0 is linear already; times baseColorFactor (0.5, 1, 1).
  REQUIRE(mesh->colors_linear.size() == 3);
  REQUIRE(mesh->colors_linear[0] == glm::vec3(0.5f, 0.0f, 0.0f));
  REQUIRE(mesh->colors_linear[1] == glm::vec3(0.0f, 1.0f, 0.0f));
  REQUIRE(mesh->colors_linear[2] == glm::vec3(static_cast<float>(51.0 / 255.0 * 0.5),
                                              static_cast<float>(102.0 / 255.0), 1.0f));

  // Without COLOR_0 the baseColorFactor becomes the uniform (linear) colour.
  json plain = gltf;
  plain["meshes"][0]["primitives"][0]["attributes"].erase("COLOR_0");
  plain["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {0.2, 0.4, 0.6, 1.0};
  dir.write_json("plain.gltf", plain);

  json scene = valid_scene();
  scene["meshes"] = json::array({{{"gltf", "model.gltf"}},
                                 {{"gltf", "plain.gltf"}},
                                 {{"gltf", "plain.gltf"}, {"color", {1, 1, 1}}}});
  const covrast::Scene loaded = covrast::load_scene(dir.write_json("scene.json", scene));
  REQUIRE(loaded.meshes[0].color_source == ColorSource::Vertex);
  REQUIRE(loaded.meshes[0].mesh->triangle_count() == 1);
  REQUIRE(loaded.meshes[0].color_factor_linear == glm::vec3(1.0f));  // already baked in
  REQUIRE(loaded.meshes[1].color_source == ColorSource::Uniform);
  REQUIRE(loaded.meshes[1].color_linear == glm::vec3(0.2f, 0.4f, 0.6f));
  REQUIRE(loaded.meshes[1].mesh->colors_linear.empty());
  REQUIRE(loaded.meshes[2].color_linear == glm::vec3(1.0f));
  REQUIRE(loaded.meshes[1].mesh == loaded.meshes[2].mesh);

  // "vertex" on a file without COLOR_0 is an error.
  scene["meshes"] = json::array({{{"gltf", "plain.gltf"}, {"color", "vertex"}}});
  REQUIRE_THAT(load_error(dir.write_json("scene.json", scene)),
               Contains("meshes[0].color") && Contains("no vertex colours"));

  // An index past the vertices is an InputError naming the file.
  json bad_index = gltf;
  buffer.replace(48, 2, std::string("\x07\x00", 2));
  bad_index["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(buffer);
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write_json("bad_index.gltf", bad_index)),
                      Contains("bad_index.gltf") && Contains("index 7 out of range (3 vertices)"));

  // Malformed glTF JSON: reported with line and column like a scene file.
  REQUIRE_THROWS_WITH(covrast::load_mesh(dir.write("broken.gltf", "{\"asset\":\n  ]")),
                      Contains("broken.gltf:2:3: ") && Contains("unexpected ']'"));
}

TEST_CASE("binary glTF (.glb) with a node matrix, float COLOR_0 and a NaN vertex", "[scene]") {
  TempDir dir;
  // Two non-indexed triangles; the second has a NaN vertex and is dropped.
  std::string bin;
  for (const float v : {0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f,  //
                        0.0f, 0.0f, 1.0f, 1.0f, 0.0f, 1.0f}) {
    put_f32(bin, v);
  }
  put_f32(bin, std::numeric_limits<float>::quiet_NaN());
  put_f32(bin, 0.0f);
  put_f32(bin, 1.0f);
  for (int v = 0; v < 6; ++v) {
    put_f32(bin, 0.25f);
    put_f32(bin, 0.5f);
    put_f32(bin, static_cast<float>(v) / 8.0f);
  }
  REQUIRE(bin.size() == 144);
  const json gltf = {
      {"asset", {{"version", "2.0"}}},
      // No scenes: every root node is drawn. Column-major matrix with translation (4,5,6).
      {"nodes", {{{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 4, 5, 6, 1}}, {"mesh", 0}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"COLOR_0", 1}}}}}}}}},
      {"buffers", {{{"byteLength", 144}}}},
      {"bufferViews",
       {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 72}},
        {{"buffer", 0}, {"byteOffset", 72}, {"byteLength", 72}}}},
      {"accessors",
       {{{"bufferView", 0}, {"componentType", 5126}, {"count", 6}, {"type", "VEC3"}},
        {{"bufferView", 1}, {"componentType", 5126}, {"count", 6}, {"type", "VEC3"}}}},
  };
  const fs::path file = dir.write("model.glb", make_glb(gltf.dump(), bin));
  const auto mesh = covrast::load_mesh(file);
  REQUIRE(mesh->indices == std::vector<std::uint32_t>{0, 1, 2});
  REQUIRE(mesh->positions.size() == 6);
  REQUIRE(mesh->positions[0] == glm::vec3(4, 5, 6));
  REQUIRE(mesh->positions[1] == glm::vec3(5, 5, 6));
  REQUIRE(mesh->positions[2] == glm::vec3(4, 6, 6));
  REQUIRE(mesh->colors_linear.size() == 6);
  REQUIRE(mesh->colors_linear[2] == glm::vec3(0.25f, 0.5f, 0.25f));

  // Named under "gltf" in a scene the .glb is recognised by its magic.
  json scene = valid_scene();
  scene["meshes"] = json::array({{{"gltf", "model.glb"}}, {{"gltf", "model.glb"}}});
  const covrast::Scene loaded = covrast::load_scene(dir.write_json("scene.json", scene));
  REQUIRE(loaded.meshes[0].color_source == ColorSource::Vertex);
  REQUIRE(loaded.meshes[0].mesh == loaded.meshes[1].mesh);
  REQUIRE(loaded.triangle_count() == 2);
  REQUIRE(loaded.dropped_nonfinite_triangles == 2);
  REQUIRE(loaded.warnings ==
          std::vector<std::string>{(dir.path() / "model.glb").lexically_normal().string() +
                                   ": dropped 1 triangles with NaN/Inf coordinates"});
}
