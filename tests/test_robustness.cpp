// Tests: the loaders' defences against hostile input (issue 15, docs/limits.md) at the level
// of the library: the JSON depth pre-scan, the whole-file reader (regular files only, size
// limit, NUL bytes, no blocking on FIFOs), the OBJ face limit and its cost, the scene's
// triangle limit, and the warnings for what loads but draws nothing. The CLI view of the same
// inputs is the bad-input corpus (test_bad_input_corpus.cpp).
#include <covrast/error.hpp>
#include <covrast/image.hpp>
#include <covrast/scene.hpp>

#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <ctime>
#include <functional>
#include <sstream>
#include <string>

#include "scene/scene_internal.hpp"
#include "test_cli_run.hpp"
#include "test_gltf_files.hpp"
#include "test_tempdir.hpp"

namespace fs = std::filesystem;
using covrast::InputError;
using covrast::test::GltfBuilder;
using covrast::test::TempDir;
using covrast::test::write_text;

namespace {

const std::string kCamera =
    R"("camera":{"eye":[0,0,3],"target":[0,0,0],"up":[0,1,0],"fovy_deg":45,"near":0.1,"far":100})";

std::string scene_text(const std::string& meshes) {
  return R"({"width":8,"height":8,)" + kCamera + R"(,"meshes":)" + meshes + "}";
}

std::string load_error(const std::function<void()>& load) {
  try {
    load();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// The process's CPU time [s]: the bounds on work below are on it, not on wall time, so that
/// other processes on the machine (a parallel build, the sanitizer build's neighbours) cannot
/// make them fail; a quadratic blow-up still does.
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

TEST_CASE("robust: the JSON depth pre-scan counts brackets outside strings and comments",
          "[robust]") {
  std::size_t offset = 0;
  CHECK(covrast::detail::json_depth_within("[[1]]", 2, offset));
  CHECK_FALSE(covrast::detail::json_depth_within("[[[1]]]", 2, offset));
  CHECK(offset == 2);  // the third '['
  CHECK_FALSE(covrast::detail::json_depth_within(R"({"a":{"b":[1]}})", 2, offset));
  CHECK(offset == 10);
  // Brackets inside strings (also after an escaped quote) and comments do not count.
  CHECK(covrast::detail::json_depth_within(R"(["[[[[", "\"[[[[", 1])", 1, offset));
  CHECK(covrast::detail::json_depth_within("[1, // [[[[\n 2 /* {{{{ */]", 1, offset));
  // Sequential arrays do not add up.
  CHECK(covrast::detail::json_depth_within("[[1],[2],[3]]", 2, offset));
  CHECK(covrast::detail::json_depth_within("[[1],[2],{\"a\":[4]}]", 3, offset));
  CHECK_FALSE(covrast::detail::json_depth_within("[[1],[2],{\"a\":[4]}]", 2, offset));
  // 100,000 levels: measured without recursion.
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  CHECK(covrast::detail::json_depth_within(deep, 100000, offset));
  CHECK_FALSE(covrast::detail::json_depth_within(deep, 99999, offset));
  CHECK(offset == 99999);
}

TEST_CASE("robust: read_whole_file reads regular files only, up to its limit", "[robust]") {
  TempDir dir("covrast-robust");
  std::string bytes;
  std::string error;
  write_text(dir / "ten.txt", "0123456789");
  CHECK(covrast::detail::read_whole_file(dir / "ten.txt", bytes, error, 10));
  CHECK(bytes == "0123456789");
  CHECK_FALSE(covrast::detail::read_whole_file(dir / "ten.txt", bytes, error, 9));
  CHECK(error == "file of 10 bytes is larger than the 9 bytes limit");
  CHECK_FALSE(covrast::detail::read_whole_file("/dev/zero", bytes, error));
  CHECK(error == "not a regular file");
  CHECK_FALSE(covrast::detail::read_whole_file(dir.path(), bytes, error));
  CHECK(error == "Is a directory");
  // A FIFO without a writer: refused at once, not waited on.
  REQUIRE(::mkfifo((dir / "pipe").c_str(), 0600) == 0);
  const auto start = std::chrono::steady_clock::now();
  CHECK_FALSE(covrast::detail::read_whole_file(dir / "pipe", bytes, error));
  CHECK(error == "not a regular file");
  CHECK(seconds_since(start) < 5.0);
  // An embedded NUL would otherwise open "ten.txt".
  const std::string with_nul = (dir / "ten.txt").string() + std::string("\0.x", 3);
  CHECK_FALSE(covrast::detail::read_whole_file(fs::path(with_nul), bytes, error));
  CHECK(error == "the path contains a NUL byte");
  CHECK(covrast::detail::size_text(std::uint64_t(1) << 30) == "1 GiB");
  CHECK(covrast::detail::size_text(std::uint64_t(1) << 26) == "64 MiB");
}

TEST_CASE("robust: every reader names a directory and a device alike", "[robust]") {
  // One reader (core/file_read.hpp) and one wording for what is not a regular file, whether
  // a scene, a mesh, a glTF buffer, a texture or a PNG to compare is asked for.
  TempDir dir("covrast-robust");
  namespace cd = covrast::detail;
  CHECK(cd::unreadable_kind(fs::status(dir.path())) == "Is a directory");
  CHECK(cd::unreadable_kind(fs::status("/dev/zero")) == "not a regular file");
  CHECK(cd::unreadable_kind(fs::status(dir / "missing.png")).empty());
  write_text(dir / "ten.txt", "0123456789");
  CHECK(cd::unreadable_kind(fs::status(dir / "ten.txt")).empty());
  const auto message = [](const auto& read) -> std::string {
    try {
      read();
    } catch (const covrast::InputError& e) {
      return e.what();
    }
    return "no error";
  };
  CHECK(message([&] { covrast::read_image(dir.path(), "t.png"); }) ==
        "t.png: cannot read image: Is a directory");
  CHECK(message([&] { covrast::read_image("/dev/zero", "z.png"); }) ==
        "z.png: cannot read image: not a regular file");
  CHECK(message([&] { covrast::read_png(dir.path()); }) ==
        dir.path().string() + ": cannot read PNG: Is a directory");
}

TEST_CASE("robust: an OBJ face of many corners is linear, past the limit an error", "[robust]") {
  TempDir dir("covrast-robust");
  // A polygon at the limit: kMaxObjFaceCorners corners on a circle (a convex fan).
  std::string obj;
  const std::uint64_t corners = covrast::kMaxObjFaceCorners;
  for (std::uint64_t i = 0; i < corners; ++i) {
    const double angle = 6.283185307179586 * double(i) / double(corners);
    obj += "v ";
    obj += std::to_string(std::cos(angle));
    obj += ' ';
    obj += std::to_string(std::sin(angle));
    obj += " 0\n";
  }
  std::string face = "f";
  for (std::uint64_t i = 1; i <= corners; ++i) {
    face += ' ';  // appended piecewise: " " + std::string trips a g++ 12 -Wrestrict warning
    face += std::to_string(i);
  }
  write_text(dir / "big.obj", obj + face + "\n");
  auto start = cpu_seconds();
  const auto mesh = covrast::load_mesh(dir / "big.obj");
  CHECK(mesh->triangle_count() == corners - 2);
  CHECK(cpu_seconds() - start < 10.0);
  // One face line of 20 MB (the finding: minutes before): refused at the corner limit.
  std::string huge = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
  while (huge.size() < 20'000'000) huge += " 1 2 3";
  write_text(dir / "huge.obj", huge + "\n");
  start = cpu_seconds();
  CHECK(load_error([&] { covrast::load_mesh(dir / "huge.obj"); }) ==
        (dir / "huge.obj").string() + ":4: face has more than 65536 corners (docs/limits.md)");
  CHECK(cpu_seconds() - start < 10.0);
}

TEST_CASE("robust: a concave 4096-corner OBJ face is ear-clipped in bounded time", "[robust]") {
  // Issue 28: a tight spiral band of 4096 corners (96 KB) took 40 s to ear-clip, each round
  // that found no ear rescanning every corner; now 0.2 s.
  TempDir dir("covrast-robust");
  std::ostringstream obj;
  obj.precision(17);
  const int half = 2048;
  for (int side = 0; side < 2; ++side) {
    for (int k = 0; k < half; ++k) {
      const int i = side == 0 ? k : half - 1 - k;  // out along the outer arm, back the inner
      const double angle = 0.5 * i;
      const double radius = 1.0 + 0.1 * angle - (side == 0 ? 0.0 : 0.02);
      obj << "v " << radius * std::cos(angle) << ' ' << radius * std::sin(angle) << " 0\n";
    }
  }
  obj << 'f';
  for (int i = 1; i <= 2 * half; ++i) obj << ' ' << i;
  obj << '\n';
  const std::string text = obj.str();
  const auto start = cpu_seconds();
  const auto loaded = covrast::detail::parse_obj(text, "spiral.obj", dir.path());
  CHECK(cpu_seconds() - start < 5.0);
  CHECK(loaded.data->triangle_count() == std::size_t(2 * half - 2));
  CHECK(loaded.warnings.empty());  // ear-clipped, not the fan fallback
}

TEST_CASE("robust: 100,000 OBJ materials and usemtl statements load in bounded time", "[robust]") {
  // Issue 28: each newmtl and each used name was a linear search of the materials: 100,000
  // newmtl took 35 s and 100,000 usemtl 81 s.
  TempDir dir("covrast-robust");
  const int count = 100000;
  std::string mtl, obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
  for (int i = 0; i < count; ++i) {
    std::string name = "m";  // appended piecewise: "m" + std::string trips g++ 12 -Wrestrict
    name += std::to_string(i);
    mtl += "newmtl " + name + "\nKd 0.5 0.5 0.5\n";
    obj += "usemtl " + name + "\nf 1 2 3\n";
  }
  write_text(dir / "m.mtl", mtl);
  write_text(dir / "m.obj", obj);
  const auto start = cpu_seconds();
  const auto mesh = covrast::load_mesh(dir / "m.obj");
  CHECK(cpu_seconds() - start < 10.0);
  CHECK(mesh->triangle_count() == std::size_t(count));
  CHECK(mesh->materials.size() >= std::size_t(count));
}

TEST_CASE("robust: a scene that draws more than kMaxSceneTriangles is refused", "[robust]") {
  TempDir dir("covrast-robust");
  // A glTF mesh of 2^20 triangles (an accessor without a bufferView: zeros, no file bytes),
  // named by the scene 33 times: 33 * 2^20 > 2^25.
  GltfBuilder builder;
  builder.gltf["accessors"] = {{{"componentType", 5126}, {"count", 3 << 20}, {"type", "VEC3"}}};
  builder.single_mesh({{{"attributes", {{"POSITION", 0}}}}});
  write_text(dir / "m.gltf", builder.gltf.dump());
  std::string meshes = "[";
  for (int i = 0; i < 33; ++i) meshes += std::string(i ? "," : "") + R"({"gltf":"m.gltf"})";
  write_text(dir / "s.json", scene_text(meshes + "]"));
  CHECK(load_error([&] { covrast::load_scene(dir / "s.json"); }) ==
        (dir / "s.json").string() +
            ": meshes[32]: the scene's instances draw 34603008 triangles, more than 33554432 "
            "(docs/limits.md)");
  // 32 instances are within the limit.
  write_text(dir / "s.json", scene_text(meshes.substr(0, meshes.size() - 18) + "]"));
  CHECK(covrast::load_scene(dir / "s.json").triangle_count() == 32u << 20);
}

TEST_CASE("robust: a glTF file whose instances make more than kMaxSceneTriangles is refused",
          "[robust]") {
  TempDir dir("covrast-robust");
  // 2^20 triangles (zeros, no file bytes), instanced 33 times by EXT_mesh_gpu_instancing:
  // refused before the first copy is made.
  GltfBuilder builder;
  builder.gltf["accessors"] = {{{"componentType", 5126}, {"count", 3 << 20}, {"type", "VEC3"}},
                               {{"componentType", 5126}, {"count", 33}, {"type", "VEC3"}}};
  builder.single_mesh({{{"attributes", {{"POSITION", 0}}}}});
  builder.gltf["nodes"][0]["extensions"] = {
      {"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", 1}}}}}};
  write_text(dir / "m.gltf", builder.gltf.dump());
  const auto start = cpu_seconds();
  CHECK(load_error([&] { covrast::load_mesh(dir / "m.gltf"); }) ==
        (dir / "m.gltf").string() +
            ": mesh 0 primitive 0: 33 copies make more than 33554432 triangles (docs/limits.md)");
  CHECK(cpu_seconds() - start < 10.0);
  // 2 copies load (2 * 2^20 triangles).
  builder.gltf["accessors"][1]["count"] = 2;
  write_text(dir / "m.gltf", builder.gltf.dump());
  CHECK(covrast::load_mesh(dir / "m.gltf")->triangle_count() == 2u << 20);
}

TEST_CASE("robust: a glTF accessor over the element limit is refused before allocating",
          "[robust]") {
  TempDir dir("covrast-robust");
  GltfBuilder builder;
  builder.gltf["accessors"] = {
      {{"componentType", 5126}, {"count", covrast::kMaxAccessorElements + 1}, {"type", "VEC3"}}};
  builder.single_mesh({{{"attributes", {{"POSITION", 0}}}}});
  write_text(dir / "m.gltf", builder.gltf.dump());
  const auto start = cpu_seconds();
  CHECK(load_error([&] { covrast::load_mesh(dir / "m.gltf"); }) ==
        (dir / "m.gltf").string() +
            ": mesh 0 primitive 0 POSITION: accessor 0 has 16777217 elements, more than the "
            "16777216 covrast reads (docs/limits.md)");
  CHECK(cpu_seconds() - start < 5.0);
}

TEST_CASE("robust: what loads but draws nothing is a warning", "[robust]") {
  TempDir dir("covrast-robust");
  write_text(dir / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  write_text(dir / "empty.obj", "# no faces\n");
  SECTION("a mesh file without triangles") {
    write_text(dir / "s.json", scene_text(R"([{"obj":"empty.obj"},{"obj":"tri.obj"}])"));
    const covrast::Scene scene = covrast::load_scene(dir / "s.json");
    REQUIRE(scene.warnings.size() == 1);
    CHECK(scene.warnings[0] ==
          (dir / "empty.obj").string() + ": no triangles: the mesh draws nothing");
  }
  SECTION("a model matrix beyond the finite range") {
    write_text(
        dir / "s.json",
        scene_text(
            R"([{"obj":"tri.obj"},{"obj":"tri.obj","model":[1e308,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]}])"));
    const covrast::Scene scene = covrast::load_scene(dir / "s.json");
    REQUIRE(scene.warnings.size() == 1);
    CHECK(scene.warnings[0] ==
          (dir / "s.json").string() +
              ": meshes[1]: the mesh lies outside the finite range (its model matrix makes "
              "clip-space coordinates overflow): nothing of it is drawn");
  }
  SECTION("large but finite model matrices give no warning") {
    write_text(
        dir / "s.json",
        scene_text(R"([{"obj":"tri.obj","model":[1e30,0,0,0,0,1e30,0,0,0,0,1,0,0,0,0,1]}])"));
    CHECK(covrast::load_scene(dir / "s.json").warnings.empty());
  }
  SECTION("tinygltf's warnings: an image file it cannot load") {
    GltfBuilder builder;
    const int positions = builder.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    builder.single_mesh({{{"attributes", {{"POSITION", positions}}}}});
    builder.gltf["images"] = {{{"uri", "missing.png"}}};
    write_text(dir / "m.gltf", builder.gltf_text());
    write_text(dir / "s.json", scene_text(R"([{"gltf":"m.gltf"}])"));
    const covrast::Scene scene = covrast::load_scene(dir / "s.json");
    REQUIRE_FALSE(scene.warnings.empty());
    CHECK(scene.warnings[0].rfind((dir / "m.gltf").string() + ": File not found : missing.png",
                                  0) == 0);
  }
}
