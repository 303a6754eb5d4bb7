// Tests of MeshFileCache (include/covrast/scene.hpp): scenes loaded through one cache share
// the meshes of the files they have in common (each file read once), and each scene still
// gets the warnings of every file it uses.
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include <string>

#include "test_cli_run.hpp"
#include "test_tempdir.hpp"

namespace {

std::string scene_with(const std::string& obj_a, const std::string& obj_b) {
  return R"({"width": 16, "height": 16, "camera": {"eye": [0, 0, 3], "target": [0, 0, 0],
    "up": [0, 1, 0], "fovy_deg": 45, "near": 0.5, "far": 10},
    "meshes": [{"obj": ")" +
         obj_a + R"("}, {"obj": ")" + obj_b + R"("}]})";
}

}  // namespace

TEST_CASE("scenes loaded through one MeshFileCache share their mesh files", "[scene][cache]") {
  covrast::test::TempDir dir("covrast-test-mesh-cache");
  using covrast::test::write_text;
  // b.obj has a face with a NaN vertex: dropped, with a warning naming the file.
  write_text(dir / "a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  write_text(dir / "b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nf 1 2 3\nf 1 2 4\n");
  write_text(dir / "one.json", scene_with("a.obj", "b.obj"));
  write_text(dir / "two.json", scene_with("b.obj", "./a.obj"));

  covrast::MeshFileCache cache;
  const covrast::Scene one = covrast::load_scene(dir / "one.json", cache);
  CHECK(cache.files_loaded() == 2);
  const covrast::Scene two = covrast::load_scene(dir / "two.json", cache);
  CHECK(cache.files_loaded() == 2);  // nothing new: "./a.obj" is the same file
  CHECK(one.meshes[0].mesh == two.meshes[1].mesh);
  CHECK(one.meshes[1].mesh == two.meshes[0].mesh);
  REQUIRE(one.warnings.size() == 1);
  REQUIRE(two.warnings.size() == 1);  // the cached file's warning reaches the second scene too
  CHECK(two.warnings[0].find("b.obj: dropped 1 triangles") != std::string::npos);
  CHECK(two.dropped_nonfinite_triangles == 1);

  // Without a shared cache each scene loads its own copy.
  const covrast::Scene alone = covrast::load_scene(dir / "two.json");
  CHECK(alone.meshes[0].mesh != two.meshes[0].mesh);
  CHECK(alone.warnings == two.warnings);
}
