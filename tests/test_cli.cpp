// Tests of the covrast command line (the built executable, COVRAST_CLI_PATH): exit codes,
// one-line error messages, and that failed runs create no output and leave existing files
// untouched. Each test writes its scenes, meshes and images into a fresh temporary directory.
#include <covrast/image.hpp>
#include <covrast/renderer.hpp>
#include <covrast/tools.hpp>

#include <sys/wait.h>
#include <unistd.h>
#include "color/srgb.hpp"

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "test_cli_run.hpp"
#include "test_tempdir.hpp"

namespace fs = std::filesystem;

namespace {

/// A temporary directory of this file's tests.
class TempDir : public covrast::test::TempDir {
 public:
  TempDir() : covrast::test::TempDir("covrast-test-cli") {}
};

using covrast::test::read_text;
using covrast::test::RunResult;
using covrast::test::write_text;

/// Runs the CLI with `args` in `dir`.
RunResult run_cli(const TempDir& dir, std::initializer_list<std::string> args) {
  return covrast::test::run_cli_in(dir.path(), std::vector<std::string>(args));
}

/// An error must be exactly one line on stderr starting with "covrast: error: ".
void check_one_error_line(const RunResult& r) {
  INFO("stderr: " << r.err);
  REQUIRE(r.err.rfind("covrast: error: ", 0) == 0);
  REQUIRE(r.err.find('\n') == r.err.size() - 1);
}

/// Files in `dir` other than the captured stdout/stderr and the inputs listed.
std::vector<std::string> extra_files(const TempDir& dir,
                                     std::initializer_list<std::string> inputs) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    const std::string name = entry.path().filename().string();
    bool is_input = false;
    for (const std::string& input : inputs) is_input = is_input || name == input;
    if (!is_input) names.push_back(name);
  }
  return names;
}

const char* const kTriangleObj =
    "v 0 1 0\n"
    "v -0.866025404 -0.5 0\n"
    "v 0.866025404 -0.5 0\n"
    "f 1 2 3\n";

std::string scene_json(const std::string& obj, int width = 24, int height = 16) {
  return "{\n  \"width\": " + std::to_string(width) + ",\n  \"height\": " + std::to_string(height) +
         ",\n  \"background\": [0, 0, 0],\n"
         "  \"camera\": {\"eye\": [0, 0, 3], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
         "\"fovy_deg\": 45, \"near\": 0.5, \"far\": 10},\n"
         "  \"meshes\": [{\"obj\": \"" +
         obj + "\", \"color\": [1, 0.5, 0.25]}]\n}\n";
}

/// A directory with a good scene "scene.json" referencing "tri.obj".
void write_good_scene(const TempDir& dir) {
  write_text(dir / "tri.obj", kTriangleObj);
  write_text(dir / "scene.json", scene_json("tri.obj"));
}

/// Renders with `extra` arguments that must fail with exit 2, one error line, and no output.
RunResult expect_render_fails(const TempDir& dir, std::initializer_list<std::string> args) {
  const RunResult r = run_cli(dir, args);
  INFO("stdout: " << r.out);
  CHECK(r.exit_code == 2);
  check_one_error_line(r);
  CHECK(r.out.empty());
  return r;
}

covrast::Image test_image(int width, int height, int seed) {
  covrast::Image image;
  image.width = width;
  image.height = height;
  image.rgb.resize(std::size_t(width) * height * 3);
  for (std::size_t i = 0; i < image.rgb.size(); ++i) {
    image.rgb[i] = std::uint8_t((i * 37 + std::size_t(seed) * 11) % 256);
  }
  return image;
}

}  // namespace

TEST_CASE("cli: --help and --version exit 0", "[cli]") {
  TempDir dir;
  RunResult r = run_cli(dir, {"--help"});
  CHECK(r.exit_code == 0);
  CHECK(r.out.find("render") != std::string::npos);
  CHECK(r.out.find("info") != std::string::npos);
  CHECK(r.out.find("compare") != std::string::npos);
  for (const char* sub : {"render", "info", "compare"}) {
    r = run_cli(dir, {sub, "--help"});
    INFO(sub);
    CHECK(r.exit_code == 0);
    CHECK(r.out.find("Usage") != std::string::npos);
  }
  r = run_cli(dir, {"render", "--help"});
  CHECK(r.out.find("--tile") != std::string::npos);
  CHECK(r.out.find("--stats") != std::string::npos);
  r = run_cli(dir, {"--version"});
  CHECK(r.exit_code == 0);
  // The version of project() in CMakeLists.txt, not a copy of it.
  CHECK(r.out == "covrast " COVRAST_VERSION "\n");
}

TEST_CASE("cli: usage errors exit 2 with one error line", "[cli]") {
  TempDir dir;
  check_one_error_line(run_cli(dir, {}));
  CHECK(run_cli(dir, {}).exit_code == 2);
  RunResult r = run_cli(dir, {"frobnicate"});
  CHECK(r.exit_code == 2);
  check_one_error_line(r);
  r = run_cli(dir, {"render", "x.json"});  // missing -o
  CHECK(r.exit_code == 2);
  check_one_error_line(r);
}

TEST_CASE("cli: render rejects bad input with exit 2 and creates nothing", "[cli]") {
  TempDir dir;
  write_good_scene(dir);
  const std::string scene = (dir / "scene.json").string();
  const std::string out = (dir / "out.png").string();

  SECTION("malformed JSON names file:line:col") {
    write_text(dir / "bad.json", "{\n  \"width\": 24,\n  \"height\" 16\n}\n");
    const RunResult r =
        expect_render_fails(dir, {"render", (dir / "bad.json").string(), "-o", out});
    CHECK(r.err.find((dir / "bad.json").string() + ":3:") != std::string::npos);
    CHECK(extra_files(dir, {"scene.json", "tri.obj", "bad.json"}).empty());
  }
  SECTION("missing mesh file") {
    write_text(dir / "missing.json", scene_json("nope.obj"));
    const RunResult r =
        expect_render_fails(dir, {"render", (dir / "missing.json").string(), "-o", out});
    CHECK(r.err.find("nope.obj") != std::string::npos);
    CHECK(extra_files(dir, {"scene.json", "tri.obj", "missing.json"}).empty());
  }
  SECTION("out-of-range face index") {
    write_text(dir / "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    write_text(dir / "badface.json", scene_json("bad.obj"));
    const RunResult r =
        expect_render_fails(dir, {"render", (dir / "badface.json").string(), "-o", out});
    CHECK(r.err.find("bad.obj") != std::string::npos);
    CHECK(extra_files(dir, {"scene.json", "tri.obj", "bad.obj", "badface.json"}).empty());
  }
  SECTION("size 0x10") {
    expect_render_fails(dir, {"render", scene, "-o", out, "--size", "0x10"});
    CHECK(extra_files(dir, {"scene.json", "tri.obj"}).empty());
  }
  SECTION("size 20000x10") {
    expect_render_fails(dir, {"render", scene, "-o", out, "--size", "20000x10"});
    CHECK(extra_files(dir, {"scene.json", "tri.obj"}).empty());
  }
  SECTION("malformed size") {
    expect_render_fails(dir, {"render", scene, "-o", out, "--size", "24by16"});
    CHECK(extra_files(dir, {"scene.json", "tri.obj"}).empty());
  }
  SECTION("unwritable output path") {
    const RunResult r = expect_render_fails(dir, {"render", scene, "-o", "/nonexistent-dir/x.png"});
    CHECK(r.err.find("/nonexistent-dir/x.png") != std::string::npos);
    CHECK_FALSE(fs::exists("/nonexistent-dir"));
  }
  SECTION("unknown mode") {
    expect_render_fails(dir, {"render", scene, "-o", out, "--mode", "blurry"});
    CHECK(extra_files(dir, {"scene.json", "tri.obj"}).empty());
  }
  SECTION("tile 7") {
    expect_render_fails(dir, {"render", scene, "-o", out, "--tile", "7"});
    CHECK(extra_files(dir, {"scene.json", "tri.obj"}).empty());
  }
  SECTION("repeat 0") {
    expect_render_fails(dir, {"render", scene, "-o", out, "--repeat", "0"});
    CHECK(extra_files(dir, {"scene.json", "tri.obj"}).empty());
  }
  SECTION("unsupported depth extension") {
    expect_render_fails(dir, {"render", scene, "-o", out, "--depth", (dir / "d.exr").string()});
    CHECK(extra_files(dir, {"scene.json", "tri.obj"}).empty());
  }
}

TEST_CASE("cli: a failed render leaves an existing output file untouched", "[cli]") {
  TempDir dir;
  write_good_scene(dir);
  const fs::path out = dir / "out.png";
  const std::string before = "not really a png, but it must survive byte for byte\n";
  write_text(out, before);
  write_text(dir / "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  write_text(dir / "badface.json", scene_json("bad.obj"));

  expect_render_fails(dir, {"render", (dir / "badface.json").string(), "-o", out.string()});
  CHECK(read_text(out) == before);
  expect_render_fails(
      dir, {"render", (dir / "scene.json").string(), "-o", out.string(), "--size", "0x10"});
  CHECK(read_text(out) == before);
  expect_render_fails(dir,
                      {"render", (dir / "scene.json").string(), "-o", out.string(), "--tile", "7"});
  CHECK(read_text(out) == before);
  CHECK(extra_files(dir, {"scene.json", "tri.obj", "out.png", "bad.obj", "badface.json"}).empty());
}

TEST_CASE("cli: render of a good scene writes a PNG of the requested size", "[cli]") {
  TempDir dir;
  write_good_scene(dir);
  const fs::path out = dir / "out.png";

  RunResult r = run_cli(dir, {"render", (dir / "scene.json").string(), "-o", out.string()});
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out == "wrote " + out.string() + "\n");
  CHECK(r.err.empty());
  covrast::Image image = covrast::read_png(out);
  CHECK(image.width == 24);
  CHECK(image.height == 16);
  CHECK(extra_files(dir, {"scene.json", "tri.obj", "out.png"}).empty());

  // --size overrides the scene; --quiet --stats prints only the JSON line.
  r = run_cli(dir, {"render", (dir / "scene.json").string(), "-o", out.string(), "--size", "40x8",
                    "--quiet", "--stats", "--repeat", "3", "--tile", "16", "--threads", "2"});
  REQUIRE(r.exit_code == 0);
  image = covrast::read_png(out);
  CHECK(image.width == 40);
  CHECK(image.height == 8);
  REQUIRE(r.out.find('\n') == r.out.size() - 1);
  const nlohmann::json stats = nlohmann::json::parse(r.out);
  CHECK(stats.at("mode") == "coverage");
  CHECK(stats.at("width") == 40);
  CHECK(stats.at("height") == 8);
  CHECK(stats.at("tile") == 16);
  CHECK(stats.at("threads") == 2);
  CHECK(stats.at("frames") == 3);
  // The SIMD target the kernels ran on: the library's own answer (what golden reports record).
  CHECK(stats.at("simd") == covrast::build_info().simd_target);
  CHECK(stats.at("triangles").at("in") == 1);
  for (const char* key :
       {"setup_ms", "binning_ms", "raster_ms", "resolve_ms", "post_ms", "render_ms"}) {
    INFO(key);
    CHECK(stats.at(key).get<double>() >= 0.0);
  }

  // Depth as PFM: header of a 40x8 greyscale float map.
  const fs::path depth = dir / "depth.pfm";
  r = run_cli(dir, {"render", (dir / "scene.json").string(), "-o", out.string(), "--size", "40x8",
                    "--depth", depth.string()});
  REQUIRE(r.exit_code == 0);
  CHECK(r.out == "wrote " + out.string() + "\nwrote " + depth.string() + "\n");
  const std::string pfm = read_text(depth);
  const std::string header = "Pf\n40 8\n-1.0\n";
  CHECK(pfm.size() == header.size() + 40 * 8 * 4);
  CHECK(pfm.compare(0, header.size(), header) == 0);
}

TEST_CASE("cli: --threads above the hardware threads prints nothing from the scheduler", "[cli]") {
  // oneTBB's default limit is the hardware threads; without covrast raising it for an explicit
  // count, the render still succeeded but oneTBB printed "TBB Warning: The number of workers
  // is currently limited ..." to stderr, even with --quiet.
  TempDir dir;
  write_good_scene(dir);
  const int threads = int(std::thread::hardware_concurrency()) + 3;
  const RunResult r = run_cli(
      dir, {"render", (dir / "scene.json").string(), "-o", (dir / "out.png").string(), "--size",
            "512x512", "--tile", "8", "--threads", std::to_string(threads), "--quiet", "--stats"});
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());
  CHECK(nlohmann::json::parse(r.out).at("threads") == threads);
}

TEST_CASE("cli: scene warnings go to stderr, --strict makes them errors", "[cli]") {
  TempDir dir;
  // The second triangle has an infinite coordinate (1e400 overflows): dropped with a warning.
  write_text(dir / "inf.obj", std::string(kTriangleObj) + "v 1e400 0 0\nf 1 2 4\n");
  write_text(dir / "scene.json", scene_json("inf.obj"));
  const fs::path out = dir / "out.png";

  RunResult r =
      run_cli(dir, {"render", (dir / "scene.json").string(), "-o", out.string(), "--strict"});
  INFO("stderr: " << r.err);
  CHECK(r.exit_code == 2);
  CHECK(r.out.empty());
  // The error is one line, the first; the warning it is about follows.
  CHECK(r.err.rfind("covrast: error: ", 0) == 0);
  CHECK(r.err.find("--strict treats warnings as errors: ") != std::string::npos);
  CHECK(r.err.find("dropped 1 triangles") != std::string::npos);
  CHECK(r.err.find("\nwarning: ") != std::string::npos);
  CHECK(r.err.find("\ncovrast: error") == std::string::npos);
  CHECK_FALSE(fs::exists(out));

  r = run_cli(dir, {"render", (dir / "scene.json").string(), "-o", out.string()});
  CHECK(r.exit_code == 0);
  CHECK(r.err.rfind("warning: ", 0) == 0);
  CHECK(r.err.find("dropped 1 triangles") != std::string::npos);
  CHECK(r.err.find("covrast: error") == std::string::npos);
  CHECK(fs::exists(out));
}

TEST_CASE("cli: info describes a good scene", "[cli]") {
  TempDir dir;
  write_good_scene(dir);
  RunResult r = run_cli(dir, {"info", (dir / "scene.json").string()});
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("24x16") != std::string::npos);
  CHECK(r.out.find("tri.obj") != std::string::npos);

  r = run_cli(dir, {"info", (dir / "scene.json").string(), "--json"});
  REQUIRE(r.exit_code == 0);
  const nlohmann::json info = nlohmann::json::parse(r.out);
  CHECK(info.at("width") == 24);
  CHECK(info.at("height") == 16);
  CHECK(info.at("triangles") == 1);
  CHECK(info.at("vertices") == 3);
  REQUIRE(info.at("meshes").size() == 1);
  CHECK(info.at("meshes")[0].at("triangles") == 1);
  CHECK(info.at("meshes")[0].at("color_source") == "uniform");
  CHECK(info.at("camera").at("fovy_deg") == 45.0);
  // The triangle's world bounds (identity model): x in +-0.866025404, y in [-0.5, 1], z = 0.
  const nlohmann::json& bounds = info.at("bounds");
  CHECK(bounds.at("min")[0].get<double>() == Approx(-0.866025404));
  CHECK(bounds.at("min")[1].get<double>() == Approx(-0.5));
  CHECK(bounds.at("max")[0].get<double>() == Approx(0.866025404));
  CHECK(bounds.at("max")[1].get<double>() == Approx(1.0));
  CHECK(bounds.at("max")[2].get<double>() == 0.0);
  CHECK(info.at("warnings").empty());
  CHECK_FALSE(info.at("meshes")[0].contains("alpha_materials"));

  // A BLEND material is counted, in text and JSON (docs/transparency.md).
  std::string blend = scene_json("tri.obj");
  blend.replace(blend.find("\"color\""), 0, "\"material\": {\"alpha_mode\": \"blend\"}, ");
  write_text(dir / "blend.json", blend);
  r = run_cli(dir, {"info", (dir / "blend.json").string()});
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("alpha materials: 0 mask, 1 blend") != std::string::npos);
  r = run_cli(dir, {"info", (dir / "blend.json").string(), "--json"});
  REQUIRE(r.exit_code == 0);
  CHECK(nlohmann::json::parse(r.out).at("meshes")[0].at("alpha_materials").at("blend") == 1);

  r = run_cli(dir, {"info", (dir / "nope.json").string()});
  CHECK(r.exit_code == 2);
  check_one_error_line(r);
}

TEST_CASE("cli: info takes a model file as render does", "[cli]") {
  TempDir dir;
  write_good_scene(dir);
  // A model path is framed by the default camera, as `covrast render MODEL` frames it.
  RunResult r = run_cli(dir, {"info", (dir / "tri.obj").string(), "--json"});
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  const nlohmann::json info = nlohmann::json::parse(r.out);
  CHECK(info.at("triangles") == 1);
  CHECK(info.at("vertices") == 3);
  REQUIRE(info.at("meshes").size() == 1);
  CHECK(info.at("meshes")[0].at("source").get<std::string>().find("tri.obj") != std::string::npos);

  // A model that is not valid is exit 2 naming it, not a JSON syntax error about the scene.
  write_text(dir / "bad.obj", "v 0 0 0\nf 1 2 3\n");
  r = run_cli(dir, {"info", (dir / "bad.obj").string()});
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("bad.obj") != std::string::npos);
  CHECK(r.err.find("JSON") == std::string::npos);
  check_one_error_line(r);
}

TEST_CASE("cli: viewer options place the camera, the environment and the tone map", "[cli]") {
  TempDir dir;
  write_good_scene(dir);
  const std::string scene = (dir / "scene.json").string();
  // The orbit: target + radius (sin(phi) sin(theta), cos(phi), sin(phi) cos(theta)).
  const auto eye_of = [&](std::initializer_list<std::string> extra) {
    std::vector<std::string> args = {"info", scene, "--json"};
    args.insert(args.end(), extra.begin(), extra.end());
    const RunResult r = covrast::test::run_cli_in(dir.path(), args);
    INFO("stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    return nlohmann::json::parse(r.out);
  };
  nlohmann::json info = eye_of({"--orbit", "90,90,2", "--target", "1,2,3", "--fov", "30"});
  const nlohmann::json& camera = info.at("camera");
  CHECK(camera.at("eye")[0].get<double>() == Approx(3.0));
  CHECK(camera.at("eye")[1].get<double>() == Approx(2.0));
  CHECK(camera.at("eye")[2].get<double>() == Approx(3.0).margin(1e-12));
  CHECK(camera.at("target")[1] == 2.0);
  CHECK(camera.at("fovy_deg") == 30.0);
  // Near and far hold the model's bounding sphere (box x in +-0.866, y in [-0.5, 1], z = 0:
  // centre (0, 0.25, 0), radius |(1.732, 1.5, 0)| / 2) with 1% to spare.
  const double distance = std::sqrt(9.0 + 1.75 * 1.75 + 9.0);
  const double radius = 0.5 * std::sqrt(3.0 + 2.25);
  CHECK(camera.at("near").get<double>() == Approx(0.99 * (distance - radius)).epsilon(1e-6));
  CHECK(camera.at("far").get<double>() == Approx(1.01 * (distance + radius)).epsilon(1e-6));
  info = eye_of({"--orbit", "0,0,1"});  // straight down: up is -z
  CHECK(info.at("camera").at("eye")[1].get<double>() == Approx(1.0));
  CHECK(info.at("camera").at("up")[2].get<double>() == Approx(-1.0));
  info = eye_of({"--orbit", "0,90,2"});
  CHECK(info.at("camera").at("eye")[2].get<double>() == Approx(2.0));
  CHECK(info.at("tone_map") == "none");
  CHECK_FALSE(info.contains("environment"));

  info = eye_of({"--environment", "studio", "--environment-rotation", "30", "--tone-map",
                 "khronos-pbr-neutral", "--exposure", "1.5"});
  CHECK(info.at("environment").at("width") == 256);
  CHECK(info.at("environment").at("rotation_deg") == 30.0);
  CHECK(info.at("tone_map") == "khronos-pbr-neutral");
  CHECK(info.at("exposure") == 1.5);

  // Bad values: exit 2, one line naming the option; nothing written.
  for (const std::vector<std::string>& bad :
       std::vector<std::vector<std::string>>{{"--orbit", "1,2"},
                                             {"--orbit", "0,90,-1"},
                                             {"--target", "a,b,c"},
                                             {"--fov", "180"},
                                             {"--tone-map", "filmic"},
                                             {"--exposure", "0"},
                                             {"--environment", "missing.hdr"}}) {
    std::vector<std::string> args = {"render", scene, "-o", (dir / "x.png").string()};
    args.insert(args.end(), bad.begin(), bad.end());
    const RunResult r = covrast::test::run_cli_in(dir.path(), args);
    INFO(bad[0] << " " << bad[1]);
    CHECK(r.exit_code == 2);
    check_one_error_line(r);
    CHECK(r.err.find(bad[0] == "--environment" ? "missing.hdr" : bad[0]) != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "x.png"));
  }
}

TEST_CASE("cli: scene keys environment, tone_map and exposure", "[cli]") {
  TempDir dir;
  write_good_scene(dir);
  // A 4 x 2 environment PNG beside the scene, named relative to it.
  covrast::Image env;
  env.width = 4;
  env.height = 2;
  env.rgb.assign(24, 128);
  covrast::write_png(env, dir / "env.png");
  const auto with_keys = [&](const std::string& keys) {
    std::string text = scene_json("tri.obj");
    text.insert(text.find('{') + 1, keys + ", ");
    write_text(dir / "keys.json", text);
    return covrast::test::run_cli_in(dir.path(), {"info", (dir / "keys.json").string(), "--json"});
  };
  RunResult r =
      with_keys(R"("environment": {"file": "env.png", "rotation_deg": 45, "intensity": 2}, )"
                R"("tone_map": "aces-narkowicz", "exposure": 0.5)");
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  nlohmann::json info = nlohmann::json::parse(r.out);
  CHECK(info.at("environment").at("width") == 4);
  CHECK(info.at("environment").at("intensity") == 2.0);
  CHECK(info.at("environment").at("mean_radiance")[0].get<double>() ==
        Approx(covrast::detail::srgb_decode(128 / 255.0)).epsilon(1e-6));
  CHECK(info.at("tone_map") == "aces-narkowicz");
  CHECK(info.at("exposure") == 0.5);
  r = with_keys(R"("environment": "studio")");
  REQUIRE(r.exit_code == 0);
  CHECK(nlohmann::json::parse(r.out).at("environment").at("width") == 256);
  for (const std::string& bad :
       {std::string(R"("environment": "sky")"), std::string(R"("environment": {"file": 3})"),
        std::string(R"("environment": {"file": "env.png", "builtin": "studio"})"),
        std::string(R"("environment": {"file": "env.png", "spin": 1})"),
        std::string(R"("environment": {"file": "nope.hdr"})"),
        std::string(R"("environment": {"builtin": "studio", "intensity": -1})"),
        std::string(R"("tone_map": "filmic")"), std::string(R"("exposure": 0)")}) {
    INFO(bad);
    r = with_keys(bad);
    CHECK(r.exit_code == 2);
    check_one_error_line(r);
  }
}

TEST_CASE("cli: scenario renders the render-fidelity harness's JSON", "[cli]") {
  TempDir dir;
  write_good_scene(dir);  // tri.obj
  const std::string out = (dir / "s.png").string();
  const std::string scenario =
      R"({"scenario": {"name": "tri", "model": "tri.obj", "dimensions": {"width": 20, "height": 12},
          "orbit": {"theta": 0, "phi": 90, "radius": 4}, "target": {"x": 0, "y": 0.25, "z": 0},
          "verticalFoV": 40, "renderSkybox": false, "exclude": ["x"]}, "outputFile": ")" +
      out + R"("})";
  RunResult r = covrast::test::run_cli_in(dir.path(), {"scenario", scenario, "--quiet"}, true);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  const covrast::Image image = covrast::read_png(out);
  // Twice the dimensions (the harness's device pixel ratio), transparent where nothing is
  // drawn (RGBA), opaque over the model.
  REQUIRE(image.width == 40);
  REQUIRE(image.height == 24);
  const covrast::RgbaImage rgba = covrast::read_image(out, "scenario output");
  REQUIRE(rgba.rgba.size() == 40u * 24u * 4u);
  CHECK(int(rgba.rgba[3]) == 0);
  CHECK(int(rgba.rgba[(12u * 40u + 20u) * 4u + 3u]) == 255);
  // The same camera, light and tone map through `covrast render` shade the middle alike.
  const std::string rendered = (dir / "r.png").string();
  r = covrast::test::run_cli_in(
      dir.path(),
      {"render", "tri.obj", "-o", rendered, "--size", "40x24", "--orbit", "0,90,4", "--target",
       "0,0.25,0", "--fov", "40", "--environment", "studio", "--tone-map", "khronos-pbr-neutral"},
      true);
  REQUIRE(r.exit_code == 0);
  const covrast::Image same = covrast::read_png(rendered);
  for (int c = 0; c < 3; ++c) CHECK(same.pixel(20, 12)[c] == image.pixel(20, 12)[c]);
  CHECK(image.pixel(20, 12)[0] != 255);
  // A file holding the JSON works as well.
  write_text(dir / "scenario.json", scenario);
  fs::remove(out);
  r = covrast::test::run_cli_in(dir.path(), {"scenario", "scenario.json", "--quiet"}, true);
  CHECK(r.exit_code == 0);
  CHECK(fs::exists(out));
  // renderSkybox: the studio environment behind the model (RGB, no alpha), as `render
  // --skybox` draws it.
  std::string skybox = scenario;
  const std::string no_skybox = "\"renderSkybox\": false";
  skybox.replace(skybox.find(no_skybox), no_skybox.size(), "\"renderSkybox\": true");
  r = covrast::test::run_cli_in(dir.path(), {"scenario", skybox, "--quiet", "--strict"}, true);
  CHECK(r.exit_code == 0);
  r = covrast::test::run_cli_in(dir.path(),
                                {"render", "tri.obj", "-o", rendered, "--size", "40x24", "--orbit",
                                 "0,90,4", "--target", "0,0.25,0", "--fov", "40", "--environment",
                                 "studio", "--tone-map", "khronos-pbr-neutral", "--skybox"},
                                true);
  REQUIRE(r.exit_code == 0);
  CHECK(covrast::read_png(out).rgb == covrast::read_png(rendered).rgb);
  CHECK(covrast::read_image(out, "sky").rgba[3] == 255);
  // Bad input: exit 2, one line.
  for (
      const std::string& bad :
      {std::string(R"({"scenario": {"model": "tri.obj"}})"),
       std::string(R"({"scenario": {"model": "gone.glb"}, "outputFile": "o.png"})"),
       std::string(
           R"({"scenario": {"model": "tri.obj", "lighting": "gone.hdr"}, "outputFile": "o.png"})"),
       std::string(
           R"({"scenario": {"model": "tri.obj", "dimensions": {"width": 0}}, "outputFile": "o.png"})"),
       std::string(
           R"({"scenario": {"model": "tri.obj", "orbit": {"radius": "far"}}, "outputFile": "o.png"})"),
       std::string(R"({"scenario": )"), std::string("missing.json")}) {
    INFO(bad);
    r = covrast::test::run_cli_in(dir.path(), {"scenario", bad}, true);
    CHECK(r.exit_code == 2);
    check_one_error_line(r);
    CHECK_FALSE(fs::exists(dir / "o.png"));
  }
}

TEST_CASE("cli: compare exit codes follow the thresholds", "[cli]") {
  TempDir dir;
  const covrast::Image a = test_image(9, 7, 1);
  covrast::Image b = a;
  b.pixel(4, 3)[1] = std::uint8_t(b.pixel(4, 3)[1] ^ 0x40);  // one channel off by 64
  covrast::write_png(a, dir / "a.png");
  covrast::write_png(a, dir / "a2.png");
  covrast::write_png(b, dir / "b.png");
  const std::string pa = (dir / "a.png").string();
  const std::string pa2 = (dir / "a2.png").string();
  const std::string pb = (dir / "b.png").string();

  RunResult r =
      run_cli(dir, {"compare", pa, pa2, "--max-rmse", "0", "--max-diff", "0", "--max-pixels", "0"});
  CHECK(r.exit_code == 0);
  CHECK(r.err.empty());

  r = run_cli(dir, {"compare", pa, pb, "--max-diff", "8"});
  CHECK(r.exit_code == 1);
  CHECK(r.err == "FAIL: diff 64 > 8\n");

  r = run_cli(dir, {"compare", pa, pb, "--max-pixels", "0.5", "--max-diff", "64"});
  CHECK(r.exit_code == 0);  // 1 of 63 pixels differs; largest difference exactly 64

  r = run_cli(dir, {"compare", pa, pb, "--max-pixels", "0.01"});
  CHECK(r.exit_code == 1);
  CHECK(r.err.rfind("FAIL: pixels ", 0) == 0);

  // No thresholds: a difference alone is not a failure.
  r = run_cli(dir, {"compare", pa, pb, "--json", "--heatmap", (dir / "heat.png").string()});
  CHECK(r.exit_code == 0);
  REQUIRE(r.out.find('\n') == r.out.size() - 1);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  CHECK(j.at("max_diff_srgb8") == 64);
  CHECK(j.at("pixels_over_1") == 1);
  const covrast::Image heat = covrast::read_png(dir / "heat.png");
  CHECK(heat.width == 9);
  CHECK(heat.height == 7);

  // Size mismatch and unreadable input are bad input.
  covrast::write_png(test_image(8, 7, 1), dir / "small.png");
  r = run_cli(dir, {"compare", pa, (dir / "small.png").string()});
  CHECK(r.exit_code == 2);
  check_one_error_line(r);
  r = run_cli(dir, {"compare", pa, (dir / "missing.png").string()});
  CHECK(r.exit_code == 2);
  check_one_error_line(r);
  CHECK(r.err.find("missing.png") != std::string::npos);
}
