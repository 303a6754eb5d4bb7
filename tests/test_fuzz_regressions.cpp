// Regression tests for what the fuzz targets (tests/fuzz, docs/testing.md) found: each input
// that once crashed a target, rebuilt here in the test. The crashing files themselves are in
// tests/fuzz/regressions/NAME and are replayed by the fuzz build's ctest (fuzz_replay_NAME).
#include "test_tempdir.hpp"

#include <covrast/error.hpp>
#include <covrast/options.hpp>
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
