// `covrast compare`: compares two PNGs (RMSE in linear light, PSNR, largest 8-bit difference,
// shares of differing pixels), optionally writes a difference heat map, and checks optional
// thresholds for golden-image tests: exit 0 when all hold, 1 when any is exceeded.
// One vocabulary with `covrast test` and its manifests: the three measures are `rmse`,
// `diff` (largest channel difference) and `pixels` (share of pixels off by more than 1/255),
// and `--max-X` (a manifest's tolerance `max_X`) bounds measure X.
#include "commands.hpp"

#include <covrast/compare.hpp>
#include <covrast/error.hpp>
#include <covrast/image.hpp>
#include <covrast/tools.hpp>

#include <iostream>
#include <string>
#include <vector>

namespace covrast::cli {

CLI::App* add_compare_command(CLI::App& app, CompareArgs& args) {
  CLI::App* sub = app.add_subcommand(
      "compare",
      "Compare two PNG images of the same size: RMSE (linear light), PSNR, largest channel "
      "difference (8-bit sRGB) and the shares of pixels off by more than 1/255 and 8/255. "
      "With thresholds, prints 'FAIL: <measure> <value> > <limit>' to stderr for each one "
      "exceeded (measures rmse, diff, pixels: what --max-rmse, --max-diff and --max-pixels "
      "bound) and exits 1; exits 0 when all hold.");
  sub->add_option("A", args.image_a, "First image (PNG)")->required()->type_name("PNG");
  sub->add_option("B", args.image_b, "Second image (PNG)")->required()->type_name("PNG");
  sub->add_option("--heatmap", args.heatmap,
                  "Write a heat map of the per-pixel difference (black = equal .. red >= 32/255)")
      ->type_name("OUT.png");
  sub->add_flag("--json", args.json, "Print one JSON line instead of text");
  sub->add_option("--max-rmse", args.max_rmse, "Fail if the linear-light RMSE exceeds X")
      ->check(CLI::NonNegativeNumber)
      ->type_name("X");
  sub->add_option("--max-diff", args.max_diff,
                  "Fail if any channel differs by more than N (8-bit sRGB units, 0..255)")
      ->check(CLI::Range(0, 255))
      ->type_name("N");
  sub->add_option("--max-pixels", args.max_pixels,
                  "Fail if more than this share (0..1) of pixels is off by more than 1/255")
      ->check(CLI::Range(0.0, 1.0))
      ->type_name("FRACTION");
  return sub;
}

int run_compare(const CompareArgs& args) {
  if (!args.heatmap.empty()) check_output_path(args.heatmap, {".png"});
  const Image a = read_png(args.image_a);
  const Image b = read_png(args.image_b);
  if (a.width != b.width || a.height != b.height) {
    throw InputError(args.image_a + " is " + std::to_string(a.width) + "x" +
                     std::to_string(a.height) + " but " + args.image_b + " is " +
                     std::to_string(b.width) + "x" + std::to_string(b.height) +
                     ": compare needs images of the same size");
  }
  const CompareResult result = compare_images(a, b);

  if (args.json) {
    std::cout << to_json(result) << '\n';
  } else {
    const double pixels = double(result.width) * double(result.height);
    const auto percent = [&](std::size_t count) {
      return format_number(pixels > 0 ? 100.0 * double(count) / pixels : 0.0) + "%";
    };
    std::cout << "size:        " << result.width << "x" << result.height << '\n'
              << "rmse:        " << format_number(result.rmse_linear) << " (linear)\n"
              << "psnr:        " << format_number(result.psnr_db) << " dB\n"
              << "diff:        " << result.max_diff_srgb8 << "/255 (largest channel difference)\n"
              << "pixels:      " << percent(result.pixels_over_1) << " off by more than 1/255 ("
              << result.pixels_over_1 << ")\n"
              << "             " << percent(result.pixels_over_8) << " off by more than 8/255 ("
              << result.pixels_over_8 << ")\n";
  }

  if (!args.heatmap.empty()) {
    write_png(difference_heatmap(a, b), args.heatmap);
    if (!args.json) std::cout << "wrote " << args.heatmap << '\n';
  }
  std::cout.flush();

  std::vector<std::string> failures;
  if (args.max_rmse && result.rmse_linear > *args.max_rmse) {
    failures.push_back("rmse " + format_number(result.rmse_linear) + " > " +
                       format_number(*args.max_rmse));
  }
  if (args.max_diff && result.max_diff_srgb8 > *args.max_diff) {
    failures.push_back("diff " + std::to_string(result.max_diff_srgb8) + " > " +
                       std::to_string(*args.max_diff));
  }
  if (args.max_pixels && result.share_over_1 > *args.max_pixels) {
    failures.push_back("pixels " + format_number(result.share_over_1) + " > " +
                       format_number(*args.max_pixels));
  }
  for (const std::string& failure : failures) std::cerr << "FAIL: " << failure << '\n';
  return failures.empty() ? 0 : 1;
}

}  // namespace covrast::cli
