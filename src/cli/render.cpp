// `covrast render`: loads a scene, renders it (optionally K times for timing), writes the PNG
// (and optionally depth) atomically and optionally prints one JSON line of statistics.
//
// Everything that can be checked before rendering is checked first (mode, size, tile, output
// paths, scene, --strict), so bad input fails fast with exit code 2 and creates no file.
#include "commands.hpp"

#include <covrast/error.hpp>
#include <covrast/image.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>
#include <covrast/tools.hpp>

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <filesystem>
#include <iostream>
#include <string>
#include <tuple>
#include <vector>

namespace covrast::cli {
namespace {

/// --repeat's bound: a timing aid, not a property of the renderer, so it is the CLI's own.
constexpr int kMaxRepeat = 1000;

/// Median of the per-frame values of one timing field; mean of the middle two for even K.
double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  if (n == 0) return 0.0;
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

nlohmann::ordered_json stats_json(const RenderOptions& options, const RenderResult& last,
                                  const std::vector<RenderStats>& frames) {
  const auto median_of = [&](double RenderStats::*field) {
    std::vector<double> values;
    values.reserve(frames.size());
    for (const RenderStats& s : frames) values.push_back(s.*field);
    return median(std::move(values));
  };
  const RenderStats& s = last.stats;
  nlohmann::ordered_json j;
  j["mode"] = to_string(options.mode);
  j["width"] = last.color.width;
  j["height"] = last.color.height;
  j["threads"] = s.threads;
  j["tile"] = s.tile;
  // The Highway target the kernels ran on (e.g. "AVX2", "NEON", "SVE2"), so that a check
  // across machines or emulated CPUs can tell which one it compared.
  j["simd"] = build_info().simd_target;
  j["triangles"] = {{"in", s.triangles_in},
                    {"culled", s.triangles_culled},
                    {"backface_culled", s.triangles_backface_culled},
                    {"clipped", s.triangles_clipped},
                    {"setup", s.triangles_setup},
                    {"bin_entries", s.bin_entries},
                    {"hidden_bin_entries", s.hidden_bin_entries}};
  j["fragment_overflows"] = s.fragment_overflows;
  // Pixels per A-buffer resolve path (coverage mode; docs/coverage.md), of the last frame.
  nlohmann::ordered_json& paths = j["resolve_paths"] = nlohmann::ordered_json::object();
  for (const auto& [name, field] : kCoverageResolvePathFields) paths[name] = s.resolve_paths.*field;
  j["scratch_bytes"] = s.scratch_bytes;
  j["setup_ms"] = median_of(&RenderStats::setup_ms);
  j["binning_ms"] = median_of(&RenderStats::binning_ms);
  j["raster_ms"] = median_of(&RenderStats::raster_ms);
  j["resolve_ms"] = median_of(&RenderStats::resolve_ms);
  j["post_ms"] = median_of(&RenderStats::post_ms);
  j["render_ms"] = median_of(&RenderStats::render_ms);
  j["frames"] = frames.size();
  return j;
}

}  // namespace

CLI::App* add_render_command(CLI::App& app, RenderArgs& args) {
  CLI::App* sub = app.add_subcommand(
      "render",
      "Render a JSON scene to a PNG (8-bit sRGB). The output is written atomically: on any "
      "error nothing is created and an existing file is left untouched.");
  sub->add_option("scene", args.scene,
                  "Scene file (JSON, see docs/scene-format.md), or a mesh file (.obj, .gltf, "
                  ".glb) to render framed and lit without a scene file")
      ->required()
      ->type_name("SCENE.json");
  sub->add_option("-o,--output", args.output, "Output PNG file")->required()->type_name("OUT.png");
  sub->add_option(
         "--mode", args.mode,
         "Anti-aliasing mode: coverage (exact analytic area, the default), coverage-blend, "
         "aliased, ssaa:N and ssaa-grid:N (N x N ordered grid, N = 1.." +
             std::to_string(kMaxSsaaSide) +
             "), ssaa-cmj:N (N x N correlated multi-jittered), msaa:K (K = 2, 4, 8, 16), "
             "reference (double-precision ground truth), fxaa (aliased, then the FXAA 3.11 "
             "post-process: quality preset 12, edge threshold 0.166, edge threshold min 0.0833, "
             "subpix 0.75; docs/fxaa.md)")
      ->capture_default_str()
      ->type_name("MODE");
  sub->add_option(
         "--size", args.size,
         "Image size, overriding the scene's (each side 1.." + std::to_string(kMaxImageSide) + ")")
      ->type_name("WxH");
  sub->add_option(
         "--threads", args.threads,
         "Worker threads; 0 = all hardware threads (at most " + std::to_string(kMaxThreads) + ")")
      ->check(CLI::Range(0, kMaxThreads))
      ->capture_default_str()
      ->type_name("N");
  sub->add_option("--tile", args.tile, "Tile side in pixels: " + tile_px_rule())
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            int value = 0;
            const auto [end, error] =
                std::from_chars(text.data(), text.data() + text.size(), value);
            if (error != std::errc() || end != text.data() + text.size() || !valid_tile_px(value)) {
              return "must be " + tile_px_rule() + ", got '" + text + "'";
            }
            return {};
          },
          std::to_string(kMinTilePx) + ".." + std::to_string(kMaxTilePx) + ", multiple of " +
              std::to_string(kTileStepPx)))
      ->capture_default_str()
      ->type_name("N");
  sub->add_option("--depth", args.depth,
                  "Also write window depth: .png = 16-bit greyscale (0 near .. 65535 far), "
                  ".pfm = little-endian float PFM")
      ->type_name("DEPTH.png|.pfm");
  sub->add_flag("--stats", args.stats,
                "Print one JSON line of statistics (counts, median stage times) to stdout");
  sub->add_option(
         "--repeat", args.repeat,
         "Render K frames and report the median frame time (1.." + std::to_string(kMaxRepeat) + ")")
      ->check(CLI::Range(1, kMaxRepeat))
      ->capture_default_str()
      ->type_name("K");
  add_view_options(sub, args.view);
  sub->add_flag("--strict", args.strict, "Treat scene warnings as errors (exit 2, no output)");
  sub->add_flag("-q,--quiet", args.quiet, "Do not print the 'wrote ...' lines");
  sub->add_flag("--no-cull", args.no_cull,
                "Keep the back faces of closed meshes (by default they are dropped where that "
                "provably cannot change the image); for debugging and measuring");
  return sub;
}

int run_render(const RenderArgs& args) {
  RenderOptions options;
  options.mode = parse_render_mode(args.mode);
  if (!args.size.empty()) {
    try {
      std::tie(options.width, options.height) = parse_size(args.size);
    } catch (const InputError& e) {
      throw InputError(std::string("--size: ") + e.what());
    }
  }
  options.threads = args.threads;
  options.tile = args.tile;
  options.want_depth = !args.depth.empty();
  options.cull_hidden_backfaces = !args.no_cull;

  check_output_path(args.output, {".png"});
  if (options.want_depth) check_output_path(args.depth, {".png", ".pfm"});

  Scene scene = load_scene_or_model(args.scene, args.view, options.width, options.height);
  apply_view_args(scene, args.view);
  report_scene_warnings(args.scene, scene.warnings, args.strict);

  Renderer renderer(scene, options);
  const bool show_progress = args.repeat > 1 && ::isatty(STDERR_FILENO) == 1;
  std::vector<RenderStats> frames;
  frames.reserve(std::size_t(args.repeat));
  RenderResult result;
  for (int frame = 0; frame < args.repeat; ++frame) {
    if (show_progress) std::cerr << "\rframe " << frame + 1 << "/" << args.repeat << std::flush;
    result = renderer.render_frame();
    frames.push_back(result.stats);
  }
  if (show_progress) std::cerr << "\r\033[K" << std::flush;

  write_png(result.color, args.output);
  if (!args.quiet) std::cout << "wrote " << args.output << '\n';
  if (options.want_depth) {
    write_depth(result.depth, args.depth);
    if (!args.quiet) std::cout << "wrote " << args.depth << '\n';
  }
  if (args.stats) std::cout << stats_json(options, result, frames).dump() << '\n';
  std::cout.flush();
  return 0;
}

}  // namespace covrast::cli
