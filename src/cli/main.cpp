// covrast command-line entry point: parses the command line with CLI11, dispatches to the
// subcommand, and maps failures to exit codes and one-line messages:
//   0 success; 1 internal error (or a compare threshold exceeded); 2 bad input or usage.
// Every error is exactly one line on stderr starting with "covrast: error: ".
#include "commands.hpp"

#include <covrast/error.hpp>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <iostream>
#include <string>

namespace {

/// Error messages must be one line: fold any embedded line breaks into spaces.
std::string one_line(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

void print_error(const std::string& message) {
  std::cout.flush();
  std::cerr << "covrast: error: " << one_line(message) << '\n';
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "covrast: a tiled, multithreaded CPU software rasterizer with exact analytic "
      "anti-aliasing. Renders JSON scenes of OBJ/glTF meshes to PNG, inspects scenes, "
      "compares images and runs golden-image test manifests.",
      "covrast"};
  app.set_version_flag("--version", std::string("covrast ") + covrast::cli::kVersion,
                       "Print the version and exit");
  app.require_subcommand(1);
  app.footer(
      "Exit codes: 0 success, 1 internal error, compare threshold exceeded or test failed, 2 bad "
      "input or "
      "usage.\nRun 'covrast SUBCOMMAND --help' for the options of a subcommand.");

  covrast::cli::RenderArgs render_args;
  covrast::cli::InfoArgs info_args;
  covrast::cli::CompareArgs compare_args;
  covrast::cli::TestArgs test_args;
  covrast::cli::ScenarioArgs scenario_args;
  CLI::App* render = covrast::cli::add_render_command(app, render_args);
  CLI::App* info = covrast::cli::add_info_command(app, info_args);
  CLI::App* compare = covrast::cli::add_compare_command(app, compare_args);
  CLI::App* test = covrast::cli::add_test_command(app, test_args);
  CLI::App* scenario = covrast::cli::add_scenario_command(app, scenario_args);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // CLI11 reports an unknown command word only as "A subcommand is required".
    const std::string first = argc > 1 ? argv[1] : "";
    if (!first.empty() && first[0] != '-' && first != "render" && first != "info" &&
        first != "compare" && first != "test") {
      print_error("unknown command '" + first +
                  "' (expected render, info, compare or test; run 'covrast --help' for usage)");
      return 2;
    }
    print_error(std::string(e.what()) + " (run 'covrast --help' for usage)");
    return 2;
  }

  try {
    if (render->parsed()) return covrast::cli::run_render(render_args);
    if (info->parsed()) return covrast::cli::run_info(info_args);
    if (compare->parsed()) return covrast::cli::run_compare(compare_args);
    if (test->parsed()) return covrast::cli::run_test(test_args);
    if (scenario->parsed()) return covrast::cli::run_scenario(scenario_args);
    print_error("no subcommand given (run 'covrast --help' for usage)");
    return 2;
  } catch (const covrast::cli::StrictWarningsError& e) {
    print_error(e.what());  // the error line first, then the warnings it is about
    for (const std::string& warning : e.warnings()) std::cerr << "warning: " << warning << '\n';
    return 2;
  } catch (const covrast::InputError& e) {
    print_error(e.what());
    return 2;
  } catch (const std::exception& e) {
    print_error(std::string("internal error: ") + e.what());
    return 1;
  } catch (...) {
    print_error("internal error: unknown exception");
    return 1;
  }
}
