// Tests on the real-content scene set (covrast-scenegen --real DIR, scenes/README.md). Each
// scene is generated into a temporary directory, loaded with load_scene and rendered at a small
// size in the coverage, ssaa:16 and reference modes; coverage must be at least as close to the
// reference as ssaa:16 (256 samples per pixel) is: (a) its largest channel error, in 8-bit sRGB
// units, is no larger, and (b) its RMSE in linear light (compare_images, as `covrast compare`
// reports it) is at most 0.7 times as large. The sizes keep the reference renders (4,096
// samples per pixel in double precision) to a few seconds each.
//
// Some scenes fail these checks with the A-buffer as it is; the failures are the point of the
// set and are left to fail, with the measured numbers in the failure message.
#include <catch2/catch.hpp>

#include <covrast/compare.hpp>
#include <covrast/image.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

#include "test_tempdir.hpp"

namespace {

namespace fs = std::filesystem;
using namespace covrast;

/// A temporary directory of this file's tests.
class TempDir : public covrast::test::TempDir {
 public:
  TempDir() : covrast::test::TempDir("covrast-test-real") {}
};

/// Runs `covrast-scenegen --real DIR` with the given extra arguments; returns std::system's
/// status.
int run_scenegen_real(const fs::path& dir, const std::string& extra_args = "") {
  const std::string command = std::string("\"") + COVRAST_SCENEGEN_PATH + "\" --real \"" +
                              dir.string() + "\" " + extra_args + " >/dev/null 2>&1";
  return std::system(command.c_str());
}

std::string read_bytes(const fs::path& path) {
  std::ifstream stream(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>()};
}

std::map<std::string, std::string> files_in(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    files[entry.path().filename().string()] = read_bytes(entry.path());
  }
  return files;
}

Image render_in_mode(const Scene& scene, const char* mode, int width, int height) {
  RenderOptions options;
  options.mode = parse_render_mode(mode);
  options.width = width;
  options.height = height;
  Renderer renderer(scene, options);
  return renderer.render_frame().color;
}

/// Renders the scene at width x height in coverage, reference and the two 256-sample
/// supersampling patterns, and checks (a) and (b) above against the better of ssaa:16 (the
/// ordered grid) and ssaa-cmj:16 (n-rooks) in each measure: the best supersampling at 256.
void check_coverage_against_ssaa16(const Scene& scene, const std::string& label, int width,
                                   int height) {
  const Image reference = render_in_mode(scene, "reference", width, height);
  const CompareResult coverage =
      compare_images(render_in_mode(scene, "coverage", width, height), reference);
  const CompareResult grid =
      compare_images(render_in_mode(scene, "ssaa:16", width, height), reference);
  const CompareResult cmj =
      compare_images(render_in_mode(scene, "ssaa-cmj:16", width, height), reference);
  const int best_max = std::min(grid.max_diff_srgb8, cmj.max_diff_srgb8);
  const double best_rmse = std::min(grid.rmse_linear, cmj.rmse_linear);
  INFO(label << " at " << width << "x" << height << " against the reference: coverage max_diff "
             << coverage.max_diff_srgb8 << "/255, rmse " << coverage.rmse_linear
             << "; ssaa:16 max_diff " << grid.max_diff_srgb8 << "/255, rmse " << grid.rmse_linear
             << "; ssaa-cmj:16 max_diff " << cmj.max_diff_srgb8 << "/255, rmse " << cmj.rmse_linear
             << " (coverage rmse / best = " << coverage.rmse_linear / best_rmse
             << ", at most 0.7 allowed)");
  CHECK(coverage.max_diff_srgb8 <= best_max);
  CHECK(coverage.rmse_linear <= 0.7 * best_rmse);
}

/// Generates one real-content scene (with --only) and loads it.
Scene generate_and_load(const TempDir& dir, const std::string& name) {
  REQUIRE(run_scenegen_real(dir.path(), "--only " + name) == 0);
  return load_scene(dir.path() / (name + ".json"));
}

void check_real_scene(const std::string& name, int width, int height) {
  TempDir dir;
  const Scene scene = generate_and_load(dir, name);
  check_coverage_against_ssaa16(scene, name, width, height);
}

}  // namespace

TEST_CASE("covrast-scenegen --real writes the set, the same bytes every run", "[real][scenegen]") {
  TempDir first;
  TempDir second;
  REQUIRE(run_scenegen_real(first.path()) == 0);
  REQUIRE(run_scenegen_real(second.path()) == 0);
  const std::map<std::string, std::string> files = files_in(first.path());
  const bool same_bytes = files == files_in(second.path());
  CHECK(same_bytes);
  for (const char* name :
       {"folded_sphere", "pleated_sheet", "torus_knot", "interpenetrating", "open_parts", "decals",
        "cad_assembly", "stacked", "stacked_offset", "sphere_grid_per_triangle"}) {
    INFO(name);
    CHECK(files.count(std::string(name) + ".json") == 1);
  }

  // Sizes and topology the scenes rely on (closed meshes get their back faces culled).
  const auto mesh = [&first](const char* file) { return load_mesh(first.path() / file); };
  const auto folded = mesh("folded_sphere.obj");
  CHECK(folded->triangle_count() >= 150000);
  CHECK(folded->triangle_count() <= 250000);
  CHECK(folded->closed_orientation == 1);
  const auto knot = mesh("torus_knot.obj");
  CHECK(knot->triangle_count() >= 50000);
  CHECK(knot->triangle_count() <= 100000);
  CHECK(knot->closed_orientation == 1);
  CHECK(mesh("interpenetrating_sphere.obj")->closed_orientation == 1);
  CHECK(mesh("interpenetrating_box.obj")->closed_orientation == 1);
  CHECK(mesh("open_parts_eye.obj")->closed_orientation == 1);
  CHECK(mesh("open_parts_shell.obj")->closed_orientation == 0);
  CHECK(mesh("pleated_sheet.obj")->closed_orientation == 0);
  const auto cad = mesh("cad_assembly.obj");
  CHECK(cad->triangle_count() >= 100000);
  CHECK(cad->triangle_count() <= 200000);
  CHECK(cad->closed_orientation == 0);
  const auto stacked = mesh("stacked.obj");
  REQUIRE(stacked->triangle_count() == 2000);
  CHECK(stacked->positions.size() == 3);
  CHECK(mesh("stacked_offset.obj")->triangle_count() == 2000);

  // sphere_grid_per_triangle.json is scenes/sphere_grid.json with per_triangle colours.
  const Scene grid = load_scene(first.path() / "sphere_grid_per_triangle.json");
  const Scene committed = load_scene(fs::path(COVRAST_SOURCE_DIR) / "scenes/sphere_grid.json");
  CHECK(grid.width == committed.width);
  CHECK(grid.height == committed.height);
  REQUIRE(grid.meshes.size() == committed.meshes.size());
  for (std::size_t i = 0; i < grid.meshes.size(); ++i) {
    CHECK(grid.meshes[i].color_source == ColorSource::PerTriangle);
    CHECK(grid.meshes[i].model == committed.meshes[i].model);
  }

  TempDir refused;
  CHECK(run_scenegen_real(refused.path(), "--only boxes") != 0);  // a committed scene
  CHECK(fs::is_empty(refused.path()));
}

// The quality tests below are [sanitizer-slow]: each renders the reference (4,096 samples per
// pixel) and ssaa:16 of a real-content scene: 1.5-3.5 minutes each under ASan+UBSan (-O1); the
// same render paths run there in the pipeline, coverage and supersampling tests.
TEST_CASE("real-content folded_sphere: coverage closer to the reference than ssaa:16",
          "[real][sanitizer-slow]") {
  check_real_scene("folded_sphere", 160, 90);
}

TEST_CASE("real-content pleated_sheet: coverage closer to the reference than ssaa:16",
          "[real][sanitizer-slow]") {
  check_real_scene("pleated_sheet", 160, 90);
}

TEST_CASE("real-content torus_knot: coverage closer to the reference than ssaa:16",
          "[real][sanitizer-slow]") {
  check_real_scene("torus_knot", 160, 90);
}

TEST_CASE("real-content interpenetrating: coverage closer to the reference than ssaa:16",
          "[real][sanitizer-slow]") {
  check_real_scene("interpenetrating", 160, 90);
}

TEST_CASE("real-content open_parts: coverage closer to the reference than ssaa:16",
          "[real][sanitizer-slow]") {
  check_real_scene("open_parts", 160, 90);
}

TEST_CASE("real-content decals: coverage closer to the reference than ssaa:16",
          "[real][sanitizer-slow]") {
  check_real_scene("decals", 160, 90);
}

// 128x72: at 160x90 the reference alone takes about 12 s here (long thin triangles).
TEST_CASE("real-content cad_assembly: coverage closer to the reference than ssaa:16",
          "[real][sanitizer-slow]") {
  check_real_scene("cad_assembly", 128, 72);
}

// 2,000 copies in every covered pixel make the reference cost 2,000 x 4,096 samples per pixel,
// so the stacked scenes render at half their 64x48.
TEST_CASE("real-content stacked: coverage closer to the reference than ssaa:16",
          "[real][sanitizer-slow]") {
  check_real_scene("stacked", 32, 24);
}

// Known failure (tagged [!shouldfail]), issue "Coverage mode on real meshes" (open): 2000
// copies of a triangle, each shifted a little, overflow into 256 samples along their edges,
// where the visible share of each copy is a sample estimate; measured figures in the message.
// [!shouldfail] runs it every time and fails the day coverage meets the bound, so that the
// tag is removed then.
TEST_CASE("real-content stacked_offset: coverage closer to the reference than ssaa:16",
          "[real][!shouldfail][sanitizer-slow]") {
  check_real_scene("stacked_offset", 32, 24);
}

// The full 1920x1080 grid is too slow for the reference, so this renders its central 160x90
// pixels instead, where four spheres' silhouettes meet: the same camera with the field of view
// narrowed so that tan(fovy' / 2) = tan(fovy / 2) * 90 / 1080 (in coverage mode the image is
// byte for byte the centre of the full-size one).
TEST_CASE("real-content sphere_grid_per_triangle (central 160x90): coverage closer than ssaa:16",
          "[real][sanitizer-slow]") {
  TempDir dir;
  Scene scene = generate_and_load(dir, "sphere_grid_per_triangle");
  REQUIRE(scene.height == 1080);
  const double half_fovy = scene.camera.fovy_deg * (3.14159265358979323846 / 360.0);
  scene.camera.fovy_deg =
      std::atan(std::tan(half_fovy) * 90.0 / 1080.0) * (360.0 / 3.14159265358979323846);
  check_coverage_against_ssaa16(scene, "sphere_grid_per_triangle, central crop,", 160, 90);
}
