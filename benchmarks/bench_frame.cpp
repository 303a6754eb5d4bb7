// Whole-frame benchmarks: a covrast::Renderer is built once per benchmark and only
// render_frame() is timed (setup, binning, raster, resolve; no loading, no PNG encoding),
// after one untimed warm-up frame.
//
//   frame/<scene>/<mode>                    bundled scenes at their own size, all threads
//   frame/<scene>/<mode>/threads:<n>        thread scaling on sphere_grid
//   frame/real:<name>/<mode>                the scenes `covrast-scenegen --real DIR` writes
//   frame/model:<name>/<mode>               the sample models of ../shared/models, framed by
//                                           their box: every OBJ (<name> = file stem) and every
//                                           glTF model folder gltf/<name>/
//
// Options besides Google Benchmark's (which come first, e.g. --benchmark_filter=model:Duck):
//   --size=WxH        frame size of the real and model scenes (default: real scenes their
//                     own size, models 1920x1080)
//   --scenegen=PATH   the covrast-scenegen to ask for the real scenes (default: the one built
//                     with this executable)
// The real scenes are written into a temporary directory at start-up when the generator
// supports --real (exit status 0 and at least one JSON file); otherwise they are skipped with
// a note on stderr. Models that fail to load or have no triangles report an error.
//
// Modes that this build cannot construct yet (msaa, ssaa while they are being written) are
// not registered. Counters: triangles/s and pixels/s per frame, plus samples/s for the
// sample-based modes (N^2 per pixel for ssaa:N, K per pixel for msaa:K).
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <sys/wait.h>

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

/// Frame size of the real and model scenes when given (--size=WxH).
struct ContentSize {
  int width = 0;
  int height = 0;
};

/// A scene showing one mesh with per-triangle colours: camera on +z looking at the centre of
/// the bounding box of the vertices its triangles use, far enough for the bounding sphere to
/// fit the vertical field of view (the same framing as benchmarks/report.py).
covrast::Scene framed_model_scene(const fs::path& path, ContentSize size) {
  covrast::Scene scene;
  scene.width = size.width > 0 ? size.width : 1920;
  scene.height = size.height > 0 ? size.height : 1080;
  scene.background_linear = glm::vec3(0.02f);
  std::shared_ptr<covrast::MeshData> mesh = covrast::load_mesh(path);
  if (mesh->triangle_count() == 0) throw std::runtime_error(path.string() + ": no triangles");
  const glm::dvec3 lo(mesh->bounds_min), hi(mesh->bounds_max);
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

/// A scene file, at `size` when one is given.
covrast::Scene sized_scene(const fs::path& path, ContentSize size) {
  covrast::Scene scene = covrast::load_scene(path);
  if (size.width > 0) {
    scene.width = size.width;
    scene.height = size.height;
  }
  return scene;
}

/// A sample model: its benchmark name and mesh file.
struct Model {
  std::string name;
  fs::path file;
};

/// The name with every character other than a letter, digit, '_', '.' or '-' replaced by
/// '_' (as report.py does: "Box With Spaces" -> "Box_With_Spaces").
std::string safe_name(const std::string& text) {
  std::string out;
  for (char c : text) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '_' || c == '.' || c == '-';
    if (keep) {
      out += c;
    } else if (out.empty() || out.back() != '_') {
      out += '_';
    }
  }
  return out;
}

/// The files of `dir` with extension `ext`, sorted; empty when `dir` is not a directory.
std::vector<fs::path> files_with_extension(const fs::path& dir, const std::string& ext) {
  std::vector<fs::path> files;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return files;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ext) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// The sample models in `dir`: every OBJ file, then one file per folder of dir/gltf, the first
/// of glTF-Binary/*.glb, glTF/*.gltf, glTF-Embedded/*.gltf, glTF-Quantized/*.gltf (as
/// benchmarks/report.py picks them; Draco files are never used).
std::vector<Model> find_models(const fs::path& dir) {
  std::vector<Model> models;
  for (const fs::path& obj : files_with_extension(dir, ".obj")) {
    models.push_back({safe_name(obj.stem().string()), obj});
  }
  std::vector<fs::path> folders;
  std::error_code ec;
  if (fs::is_directory(dir / "gltf", ec)) {
    for (const auto& entry : fs::directory_iterator(dir / "gltf", ec)) {
      if (entry.is_directory(ec)) folders.push_back(entry.path());
    }
  }
  std::sort(folders.begin(), folders.end());
  const std::pair<const char*, const char*> variants[] = {{"glTF-Binary", ".glb"},
                                                          {"glTF", ".gltf"},
                                                          {"glTF-Embedded", ".gltf"},
                                                          {"glTF-Quantized", ".gltf"}};
  for (const fs::path& folder : folders) {
    std::string name = safe_name(folder.filename().string());
    if (std::any_of(models.begin(), models.end(),
                    [&name](const Model& m) { return m.name == name; })) {
      name += "_gltf";  // an OBJ model of the same name came first
    }
    std::optional<fs::path> file;
    for (const auto& [variant, ext] : variants) {
      const std::vector<fs::path> files = files_with_extension(folder / variant, ext);
      if (!files.empty()) {
        file = files.front();
        break;
      }
    }
    if (file) {
      models.push_back({name, *file});
    } else {
      std::fprintf(stderr, "bench_frame: model %s: no glTF-Binary/*.glb or glTF/*.gltf, skipped\n",
                   name.c_str());
    }
  }
  return models;
}

/// A fresh directory under the system temp directory, removed with everything in it on
/// destruction.
class TempDir {
 public:
  TempDir() {
    const auto ticks = std::chrono::steady_clock::now().time_since_epoch().count();
    path_ = fs::temp_directory_path() / ("covrast_bench_frame_" + std::to_string(ticks));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// Runs `scenegen --real dir`; returns the JSON files it wrote (sorted), or nothing with a note
/// on stderr when the generator lacks the option (non-zero exit status or no JSON written).
std::vector<fs::path> generate_real_scenes(const std::string& scenegen, const fs::path& dir) {
  const std::string command =
      "\"" + scenegen + "\" --real \"" + dir.string() + "\" >/dev/null 2>&1";
  const int status = std::system(command.c_str());
  const int exit_status = status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::vector<fs::path> scenes = files_with_extension(dir, ".json");
  if (exit_status != 0 || scenes.empty()) {
    std::fprintf(stderr,
                 "bench_frame: %s --real is not supported (exit status %d, %zu JSON files): the "
                 "frame/real:* scenes are skipped\n",
                 scenegen.c_str(), exit_status, scenes.size());
    return {};
  }
  return scenes;
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

void register_all(ContentSize size, const std::string& scenegen, const fs::path& real_dir) {
  std::vector<covrast::RenderMode> modes;
  for (const char* text : {"aliased", "fxaa", "coverage", "coverage-blend", "msaa:4", "msaa:8",
                           "msaa:16", "ssaa:2", "ssaa:4", "ssaa:8", "ssaa:16"}) {
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

  // Generated real-content scenes, when the generator has --real.
  const std::vector<covrast::RenderMode> content_modes = [&modes] {
    std::vector<covrast::RenderMode> picked;
    for (const covrast::RenderMode& mode : modes) {
      const std::string text = covrast::to_string(mode);
      if (text == "aliased" || text == "fxaa" || text == "coverage" || text == "coverage-blend" ||
          text == "msaa:4") {
        picked.push_back(mode);
      }
    }
    return picked;
  }();
  const std::vector<fs::path> real = generate_real_scenes(scenegen, real_dir);
  if (real.empty()) {
    benchmark::RegisterBenchmark("frame/real:none", [](benchmark::State& state) {
      state.SkipWithError("covrast-scenegen --real is not supported by this build");
    });
  }
  for (const fs::path& scene : real) {
    for (const covrast::RenderMode& mode : content_modes) {
      covrast::RenderOptions options;
      options.mode = mode;
      register_frame(
          "frame/real:" + safe_name(scene.stem().string()) + "/" + covrast::to_string(mode),
          [scene, size] { return sized_scene(scene, size); }, scene.string(), options);
    }
  }

  // Sample models, when present.
  const std::vector<Model> models = find_models(kModelDir);
  if (models.empty()) {
    benchmark::RegisterBenchmark("frame/model:none", [](benchmark::State& state) {
      state.SkipWithError("no sample models: ../shared/models not found or empty");
    });
  }
  for (const Model& model : models) {
    for (const covrast::RenderMode& mode : content_modes) {
      covrast::RenderOptions options;
      options.mode = mode;
      const fs::path file = model.file;
      register_frame(
          "frame/model:" + model.name + "/" + covrast::to_string(mode),
          [file, size] { return framed_model_scene(file, size); }, file.string(), options);
    }
  }
}

/// Takes this program's own options (--size=WxH, --scenegen=PATH) out of argv; returns false
/// with a message on stderr for a malformed one.
bool take_own_options(int& argc, char** argv, ContentSize& size, std::string& scenegen) {
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    const char* arg = argv[i];
    if (std::strncmp(arg, "--size=", 7) == 0) {
      int w = 0, h = 0;
      char tail = 0;
      if (std::sscanf(arg + 7, "%dx%d%c", &w, &h, &tail) != 2 || w < 1 || h < 1 || w > 16384 ||
          h > 16384) {
        std::fprintf(stderr, "bench_frame: --size: expected WxH (1..16384), got '%s'\n", arg + 7);
        return false;
      }
      size = {w, h};
    } else if (std::strncmp(arg, "--scenegen=", 11) == 0) {
      scenegen = arg + 11;
    } else {
      argv[kept++] = argv[i];
    }
  }
  argc = kept;
  argv[argc] = nullptr;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  ContentSize size;
  std::string scenegen = COVRAST_SCENEGEN_PATH;
  if (!take_own_options(argc, argv, size, scenegen)) return 1;
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  // The real scenes are loaded when their first benchmark runs, so the directory they are
  // written into lives until every benchmark has run.
  const TempDir real_dir;
  register_all(size, scenegen, real_dir.path());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
