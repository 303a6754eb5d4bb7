// Whole-frame benchmarks: a covrast::Renderer is built once per benchmark and only
// render_frame() is timed (setup, binning, raster, resolve; no loading, no PNG encoding),
// after one untimed warm-up frame.
//
//   frame/<scene>/<mode>                    bundled scenes at their own size, all threads
//   frame/<scene>/<mode>/threads:<n>        thread scaling on sphere_grid
//   frame/model:<file>/<mode>               every OBJ in ../shared/models, framed by its box
//
// Modes that this build cannot construct yet (msaa, ssaa while they are being written) are
// not registered. Counters: triangles/s and pixels/s per frame, plus samples/s for the
// sample-based modes (N^2 per pixel for ssaa:N, K per pixel for msaa:K).
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;

const fs::path kSceneDir = fs::path(COVRAST_SOURCE_DIR) / "scenes";
const fs::path kModelDir = fs::path(COVRAST_SOURCE_DIR) / ".." / "shared" / "models";

/// Scenes are loaded on first use, so that a filtered run loads only what it needs.
/// `make` builds the scene; the cache keeps it alive for every benchmark that uses it.
const covrast::Scene& cached_scene(const std::string& key,
                                   const std::function<covrast::Scene()>& make) {
  static std::map<std::string, std::unique_ptr<covrast::Scene>> cache;
  auto it = cache.find(key);
  if (it == cache.end()) {
    it = cache.emplace(key, std::make_unique<covrast::Scene>(make())).first;
  }
  return *it->second;
}

/// Samples per pixel of a mode, for the samples/s counter (0: not a sample-based mode).
int samples_per_pixel(const covrast::RenderMode& mode) {
  switch (mode.kind) {
    case covrast::ModeKind::Ssaa:
    case covrast::ModeKind::SsaaGrid:
    case covrast::ModeKind::SsaaCmj:
      return mode.samples * mode.samples;
    case covrast::ModeKind::Msaa:
      return mode.samples;
    default:
      return 0;
  }
}

/// Can this build render `mode`? Builds a Renderer for an empty 8x8 scene.
bool mode_available(const covrast::RenderMode& mode) {
  covrast::Scene empty;
  empty.width = 8;
  empty.height = 8;
  covrast::RenderOptions options;
  options.mode = mode;
  options.threads = 1;
  try {
    covrast::Renderer renderer(empty, options);
  } catch (const std::exception&) {
    return false;
  }
  return true;
}

void run_frames(benchmark::State& state, const covrast::Scene& scene,
                const covrast::RenderOptions& options) {
  std::unique_ptr<covrast::Renderer> renderer;
  try {
    renderer = std::make_unique<covrast::Renderer>(scene, options);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  // One untimed frame first: it sizes the per-frame buffers the Renderer keeps, so that the
  // timed frames measure the steady state even when only one iteration runs.
  std::size_t pixels = renderer->render_frame().color.rgb.size() / 3;
  for (auto _ : state) {
    covrast::RenderResult result = renderer->render_frame();
    pixels = result.color.rgb.size() / 3;
    benchmark::DoNotOptimize(result.color.rgb.data());
  }
  const double frames = double(state.iterations());
  state.counters["triangles/s"] =
      benchmark::Counter(frames * double(scene.triangle_count()), benchmark::Counter::kIsRate);
  state.counters["pixels/s"] =
      benchmark::Counter(frames * double(pixels), benchmark::Counter::kIsRate);
  if (int spp = samples_per_pixel(options.mode); spp > 0) {
    state.counters["samples/s"] =
        benchmark::Counter(frames * double(pixels) * spp, benchmark::Counter::kIsRate);
  }
}

/// A scene showing one mesh: camera on +z looking at the centre of its bounding box, far
/// enough for the bounding sphere to fit the vertical field of view.
covrast::Scene framed_model_scene(const fs::path& path) {
  covrast::Scene scene;
  scene.width = 1920;
  scene.height = 1080;
  scene.background_linear = glm::vec3(0.02f);
  std::shared_ptr<covrast::MeshData> mesh = covrast::load_mesh(path);
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const glm::vec3& p : mesh->positions) {
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
  }
  const glm::dvec3 centre = 0.5 * (lo + hi);
  const double radius = std::max(0.5 * glm::length(hi - lo), 1e-6);
  const double half_fovy = glm::radians(scene.camera.fovy_deg) / 2;
  const double distance = 1.05 * radius / std::sin(half_fovy);
  scene.camera.target = centre;
  scene.camera.eye = centre + glm::dvec3(0.0, 0.0, distance);
  scene.camera.near = std::max(distance - 1.5 * radius, 1e-3 * distance);
  scene.camera.far = distance + 1.5 * radius;
  covrast::MeshInstance instance;
  instance.mesh = std::move(mesh);
  instance.color_source = covrast::ColorSource::PerTriangle;
  scene.meshes.push_back(std::move(instance));
  return scene;
}

void register_frame(const std::string& name, std::function<covrast::Scene()> make,
                    const std::string& key, covrast::RenderOptions options) {
  benchmark::RegisterBenchmark(name.c_str(),
                               [key, make, options](benchmark::State& state) {
                                 const covrast::Scene* scene = nullptr;
                                 try {
                                   scene = &cached_scene(key, make);
                                 } catch (const std::exception& e) {
                                   state.SkipWithError(e.what());
                                   return;
                                 }
                                 run_frames(state, *scene, options);
                               })
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
}

void register_all() {
  std::vector<covrast::RenderMode> modes;
  for (const char* text : {"aliased", "coverage", "coverage-blend", "msaa:4", "msaa:8", "msaa:16",
                           "ssaa:2", "ssaa:4", "ssaa:8", "ssaa:16"}) {
    covrast::RenderMode mode = covrast::parse_render_mode(text);
    if (mode_available(mode)) {
      modes.push_back(mode);
    } else {
      std::fprintf(stderr, "bench_frame: mode %s is not available in this build, skipped\n", text);
    }
  }

  for (const char* name : {"sphere_grid", "overlap", "slivers"}) {
    const fs::path path = kSceneDir / (std::string(name) + ".json");
    auto make = [path] { return covrast::load_scene(path); };
    for (const covrast::RenderMode& mode : modes) {
      covrast::RenderOptions options;
      options.mode = mode;
      register_frame("frame/" + std::string(name) + "/" + covrast::to_string(mode), make,
                     path.string(), options);
    }
  }

  // Thread scaling on the geometry-bound scene.
  const fs::path grid = kSceneDir / "sphere_grid.json";
  const int hardware = int(std::max(1u, std::thread::hardware_concurrency()));
  for (const char* text : {"aliased", "coverage"}) {
    for (int threads = 1; threads <= hardware; ++threads) {
      covrast::RenderOptions options;
      options.mode = covrast::parse_render_mode(text);
      options.threads = threads;
      register_frame(
          "frame/sphere_grid/" + std::string(text) + "/threads:" + std::to_string(threads),
          [grid] { return covrast::load_scene(grid); }, grid.string(), options);
    }
  }

  // Sample models, when present.
  std::vector<fs::path> models;
  std::error_code ec;
  if (fs::is_directory(kModelDir, ec)) {
    for (const auto& entry : fs::directory_iterator(kModelDir, ec)) {
      if (entry.path().extension() == ".obj") models.push_back(entry.path());
    }
  }
  std::sort(models.begin(), models.end());
  if (models.empty()) {
    benchmark::RegisterBenchmark("frame/model:none", [](benchmark::State& state) {
      state.SkipWithError("no OBJ models: ../shared/models not found or empty");
    });
  }
  for (const fs::path& model : models) {
    for (const char* text : {"aliased", "coverage", "coverage-blend"}) {
      covrast::RenderOptions options;
      options.mode = covrast::parse_render_mode(text);
      register_frame(
          "frame/model:" + model.filename().string() + "/" + text,
          [model] { return framed_model_scene(model); }, model.string(), options);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  register_all();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
