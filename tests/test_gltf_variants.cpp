// Tests of KHR_materials_variants (src/scene/gltf_variants.cpp): a variant chosen by a scene's
// "variant", SceneChoices or `--variant` draws the material its mapping names, colours
// included; without one the default materials; unknown names and malformed mappings are
// errors naming the JSON path; `covrast info` lists the variants.
#include <covrast/error.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include <fstream>
#include <string>

#include "test_cli_run.hpp"
#include "test_gltf_files.hpp"
#include "test_tempdir.hpp"

using Catch::Matchers::Contains;

namespace {

/// One triangle of material 0 (red); variant "blue" maps it to material 1 (blue), variant
/// "plain" has no mapping. `mappings` replaces the primitive's mappings when given.
std::string variant_triangle(const nlohmann::json& mappings = nullptr) {
  covrast::test::GltfBuilder b;
  const int pos = b.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  nlohmann::json primitive = {{"attributes", {{"POSITION", pos}}}, {"material", 0}};
  primitive["extensions"]["KHR_materials_variants"]["mappings"] =
      mappings.is_null() ? nlohmann::json{{{"material", 1}, {"variants", {0}}}} : mappings;
  b.single_mesh(nlohmann::json::array({primitive}));
  b.gltf["materials"] = {{{"pbrMetallicRoughness", {{"baseColorFactor", {1, 0, 0, 1}}}}},
                         {{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 1, 1}}}}}};
  b.gltf["extensionsUsed"] = {"KHR_materials_variants"};
  b.gltf["extensions"]["KHR_materials_variants"]["variants"] = {{{"name", "blue"}},
                                                                {{"name", "plain"}}};
  return b.glb();
}

glm::vec3 colour_of(const covrast::Scene& scene) {
  REQUIRE(scene.meshes.size() == 1);
  REQUIRE(scene.meshes[0].color_source == covrast::ColorSource::Uniform);
  return scene.meshes[0].color_linear;
}

}  // namespace

TEST_CASE("variants: the chosen variant's material is drawn, colours included",
          "[gltf][variants]") {
  covrast::test::TempDir dir("covrast-variants");
  const std::filesystem::path file = dir / "v.glb";
  std::ofstream(file, std::ios::binary) << variant_triangle();
  const covrast::Scene plain = covrast::load_mesh_scene(file, 16, 16);
  CHECK(plain.meshes[0].mesh->material_variants == std::vector<std::string>{"blue", "plain"});
  CHECK(colour_of(plain) == glm::vec3(1, 0, 0));
  for (const std::string& warning : plain.warnings) {
    CHECK(warning.find("KHR_materials_variants") == std::string::npos);  // honoured
  }
  covrast::SceneChoices choices;
  choices.material_variant = "blue";
  CHECK(colour_of(covrast::load_mesh_scene(file, 16, 16, choices)) == glm::vec3(0, 0, 1));
  choices.material_variant = "plain";  // no mapping: the primitive's own material
  CHECK(colour_of(covrast::load_mesh_scene(file, 16, 16, choices)) == glm::vec3(1, 0, 0));
  choices.material_variant = "green";
  CHECK_THROWS_WITH(covrast::load_mesh_scene(file, 16, 16, choices),
                    Contains("v.glb: no material variant 'green' (variants: blue, plain)"));

  // A scene's "variant" key, per mesh entry; the same file drawn both ways.
  const auto scene_with = [&](const nlohmann::json& meshes) {
    std::ofstream(dir / "s.json") << nlohmann::json{
        {"width", 8},
        {"height", 8},
        {"camera",
         {{"eye", {0, 0, 5}},
          {"target", {0, 0, 0}},
          {"up", {0, 1, 0}},
          {"fovy_deg", 40},
          {"near", 0.1},
          {"far", 10}}},
        {"meshes", meshes}}.dump();
    return dir / "s.json";
  };
  const covrast::Scene both = covrast::load_scene(
      scene_with({{{"gltf", "v.glb"}}, {{"gltf", "v.glb"}, {"variant", "blue"}}}));
  REQUIRE(both.meshes.size() == 2);
  CHECK(both.meshes[0].color_linear == glm::vec3(1, 0, 0));
  CHECK(both.meshes[1].color_linear == glm::vec3(0, 0, 1));
  CHECK_THROWS_WITH(covrast::load_scene(scene_with({{{"gltf", "v.glb"}, {"variant", 3}}})),
                    Contains("meshes[0].variant: expected a material variant name"));
  std::ofstream(dir / "t.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  CHECK_THROWS_WITH(covrast::load_scene(scene_with({{{"obj", "t.obj"}, {"variant", "blue"}}})),
                    Contains("meshes[0].variant: only glTF files have material variants"));
  // SceneChoices in the place of the key: every glTF mesh.
  choices.material_variant = "blue";
  const covrast::Scene overridden = covrast::load_scene(scene_with({{{"gltf", "v.glb"}}}), choices);
  CHECK(overridden.meshes[0].color_linear == glm::vec3(0, 0, 1));
}

TEST_CASE("variants: malformed mappings are errors naming the JSON path", "[gltf][variants]") {
  covrast::test::TempDir dir("covrast-variants");
  const std::filesystem::path file = dir / "v.glb";
  const std::string at = "mesh 0 primitive 0: extensions.KHR_materials_variants.mappings[0]";
  const auto expect = [&](const nlohmann::json& mappings, const std::string& message) {
    std::ofstream(file, std::ios::binary) << variant_triangle(mappings);
    CHECK_THROWS_WITH(covrast::load_mesh_scene(file, 16, 16), Contains(message));
  };
  expect({{{"material", 1}, {"variants", {2}}}},
         at + ".variants[0]: expected the index of one of the 2 variants");
  expect({{{"material", 7}, {"variants", {0}}}},
         at + ".material: expected the index of one of the file's 2 materials");
  expect({{{"material", 1}, {"variants", {0, 0}}}}, at + ".variants[1]: variant 0 is mapped twice");
  expect({{{"material", 1}}}, at + ".variants: expected an array of variant indices");
  expect(nlohmann::json::object(),
         "mesh 0 primitive 0: extensions.KHR_materials_variants.mappings: expected an array");
}

TEST_CASE("variants: --variant renders a variant, info lists them", "[gltf][variants][cli]") {
  covrast::test::TempDir dir("covrast-variants");
  std::ofstream(dir / "v.glb", std::ios::binary) << variant_triangle();
  const auto info = covrast::test::run_cli_in(dir.path(), {"info", "v.glb"}, true);
  CHECK(info.exit_code == 0);
  CHECK_THAT(info.out, Contains("material variants: blue, plain"));
  const auto ok = covrast::test::run_cli_in(
      dir.path(), {"render", "v.glb", "--size", "16x16", "--variant", "blue", "-o", "b.png"}, true);
  CHECK(ok.exit_code == 0);
  const auto bad = covrast::test::run_cli_in(
      dir.path(), {"render", "v.glb", "--variant", "nope", "-o", "n.png"}, true);
  CHECK(bad.exit_code == 2);
  CHECK_THAT(bad.err, Contains("no material variant 'nope' (variants: blue, plain)"));
  CHECK_FALSE(std::filesystem::exists(dir / "n.png"));
}
