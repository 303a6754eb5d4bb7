// The covrast command line: one function pair per subcommand (options registration, run)
// plus the helpers they share. Uses only the public headers in include/covrast/.
#pragma once

#include <covrast/error.hpp>
#include <covrast/scene.hpp>

#include <CLI/CLI.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace covrast::cli {

/// The program version: project(covrast VERSION ...) in CMakeLists.txt, passed in by the
/// build as COVRAST_VERSION.
inline constexpr const char* kVersion = COVRAST_VERSION;

/// The viewer options (src/cli/view_options.cpp): empty or unset leaves the scene's value.
struct ViewArgs {
  std::string environment;  ///< a file, or "studio"
  double environment_rotation_deg = 0.0;
  double environment_intensity = 1.0;
  std::string orbit;   ///< "THETA,PHI,RADIUS"
  std::string target;  ///< "X,Y,Z"
  std::optional<double> fov_deg;
  std::string tone_map;
  std::optional<double> exposure;
  bool transparent = false;      ///< BackgroundKind::Transparent
  bool skybox = false;           ///< BackgroundKind::Skybox
  std::optional<double> time_s;  ///< --time: pose glTF files at this moment
  std::string animation;         ///< --animation INDEX|NAME
  std::string variant;           ///< --variant NAME (KHR_materials_variants)
};

struct RenderArgs {
  std::string scene;
  std::string output;
  std::string mode = "coverage";
  std::string size;  ///< "WxH"; empty: the scene's size
  int threads = 0;
  int tile = 64;
  std::string depth;  ///< empty: no depth output
  bool stats = false;
  int repeat = 1;
  bool strict = false;
  bool quiet = false;
  bool no_cull = false;  ///< keep hidden back faces (RenderOptions::cull_hidden_backfaces)
  ViewArgs view;
};

struct ScenarioArgs {
  std::string scenario;  ///< the harness's JSON, or a file holding it
  std::string mode = "coverage";
  int threads = 0;
  std::string tone_map = "khronos-pbr-neutral";
  bool strict = false;
  bool quiet = false;
};

struct InfoArgs {
  std::string scene;
  bool json = false;
  bool validate = false;  ///< --validate: list every finding instead of describing the scene
  bool strict = false;    ///< --strict (with --validate): warnings make the exit status 2
  ViewArgs view;
};

struct CompareArgs {
  std::string image_a;
  std::string image_b;
  std::string heatmap;  ///< empty: no heat map
  bool json = false;
  std::optional<double> max_rmse;
  std::optional<int> max_diff;
  std::optional<double> max_pixels;
};

struct TestArgs {
  std::string manifest;
  std::string junit;      ///< empty: no JUnit XML
  std::string report;     ///< empty: no HTML report
  std::string artifacts;  ///< empty: no artifact images
  bool json = false;
  bool update = false;
  bool all = false;
  std::string shard;  ///< "I/N", empty: everything
  int shard_index = 1, shard_count = 1;
  std::string filter;  ///< glob on case names, empty: all
  int threads = 0;
  bool strict = false;
  bool quiet = false;
};

/// The error of `--strict` on a scene with warnings: one line, printed first like every error;
/// main() prints the warnings after it, one `warning: ...` line each.
class StrictWarningsError : public InputError {
 public:
  StrictWarningsError(const std::string& message, std::vector<std::string> warnings)
      : InputError(message), warnings_(std::move(warnings)) {}
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  std::vector<std::string> warnings_;
};

CLI::App* add_render_command(CLI::App& app, RenderArgs& args);
CLI::App* add_info_command(CLI::App& app, InfoArgs& args);
CLI::App* add_compare_command(CLI::App& app, CompareArgs& args);
CLI::App* add_test_command(CLI::App& app, TestArgs& args);

/// Each returns the process exit code; InputError and other exceptions propagate to main.
int run_render(const RenderArgs& args);
int run_info(const InfoArgs& args);
CLI::App* add_scenario_command(CLI::App& app, ScenarioArgs& args);
int run_scenario(const ScenarioArgs& args);
int run_compare(const CompareArgs& args);
int run_test(TestArgs args);

/// Adds the viewer options to a subcommand.
void add_view_options(CLI::App* sub, ViewArgs& args);
/// Applies them to a loaded scene (environment files are read here); throws InputError
/// naming the option for bad values.
void apply_view_args(Scene& scene, const ViewArgs& args);

/// The warnings of a loaded scene: with `strict`, throws StrictWarningsError naming `what`
/// and the first warning (main prints all of them after that one error line); otherwise
/// prints each to stderr as "warning: ...".
void report_scene_warnings(const std::string& what, const std::vector<std::string>& warnings,
                           bool strict);

/// What `view`'s --variant, --time and --animation choose (SceneChoices); InputError for a
/// --time that is not a finite number of seconds >= 0.
SceneChoices scene_choices(const ViewArgs& view);

/// The scene a command's SCENE argument names: a scene JSON file, or a mesh file (.obj, .gltf,
/// .glb, any case) framed and lit without a scene file (load_mesh_scene), at `width` x
/// `height` when given (> 0), else 640x360.
/// `view`'s --time and --animation pose glTF files (AnimationTime), in a scene file in the
/// place of its "animation" and "time" keys.
Scene load_scene_or_model(const std::string& path, const ViewArgs& view, int width = 0,
                          int height = 0);

/// Throws InputError unless `path` could be created or replaced: its directory exists, is a
/// directory and is writable, the path is not a directory, and its extension (lower case) is
/// one of `extensions`. Run before any expensive work, so a bad output path fails fast.
void check_output_path(const std::filesystem::path& path,
                       const std::vector<std::string_view>& extensions);

/// Parses an image size "WxH" (decimal, each side 1..kMaxImageSide). Throws InputError.
std::pair<int, int> parse_size(const std::string& text);

/// Parses a shard "I/N" (1 <= I <= N <= 10000). Throws InputError.
std::pair<int, int> parse_shard(const std::string& text);

/// A case or scene name as a file name: letters, digits, '-', '_' and '.' kept, anything
/// else '_' (never empty, never "." or "..").
std::string safe_file_name(const std::string& name);

/// Writes a text file atomically (a temporary file beside it, then rename). Throws InputError.
void write_text_file(const std::filesystem::path& path, const std::string& text);

/// Compact decimal form of a double for human-readable output ("%.6g"; "inf" for infinity).
std::string format_number(double value);

}  // namespace covrast::cli
