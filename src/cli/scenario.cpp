// `covrast scenario ARG`: renders one scenario of google/model-viewer's render-fidelity harness
// (packages/render-fidelity-tools), which calls a command-line renderer as
// `EXECUTABLE ARGS... '{"scenario": {...}, "outputFile": "path.png"}'`. docs/environments.md,
// "Render-fidelity scenarios", has the mapping and the harness's config entry.
#include "commands.hpp"

#include <covrast/environment.hpp>
#include <covrast/error.hpp>
#include <covrast/image.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>

#include <nlohmann/json.hpp>

#include <fstream>
#include <iostream>
#include <iterator>
#include <string>

namespace covrast::cli {
namespace {

using json = nlohmann::json;

/// A scenario file is small; more than this is not one.
constexpr std::uintmax_t kMaxScenarioFileBytes = std::uintmax_t(1) << 20;

/// ARG as JSON text (it starts with '{') or as the path of a file holding it.
json read_scenario_argument(const std::string& arg) {
  const std::size_t first = arg.find_first_not_of(" \t\r\n");
  std::string text;
  std::string name = "scenario";
  if (first != std::string::npos && arg[first] == '{') {
    text = arg;
  } else {
    name = arg;
    std::error_code error;
    if (!std::filesystem::is_regular_file(arg, error)) {
      throw InputError(arg + ": cannot read scenario: not a regular file or missing");
    }
    if (std::filesystem::file_size(arg, error) > kMaxScenarioFileBytes) {
      throw InputError(arg + ": cannot read scenario: larger than 1 MiB");
    }
    std::ifstream in(arg, std::ios::binary);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  try {
    return json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(name + ": invalid JSON: " + e.what());
  }
}

/// The number at `object[key]`, or `fallback` when the key is absent.
double number_or(const json& object, const char* key, double fallback, const std::string& where) {
  const auto it = object.find(key);
  if (it == object.end()) return fallback;
  if (!it->is_number()) throw InputError("scenario: " + where + key + ": expected a number");
  return it->get<double>();
}

const json& object_or_empty(const json& object, const char* key) {
  static const json empty = json::object();
  const auto it = object.find(key);
  if (it == object.end()) return empty;
  if (!it->is_object()) throw InputError(std::string("scenario: ") + key + ": expected an object");
  return *it;
}

std::string string_at(const json& object, const char* key, const std::string& where) {
  const auto it = object.find(key);
  if (it == object.end() || !it->is_string() || it->get<std::string>().empty()) {
    throw InputError("scenario: " + where + key + ": expected a non-empty string");
  }
  return it->get<std::string>();
}

}  // namespace

CLI::App* add_scenario_command(CLI::App& app, ScenarioArgs& args) {
  CLI::App* sub = app.add_subcommand(
      "scenario",
      "Render a scenario of model-viewer's render-fidelity harness: ARG is "
      "'{\"scenario\": {...}, \"outputFile\": \"out.png\"}' or a file holding it. The image is "
      "2 x width by 2 x height (the harness's device pixel ratio), lit by the scenario's "
      "lighting (the built-in studio environment without one), tone-mapped with "
      "khronos-pbr-neutral, over a transparent background (RGBA) or, with renderSkybox, the "
      "environment (docs/environments.md)");
  sub->add_option("scenario", args.scenario, "The harness's JSON argument, or a file with it")
      ->required()
      ->type_name("ARG");
  sub->add_option("--mode", args.mode, "Raster mode (as covrast render)")->type_name("MODE");
  sub->add_option("--threads", args.threads, "Worker threads (0 = all cores)")->type_name("N");
  sub->add_option("--tone-map", args.tone_map, "Tone map (default khronos-pbr-neutral)")
      ->type_name("NAME");
  sub->add_flag("--strict", args.strict, "Treat warnings as errors (exit 2, no output)");
  sub->add_flag("-q,--quiet", args.quiet, "Do not print the 'wrote ...' line");
  return sub;
}

int run_scenario(const ScenarioArgs& args) {
  const json root = read_scenario_argument(args.scenario);
  if (!root.is_object()) throw InputError("scenario: expected a JSON object");
  const json& scenario = object_or_empty(root, "scenario");
  if (scenario.empty()) throw InputError("scenario: the key \"scenario\" is missing or empty");
  const std::string output = string_at(root, "outputFile", "");
  check_output_path(output, {".png"});

  // The harness's defaults (render-fidelity-tools, common.ts ScenarioConfig and its configs).
  const json& dimensions = object_or_empty(scenario, "dimensions");
  const double width = number_or(dimensions, "width", 768.0, "dimensions.");
  const double height = number_or(dimensions, "height", 768.0, "dimensions.");
  if (!(width >= 1.0 && height >= 1.0 && 2.0 * width <= kMaxImageSide &&
        2.0 * height <= kMaxImageSide && width == std::floor(width) &&
        height == std::floor(height))) {
    throw InputError("scenario: dimensions: expected whole numbers from 1 to " +
                     std::to_string(kMaxImageSide / 2));
  }
  RenderOptions options;
  options.mode = parse_render_mode(args.mode);
  options.threads = args.threads;

  Scene scene = load_mesh_scene(string_at(scenario, "model", ""), 2 * int(width), 2 * int(height));
  const json& target = object_or_empty(scenario, "target");
  const glm::dvec3 target_point(number_or(target, "x", 0.0, "target."),
                                number_or(target, "y", 0.0, "target."),
                                number_or(target, "z", 0.0, "target."));
  const json& orbit = object_or_empty(scenario, "orbit");
  const double theta = number_or(orbit, "theta", 0.0, "orbit.");
  const double phi = number_or(orbit, "phi", 90.0, "orbit.");
  const double radius = number_or(orbit, "radius", 1.0, "orbit.");
  if (!(radius > 0.0)) throw InputError("scenario: orbit.radius: expected a number > 0");
  const double fov = number_or(scenario, "verticalFoV", 45.0, "");
  if (!(fov > 0.0 && fov < 180.0)) throw InputError("scenario: verticalFoV: expected (0, 180)");
  scene.camera.fovy_deg = fov;
  place_orbit_camera(scene, target_point, theta, phi, radius);

  ViewArgs view;
  view.environment = "studio";
  if (const auto it = scenario.find("lighting"); it != scenario.end() && !it->is_null()) {
    view.environment = string_at(scenario, "lighting", "");
  }
  view.tone_map = args.tone_map;
  // renderSkybox (default false): the environment behind the model, else a transparent
  // background, which the harness's metric skips in the candidate.
  const auto skybox = scenario.find("renderSkybox");
  if (skybox != scenario.end() && !skybox->is_boolean() && !skybox->is_null()) {
    throw InputError("scenario: renderSkybox: expected true or false");
  }
  view.skybox = skybox != scenario.end() && *skybox == true;
  view.transparent = !view.skybox;
  apply_view_args(scene, view);
  report_scene_warnings("scenario", scene.warnings, args.strict);

  const RenderResult result = render(scene, options);
  write_png(result.color, output);
  if (!args.quiet) std::cout << "wrote " << output << '\n';
  return 0;
}

}  // namespace covrast::cli
