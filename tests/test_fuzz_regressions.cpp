// Regression tests for what the fuzz targets (tests/fuzz, docs/testing.md) found: each input
// that once crashed a target, rebuilt here in the test. The crashing files themselves are in
// tests/fuzz/regressions/NAME and are replayed by the fuzz build's ctest (fuzz_replay_NAME).
#include "test_tempdir.hpp"

#include <covrast/error.hpp>
#include <covrast/scene.hpp>

#include <catch2/catch.hpp>

#include <fstream>
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
