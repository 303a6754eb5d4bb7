// Benchmarks of the CI workflow (docs/ci.md): what a golden-image job pays besides rendering.
//
//   ci/encode_png/<W>x<H>      encode_png of a rendered frame of scenes/default.json (the PNG
//                              encoder: what --update and every `covrast render` pay)
//   ci/read_png/<W>x<H>        read_png of that file (what `covrast test` pays per golden)
//   ci/compare/<W>x<H>         compare_images against itself
//   ci/manifest/200            one `covrast test` process over a 200-case manifest (the bundled
//                              scenes x 5 modes x 6 sizes from 96x54 to 480x270; all pass)
//   ci/processes/200           200 `covrast render` processes, one per case of that manifest
//                              (without the 200 `covrast compare` processes a script would add)
// The manifest and its goldens are written into a temporary directory at start-up (with
// `covrast test --update`, untimed). The process benchmarks time whole processes, so they run
// a few iterations only; quote their medians.
#include <covrast/compare.hpp>
#include <covrast/image.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <unistd.h>

#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const char* const kScenes[] = {"boxes",   "default", "lit",          "near_plane",
                               "overlap", "slivers", "sphere_closed"};
const char* const kModes[] = {"coverage", "coverage-blend", "aliased", "msaa:4", "ssaa:2"};
const int kSizes[][2] = {{96, 54}, {160, 90}, {240, 135}, {320, 180}, {400, 225}, {480, 270}};
constexpr int kCases = 200;

struct Case {
  std::string name, scene, mode, size;
};

std::vector<Case> manifest_cases() {
  std::vector<Case> cases;
  for (const auto& size : kSizes) {
    for (const char* scene : kScenes) {
      for (const char* mode : kModes) {
        if (int(cases.size()) == kCases) return cases;
        const std::string wxh = std::to_string(size[0]) + "x" + std::to_string(size[1]);
        std::string name = std::string(scene) + "-" + mode + "-" + wxh;
        for (char& c : name) c = c == ':' ? '_' : c;
        cases.push_back(
            {name, std::string(COVRAST_SOURCE_DIR) + "/scenes/" + scene + ".json", mode, wxh});
      }
    }
  }
  return cases;
}

/// A temporary folder with the manifest and its goldens.
class Workspace {
 public:
  Workspace() {
    dir_ = fs::temp_directory_path() / ("covrast-bench-ci-" + std::to_string(::getpid()));
    fs::create_directories(dir_ / "goldens");
    std::ofstream m(dir_ / "manifest.json");
    m << "{\"cases\": [\n";
    const std::vector<Case> cases = manifest_cases();
    for (std::size_t i = 0; i < cases.size(); ++i) {
      const Case& c = cases[i];
      m << "  {\"name\": \"" << c.name << "\", \"scene\": \"" << c.scene << "\", \"golden\": "
        << "\"goldens/" << c.name << ".png\", \"mode\": \"" << c.mode << "\", \"size\": \""
        << c.size << "\"}" << (i + 1 < cases.size() ? ",\n" : "\n");
    }
    m << "]}\n";
    m.close();
    run("test " + (dir_ / "manifest.json").string() + " --update --quiet");
  }
  ~Workspace() {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  const fs::path& dir() const { return dir_; }
  static void run(const std::string& args) {
    const std::string command = std::string(COVRAST_CLI_PATH) + " " + args + " >/dev/null";
    if (std::system(command.c_str()) != 0) throw std::runtime_error("failed: " + command);
  }

 private:
  fs::path dir_;
};

covrast::Image default_frame(int width, int height) {
  const covrast::Scene scene =
      covrast::load_scene(std::string(COVRAST_SOURCE_DIR) + "/scenes/default.json");
  covrast::RenderOptions options;
  options.width = width;
  options.height = height;
  return covrast::render(scene, options).color;
}

void register_image_benchmarks(int width, int height) {
  const std::string wxh = std::to_string(width) + "x" + std::to_string(height);
  benchmark::RegisterBenchmark(("ci/encode_png/" + wxh).c_str(), [=](benchmark::State& state) {
    const covrast::Image frame = default_frame(width, height);
    for (auto _ : state) benchmark::DoNotOptimize(covrast::encode_png(frame));
  });
  benchmark::RegisterBenchmark(("ci/read_png/" + wxh).c_str(), [=](benchmark::State& state) {
    const fs::path file = fs::temp_directory_path() /
                          ("covrast-bench-ci-" + std::to_string(::getpid()) + "-" + wxh + ".png");
    covrast::write_png(default_frame(width, height), file);
    for (auto _ : state) benchmark::DoNotOptimize(covrast::read_png(file));
    fs::remove(file);
  });
  benchmark::RegisterBenchmark(("ci/compare/" + wxh).c_str(), [=](benchmark::State& state) {
    const covrast::Image frame = default_frame(width, height);
    for (auto _ : state) benchmark::DoNotOptimize(covrast::compare_images(frame, frame));
  });
}

void register_process_benchmarks(const Workspace& w) {
  benchmark::RegisterBenchmark("ci/manifest/200",
                               [&w](benchmark::State& state) {
                                 const std::string args =
                                     "test " + (w.dir() / "manifest.json").string() + " --quiet";
                                 for (auto _ : state) Workspace::run(args);
                               })
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Iterations(3);
  benchmark::RegisterBenchmark("ci/processes/200",
                               [&w](benchmark::State& state) {
                                 const std::vector<Case> cases = manifest_cases();
                                 const std::string out = (w.dir() / "out.png").string();
                                 for (auto _ : state) {
                                   for (const Case& c : cases) {
                                     Workspace::run("render " + c.scene + " -o " + out +
                                                    " --mode " + c.mode + " --size " + c.size +
                                                    " --quiet");
                                   }
                                 }
                               })
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime()
      ->Iterations(3);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  for (const auto& size : {std::pair{320, 180}, std::pair{1920, 1080}}) {
    register_image_benchmarks(size.first, size.second);
  }
  const Workspace workspace;
  register_process_benchmarks(workspace);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
