// Regression tests for what the fuzz targets (tests/fuzz, docs/testing.md) found: each input
// that once crashed a target, rebuilt here in the test. The crashing files themselves are in
// tests/fuzz/regressions/NAME and are replayed by the fuzz build's ctest (fuzz_replay_NAME).
#include "fuzz/render_splits.hpp"
#include "test_tempdir.hpp"

#include <covrast/error.hpp>
#include <covrast/options.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include <bit>
#include <cstdint>
#include <fstream>
#include <memory>
#include <string>

namespace {

using covrast::test::TempDir;

/// The message of the InputError that loading a scene file with `text` throws; "" if none.
std::string load_error(const TempDir& dir, const std::string& text) {
  const std::filesystem::path path = dir / "scene.json";
  std::ofstream(path, std::ios::binary) << text;
  try {
    covrast::load_scene(path);
  } catch (const covrast::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// fuzz_scene_json, crash-de3e67fc: a JSON number beyond a double's range escaped load_scene as
// nlohmann's out_of_range (only parse_error was caught), so the command line said "internal
// error" (exit 1) without naming the file.
TEST_CASE("fuzz regression: a JSON number beyond a double's range is an input error",
          "[fuzz][scene]") {
  TempDir dir("covrast-fuzz-regressions");
  const std::string file = (dir / "scene.json").string();
  for (const char* number : {"1e400", "-1e3080", "1e999999999"}) {
    INFO(number);
    const std::string message =
        load_error(dir, std::string(R"({"width": 16, "height": 9, "camera": {"eye": [0, 0, )") +
                            number + R"(]}, "meshes": []})");
    CHECK(message == file + ": number overflow parsing '" + number + "'");
  }
  // The largest finite double and the denormals still load as numbers (and fail later, on the
  // camera, for the reason the scene gives).
  const std::string message = load_error(
      dir,
      R"({"width": 16, "height": 9, "camera": {"eye": [0, 0, 1.7976931348623157e308]}, "meshes": []})");
  CHECK(message.find("number overflow") == std::string::npos);
  CHECK(message.rfind(file + ": ", 0) == 0);
}

// fuzz_manifest, crash-41e35426: a manifest mode of "coverage" plus an escaped newline came
// back in parse_render_mode's message as it was, so the error took two lines. Every
// InputError now turns control characters into '?'.
TEST_CASE("fuzz regression: an input error is one line whatever the input quoted in it",
          "[fuzz][cli]") {
  for (const char* mode : {"coverage\n", "msaa:\t4", "ssaa:4\r", "aliased\x7f"}) {
    INFO(mode);
    try {
      covrast::parse_render_mode(mode);
      FAIL("accepted");
    } catch (const covrast::InputError& e) {
      const std::string message = e.what();
      CHECK(message.find_first_of("\n\t\r\x7f") == std::string::npos);
      CHECK(message.rfind("unknown mode '", 0) == 0);
    }
  }
  // UTF-8 (a file name, say) is kept as it is.
  CHECK(std::string(covrast::InputError("a\nb: caf\xc3\xa9").what()) == "a?b: caf\xc3\xa9");
}

// fuzz_render, crash-6b0dcfa6: triangles with NaN corners, clipped, set up with NaN depth
// slopes; the exact clipping of a mixed pixel (visible_parts.hpp) took both fragments as
// visible all over their parts and a debug check stopped the render (their areas did not fit
// in the pixel). A plane that is not finite now leaves the pixel to the samples.
TEST_CASE("fuzz regression: NaN depth planes leave a mixed pixel to the samples",
          "[fuzz][coverage]") {
  const std::uint32_t bits[2][9] = {{0xbf4ccccd, 0xbf333333, 0x00000000, 0x3f666666, 0xbe4ccccd,
                                     0x00000000, 0xffffffff, 0xffffffff, 0xffffffff},
                                    {0xffffffff, 0xffffffff, 0xffffffff, 0xcccccdff, 0x666666bd,
                                     0x0000003f, 0x00000000, 0x0000003f, 0x8000003f}};
  auto mesh = std::make_shared<covrast::MeshData>();
  mesh->source = "fuzz";
  for (const auto& triangle : bits) {
    for (int corner = 0; corner < 3; ++corner) {
      mesh->indices.push_back(std::uint32_t(mesh->positions.size()));
      mesh->positions.push_back({std::bit_cast<float>(triangle[3 * corner]),
                                 std::bit_cast<float>(triangle[3 * corner + 1]),
                                 std::bit_cast<float>(triangle[3 * corner + 2])});
    }
  }
  covrast::analyze_mesh_topology(*mesh);
  covrast::Scene scene;
  scene.width = 9;
  scene.height = 7;
  scene.background_linear = glm::vec3(0.02f, 0.05f, 0.1f);
  covrast::add_instance(scene, mesh, covrast::InstanceDesc{});
  covrast::check_scene(scene);
  covrast::RenderOptions options;
  options.mode = covrast::parse_render_mode("coverage");
  options.want_depth = true;
  const auto [a, b] = covrast::fuzz::render_two_splits(scene, options);
  CHECK(a.color.rgb == b.color.rgb);
  CHECK(a.stats.resolve_paths.total() == std::uint64_t(scene.width) * scene.height);
}
