// glTF animation time (scene/gltf_animation.hpp): generated files whose animations move one
// triangle, posed at chosen times and compared with poses computed by hand from the
// specification's formulas (glTF 2.0, Appendix C).
#include <covrast/error.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "test_gltf_files.hpp"
#include "test_tempdir.hpp"

using covrast::AnimationTime;
using covrast::test::GltfBuilder;

namespace {

/// The triangle (0,0,0), (1,0,0), (0,1,0) on node 0, with a morph target that moves every
/// vertex by +1 in z, and one animation per entry of `channels` (each {path, interpolation,
/// times, values}).
struct Channel {
  std::string path;
  std::string interpolation;
  std::vector<float> times;
  std::vector<float> values;
};

std::string animated_triangle(const std::vector<std::vector<Channel>>& animations) {
  GltfBuilder builder;
  const int positions = builder.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  const int delta = builder.add_floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
  builder.single_mesh(
      {{{"attributes", {{"POSITION", positions}}}, {"targets", {{{"POSITION", delta}}}}}});
  builder.gltf["meshes"][0]["weights"] = {0.0};
  for (std::size_t a = 0; a < animations.size(); ++a) {
    nlohmann::json animation = {{"name", "anim" + std::to_string(a)},
                                {"channels", nlohmann::json::array()},
                                {"samplers", nlohmann::json::array()}};
    for (const Channel& c : animations[a]) {
      const std::string type = c.path == "rotation"  ? "VEC4"
                               : c.path == "weights" ? "SCALAR"
                                                     : "VEC3";
      const int input = builder.add_floats(c.times, "SCALAR");
      const int output = builder.add_floats(c.values, type);
      animation["samplers"].push_back(
          {{"input", input}, {"output", output}, {"interpolation", c.interpolation}});
      animation["channels"].push_back({{"sampler", animation["samplers"].size() - 1},
                                       {"target", {{"node", 0}, {"path", c.path}}}});
    }
    builder.gltf["animations"].push_back(animation);
  }
  return builder.glb();
}

/// The triangle's three vertices after loading `glb` posed by `pose` (the loader bakes node
/// transforms and morph weights into the positions).
std::vector<glm::vec3> posed(const std::string& glb, const std::optional<AnimationTime>& pose,
                             std::vector<std::string>* warnings = nullptr) {
  covrast::test::TempDir dir("covrast-anim");
  const std::filesystem::path file = dir / "a.glb";
  std::ofstream(file, std::ios::binary) << glb;
  const covrast::Scene scene = covrast::load_mesh_scene(file, 64, 64, pose);
  if (warnings != nullptr) *warnings = scene.warnings;
  return scene.meshes.at(0).mesh->positions;
}

AnimationTime at(double t, int index = -1, std::string name = {}) {
  return AnimationTime{index, std::move(name), t};
}

void check_vertex(const glm::vec3& got, const glm::dvec3& want) {
  INFO("got (" << got.x << ", " << got.y << ", " << got.z << "), want (" << want.x << ", " << want.y
               << ", " << want.z << ")");
  CHECK(got.x == Approx(want.x).margin(1e-6));
  CHECK(got.y == Approx(want.y).margin(1e-6));
  CHECK(got.z == Approx(want.z).margin(1e-6));
}

}  // namespace

TEST_CASE("animation: LINEAR translation and scale at a time between keyframes, and clamped",
          "[animation]") {
  const std::string glb =
      animated_triangle({{{"translation", "LINEAR", {1, 3}, {0, 0, 0, 4, -2, 0}},
                          {"scale", "LINEAR", {0, 2}, {1, 1, 1, 3, 1, 1}}}});
  // t = 2: translation halfway, (2, -1, 0); scale at its last key, x 3.
  std::vector<glm::vec3> v = posed(glb, at(2.0));
  check_vertex(v[0], {2, -1, 0});
  check_vertex(v[1], {5, -1, 0});
  check_vertex(v[2], {2, 0, 0});
  // t = 0.5: translation before its first key (0), scale a quarter of the way (1.5).
  v = posed(glb, at(0.5));
  check_vertex(v[1], {1.5, 0, 0});
  // t = 10: both past their last keys.
  v = posed(glb, at(10.0));
  check_vertex(v[1], {7, -2, 0});
  // No time: the static pose.
  v = posed(glb, std::nullopt);
  check_vertex(v[1], {1, 0, 0});
}

TEST_CASE("animation: STEP holds the keyframe at or before the time", "[animation]") {
  const std::string glb =
      animated_triangle({{{"translation", "STEP", {0, 1, 2}, {0, 0, 0, 5, 0, 0, 9, 0, 0}}}});
  check_vertex(posed(glb, at(0.99))[0], {0, 0, 0});
  check_vertex(posed(glb, at(1.0))[0], {5, 0, 0});
  check_vertex(posed(glb, at(1.5))[0], {5, 0, 0});
  check_vertex(posed(glb, at(2.5))[0], {9, 0, 0});
}

TEST_CASE("animation: LINEAR rotation is the slerp on the shorter arc", "[animation]") {
  // From identity to 90 degrees about +z; the second key is stored negated (the same rotation):
  // the shorter arc still goes through 45 degrees at t = 0.5.
  const double s = std::sin(std::numbers::pi / 4.0), c = std::cos(std::numbers::pi / 4.0);
  const std::string glb = animated_triangle(
      {{{"rotation", "LINEAR", {0, 1}, {0, 0, 0, 1, 0, 0, float(-s), float(-c)}}}});
  const double a = std::numbers::pi / 4.0;  // 45 degrees at t = 0.5
  const std::vector<glm::vec3> v = posed(glb, at(0.5));
  check_vertex(v[1], {std::cos(a), std::sin(a), 0});
  check_vertex(v[2], {-std::sin(a), std::cos(a), 0});
  // At a third of the way: 30 degrees (slerp is uniform in angle, lerp would not be).
  const std::vector<glm::vec3> w = posed(glb, at(1.0 / 3.0));
  check_vertex(w[1], {std::cos(std::numbers::pi / 6.0), std::sin(std::numbers::pi / 6.0), 0});
}

TEST_CASE("animation: CUBICSPLINE translation follows the Hermite spline with scaled tangents",
          "[animation]") {
  // Keys at t = 1 and 3 (interval 2): values 0 and 4 in x, out-tangent of key 0 = 1, in-tangent
  // of key 1 = -2 (per second). At t = 1.5, u = 0.25:
  //   p = (2u^3 - 3u^2 + 1) 0 + 2 (u^3 - 2u^2 + u) 1 + (-2u^3 + 3u^2) 4 + 2 (u^3 - u^2) (-2)
  const std::string glb =
      animated_triangle({{{"translation",
                           "CUBICSPLINE",
                           {1, 3},
                           {/* key 0: in, value, out */ 9, 9, 9, 0, 0, 0, 1, 0, 0,
                            /* key 1 */ -2, 0, 0, 4, 0, 0, 9, 9, 9}}}});
  const double u = 0.25, u2 = u * u, u3 = u2 * u;
  const double x = 2 * (u3 - 2 * u2 + u) * 1 + (-2 * u3 + 3 * u2) * 4 + 2 * (u3 - u2) * -2;
  check_vertex(posed(glb, at(1.5))[0], {x, 0, 0});
  // At the keys themselves, the values (the tangents 9 of the ends are never used there).
  check_vertex(posed(glb, at(3.0))[0], {4, 0, 0});
  check_vertex(posed(glb, at(0.0))[0], {0, 0, 0});
}

TEST_CASE("animation: morph weights are sampled and applied", "[animation]") {
  const std::string glb = animated_triangle({{{"weights", "LINEAR", {0, 2}, {0, 1}}}});
  // Weight 0.25 at t = 0.5: every vertex 0.25 along the target's +z.
  check_vertex(posed(glb, at(0.5))[2], {0, 1, 0.25});
}

TEST_CASE("animation: selecting by index or name, and what is refused", "[animation]") {
  const std::string glb =
      animated_triangle({{{"translation", "LINEAR", {0, 1}, {0, 0, 0, 1, 0, 0}}},
                         {{"translation", "LINEAR", {0, 1}, {0, 0, 0, 0, 3, 0}}}});
  check_vertex(posed(glb, at(1.0))[0], {1, 0, 0});               // the first by default
  check_vertex(posed(glb, at(1.0, 1))[0], {0, 3, 0});            // by index
  check_vertex(posed(glb, at(1.0, -1, "anim1"))[0], {0, 3, 0});  // by name
  CHECK_THROWS_WITH(posed(glb, at(1.0, 2)), Catch::Contains("animation 2 does not exist"));
  CHECK_THROWS_WITH(posed(glb, at(1.0, -1, "walk")),
                    Catch::Contains("no animation named 'walk'") && Catch::Contains("'anim1'"));
  CHECK_THROWS_AS(posed(glb, at(-1.0)), covrast::InputError);
  // Keyframe times that go backwards are an error naming the channel.
  const std::string backwards =
      animated_triangle({{{"translation", "LINEAR", {1, 0}, {0, 0, 0, 1, 0, 0}}}});
  CHECK_THROWS_WITH(posed(backwards, at(0.5)), Catch::Contains("strictly increasing"));
  // A file without animations keeps its static pose, with a warning.
  std::vector<std::string> warnings;
  check_vertex(posed(animated_triangle({}), at(1.0), &warnings)[1], {1, 0, 0});
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].find("no animations") != std::string::npos);
}

TEST_CASE("animation: a scene file's \"animation\" and \"time\" keys, and load_scene's pose",
          "[animation]") {
  covrast::test::TempDir dir("covrast-anim");
  std::ofstream(dir / "a.glb", std::ios::binary)
      << animated_triangle({{{"translation", "LINEAR", {0, 1}, {0, 0, 0, 1, 0, 0}}},
                            {{"translation", "LINEAR", {0, 1}, {0, 0, 0, 0, 3, 0}}}});
  auto scene_file = [&](const std::string& keys) {
    std::ofstream(dir / "s.json")
        << R"({"width": 8, "height": 8, "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fovy_deg": 40, "near": 0.1, "far": 10},)"
        << keys << R"("meshes": [{"gltf": "a.glb"}]})";
    return dir / "s.json";
  };
  auto first_vertex = [](const covrast::Scene& scene) {
    return scene.meshes.at(0).mesh->positions[0];
  };
  check_vertex(first_vertex(covrast::load_scene(scene_file(R"("time": 0.5,)"))), {0.5, 0, 0});
  check_vertex(
      first_vertex(covrast::load_scene(scene_file(R"("animation": "anim1", "time": 0.5,)"))),
      {0, 1.5, 0});
  check_vertex(first_vertex(covrast::load_scene(scene_file(R"("animation": 1, "time": 2,)"))),
               {0, 3, 0});
  check_vertex(first_vertex(covrast::load_scene(scene_file(""))), {0, 0, 0});
  // The pose argument replaces the file's keys.
  check_vertex(first_vertex(covrast::load_scene(scene_file(R"("time": 0.5,)"), at(0.25, 1))),
               {0, 0.75, 0});
  for (const std::string bad : {R"("time": -1,)", R"("time": "1",)", R"("animation": -2,)",
                                R"("animation": 1.5,)", R"("animation": "",)"}) {
    INFO(bad);
    CHECK_THROWS_AS(covrast::load_scene(scene_file(bad)), covrast::InputError);
  }
}
