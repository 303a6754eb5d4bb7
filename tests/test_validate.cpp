// Tests of covrast::validate_file and `covrast info --validate` (src/scene/validate.cpp): every
// wrong field of a glTF file listed with its JSON path (the load stops at the first), the
// load's own error and warnings for other files, and the exit status.
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include <fstream>
#include <string>
#include <vector>

#include "test_cli_run.hpp"
#include "test_gltf_files.hpp"
#include "test_tempdir.hpp"

using Catch::Matchers::Contains;

namespace {

/// One triangle whose material and mesh carry the three mistakes of issue 26's report: a
/// normalTexture.scale that is a string, a texture index of -1 (both used: errors) and a mesh
/// name that is a number (ignored: a warning). `broken` false: the same file without them.
std::string triangle(bool broken) {
  covrast::test::GltfBuilder b;
  const int pos = b.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  b.single_mesh({{{"attributes", {{"POSITION", pos}}}, {"material", 0}}});
  b.gltf["materials"] = nlohmann::json::array({nlohmann::json::object()});
  if (broken) {
    b.gltf["meshes"][0]["name"] = 5;
    b.gltf["materials"][0]["normalTexture"] = {{"index", -1}, {"scale", "1"}};
  }
  return b.gltf_text();
}

}  // namespace

TEST_CASE("validate: every wrong field of a glTF file with its JSON path", "[validate][gltf]") {
  covrast::test::TempDir dir("covrast-validate");
  std::ofstream(dir / "bad.gltf") << triangle(true);
  std::ofstream(dir / "good.gltf") << triangle(false);
  const std::string bad = (dir / "bad.gltf").lexically_normal().string();
  const covrast::Validation found = covrast::validate_file(dir / "bad.gltf");
  CHECK(found.errors ==
        std::vector<std::string>{
            bad + ": materials[0].normalTexture.index: expected an index (an integer >= 0), got -1",
            bad + ": materials[0].normalTexture.scale: expected a number, got \"1\""});
  CHECK(found.warnings ==
        std::vector<std::string>{bad + ": meshes[0].name: expected a string, got 5 (ignored)"});
  // The load itself stops at the first of them.
  CHECK_THROWS_WITH(covrast::load_mesh_scene(dir / "bad.gltf", 16, 16),
                    Contains("materials[0].normalTexture.index"));

  const covrast::Validation clean = covrast::validate_file(dir / "good.gltf");
  CHECK(clean.errors.empty());
  CHECK(clean.warnings.empty());
  // Not there, and a scene file's own error: the load's message.
  const covrast::Validation missing = covrast::validate_file(dir / "none.glb");
  REQUIRE(missing.errors.size() == 1);
  CHECK_THAT(missing.errors[0], Contains("none.glb"));
  std::ofstream(dir / "s.json") << R"({"width": 8, "height": 8, "meshes": []})";
  const covrast::Validation scene = covrast::validate_file(dir / "s.json");
  REQUIRE(scene.errors.size() == 1);
  CHECK_THAT(scene.errors[0], Contains("camera"));
}

TEST_CASE("validate: info --validate lists the findings and sets the exit status",
          "[validate][cli]") {
  covrast::test::TempDir dir("covrast-validate");
  std::ofstream(dir / "bad.gltf") << triangle(true);
  std::ofstream(dir / "good.gltf") << triangle(false);
  const auto bad = covrast::test::run_cli_in(dir.path(), {"info", "--validate", "bad.gltf"}, true);
  CHECK(bad.exit_code == 2);
  CHECK_THAT(bad.out, Contains("bad.gltf: 2 errors, 1 warning\n"));
  CHECK_THAT(bad.out, Contains("error: bad.gltf: materials[0].normalTexture.index: "));
  CHECK_THAT(bad.out, Contains("error: bad.gltf: materials[0].normalTexture.scale: "));
  CHECK_THAT(bad.out, Contains("warning: bad.gltf: meshes[0].name: "));
  const auto json =
      covrast::test::run_cli_in(dir.path(), {"info", "--validate", "--json", "bad.gltf"}, true);
  CHECK(json.exit_code == 2);
  const nlohmann::json parsed = nlohmann::json::parse(json.out);
  CHECK(parsed["valid"] == false);
  CHECK(parsed["errors"].size() == 2);
  CHECK(parsed["warnings"].size() == 1);
  const auto good =
      covrast::test::run_cli_in(dir.path(), {"info", "--validate", "good.gltf"}, true);
  CHECK(good.exit_code == 0);
  CHECK_THAT(good.out, Contains("good.gltf: 0 errors, 0 warnings"));
  // A warning alone: exit 0, and 2 with --strict. An ignored field of a wrong type is one.
  std::ofstream(dir / "warn.gltf") << [] {
    nlohmann::json g = nlohmann::json::parse(triangle(false));
    g["meshes"][0]["name"] = 5;
    return g.dump();
  }();
  CHECK(
      covrast::test::run_cli_in(dir.path(), {"info", "--validate", "warn.gltf"}, true).exit_code ==
      0);
  CHECK(covrast::test::run_cli_in(dir.path(), {"info", "--validate", "--strict", "warn.gltf"}, true)
            .exit_code == 2);
}
