// `covrast test MANIFEST`: renders every case of a golden manifest (manifest.hpp) in one
// process, compares each with its golden image within the case's tolerance, and reports:
// text on stdout, optionally JUnit XML, a JSON summary, an HTML page and the failing cases'
// actual and difference images. --update blesses: it writes the goldens of failing and
// missing cases (or all of them), atomically, each recording what rendered it.
//
// Exit codes: 0 every case passed or was skipped (or --update wrote what was needed),
// 1 a case failed (a missing golden too), 2 a bad manifest, scene or option.
#include "commands.hpp"
#include "golden_results.hpp"
#include "manifest.hpp"

#include <covrast/error.hpp>
#include <covrast/renderer.hpp>
#include <covrast/scene.hpp>
#include <covrast/tools.hpp>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>

namespace covrast::cli {
namespace {

using Clock = std::chrono::steady_clock;

/// The keyword of the PNG text record in which a golden says what rendered it.
constexpr const char* kRecordKeyword = "covrast";

struct PlannedCase {
  const TestCase* test;
  std::shared_ptr<const Scene> scene;
  RenderOptions options;
};

/// The record a golden keeps: one JSON line.
std::string record_of(const PlannedCase& plan, const BuildInfo& build, int width, int height) {
  nlohmann::ordered_json record;
  record["covrast"] = build.version;
  record["mode"] = plan.test->mode;
  record["size"] = std::to_string(width) + "x" + std::to_string(height);
  record["simd"] = build.simd_target;
  record["compiler"] = build.compiler;
  record["cpu"] = build.cpu;
  return record.dump(-1, ' ', true);  // ASCII only, as PNG text must be
}

std::string golden_record(const std::filesystem::path& golden) {
  for (const PngText& text : read_png_text(golden)) {
    if (text.keyword == kRecordKeyword) return text.text;
  }
  return "(no record: not written by covrast test --update)";
}

/// The cases to run: --filter, then --shard.
std::vector<const TestCase*> select_cases(const Manifest& manifest, const TestArgs& args) {
  std::vector<const TestCase*> chosen;
  for (const TestCase& c : manifest.cases) {
    if (args.filter.empty() || name_matches(c.name, args.filter)) chosen.push_back(&c);
  }
  if (args.shard_count > 1) chosen = shard_cases(chosen, args.shard_index, args.shard_count);
  return chosen;
}

/// Loads every scene once (cases that share a scene file share it) and checks each case's
/// options before anything renders, so that a bad scene fails the run with exit 2 and no
/// output.
std::vector<PlannedCase> plan_cases(const std::vector<const TestCase*>& cases,
                                    const TestArgs& args) {
  std::map<std::filesystem::path, std::shared_ptr<const Scene>> scenes;
  MeshFileCache mesh_files;  // scenes that share mesh files share the loaded meshes
  std::vector<PlannedCase> plans;
  const int threads_per_case = cases.size() > 1 ? 1 : args.threads;
  for (const TestCase* c : cases) {
    PlannedCase plan{c, nullptr, {}};
    if (c->skip) {
      plans.push_back(plan);
      continue;
    }
    auto& scene = scenes[c->scene];
    try {
      if (!scene) scene = std::make_shared<const Scene>(load_scene(c->scene, mesh_files));
      plan.options.mode = parse_render_mode(c->mode);
      plan.options.width = c->width;
      plan.options.height = c->height;
      plan.options.threads = threads_per_case;
      Renderer check(*scene, plan.options);  // validates the size and mode against the scene
    } catch (const InputError& e) {
      throw InputError("case '" + c->name + "': " + e.what());
    }
    if (args.strict && !scene->warnings.empty()) {
      throw InputError("case '" + c->name + "': " + scene->warnings.front() + " (--strict)");
    }
    plan.scene = scene;
    plans.push_back(plan);
  }
  if (!args.quiet) {
    for (const auto& [path, scene] : scenes) {
      for (const std::string& w : scene->warnings) std::cerr << "covrast: warning: " << w << '\n';
    }
  }
  return plans;
}

/// "case 12 of 200, 3 s left" on one line of a terminal; nothing when stderr is not one.
class Progress {
 public:
  Progress(std::size_t total, bool on) : total_(total), on_(on && isatty(STDERR_FILENO) != 0) {}
  void done_one() {
    if (!on_) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    ++done_;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    const double left = elapsed / double(done_) * double(total_ - done_);
    std::fprintf(stderr, "\r\033[Kcovrast test: case %zu of %zu, %.0f s left", done_, total_, left);
    if (done_ == total_) std::fprintf(stderr, "\r\033[K");
  }

 private:
  std::size_t total_, done_ = 0;
  bool on_;
  Clock::time_point start_ = Clock::now();
  std::mutex mutex_;
};

std::vector<std::string> exceeded_measures(const CompareResult& r, const Tolerance& t) {
  std::vector<std::string> out;
  if (r.max_diff_srgb8 > t.max_diff) {
    out.push_back("diff " + std::to_string(r.max_diff_srgb8) + " > " + std::to_string(t.max_diff));
  }
  if (r.share_over_1 > t.max_pixels) {
    out.push_back("pixels " + format_number(r.share_over_1) + " > " + format_number(t.max_pixels));
  }
  if (r.rmse_linear > t.max_rmse) {
    out.push_back("rmse " + format_number(r.rmse_linear) + " > " + format_number(t.max_rmse));
  }
  return out;
}

/// Renders one case and compares it with its golden (the golden is read here, in parallel
/// with the other cases).
CaseResult run_case(const PlannedCase& plan, const BuildInfo& build) {
  CaseResult result;
  result.test = plan.test;
  if (plan.test->skip) return result;  // Skipped
  const Clock::time_point start = Clock::now();
  Image actual = render(*plan.scene, plan.options).color;
  result.render_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  result.actual_record = record_of(plan, build, actual.width, actual.height);
  std::error_code ec;
  if (!std::filesystem::exists(plan.test->golden, ec)) {
    result.status = CaseStatus::Missing;
    result.exceeded.push_back("no golden image " + plan.test->golden.string() +
                              " (run covrast test --update to write it)");
    result.actual = std::move(actual);
    return result;
  }
  Image golden = read_png(plan.test->golden);
  result.golden_record = golden_record(plan.test->golden);
  if (golden.width != actual.width || golden.height != actual.height) {
    result.status = CaseStatus::Failed;
    result.exceeded.push_back("size " + std::to_string(actual.width) + "x" +
                              std::to_string(actual.height) + " != golden " +
                              std::to_string(golden.width) + "x" + std::to_string(golden.height));
  } else {
    result.measures = compare_images(actual, golden);
    result.exceeded = exceeded_measures(result.measures, plan.test->tolerance);
    result.status = result.exceeded.empty() ? CaseStatus::Passed : CaseStatus::Failed;
    if (result.status == CaseStatus::Failed) result.heatmap = difference_heatmap(golden, actual);
  }
  if (result.status != CaseStatus::Passed) {
    result.actual = std::move(actual);
    result.golden = std::move(golden);
  }
  return result;
}

std::vector<CaseResult> run_cases(const std::vector<PlannedCase>& plans, const TestArgs& args,
                                  const BuildInfo& build) {
  std::vector<CaseResult> results(plans.size());
  Progress progress(plans.size(), !args.quiet);
  // The cases run in parallel, one thread each (a lone case takes every thread): small CI
  // images keep a thread busier as a whole case than as a few tiles.
  for_each_in_parallel(plans.size(), args.threads, [&](std::size_t i) {
    try {
      results[i] = run_case(plans[i], build);
    } catch (const InputError& e) {
      throw InputError("case '" + plans[i].test->name + "': " + e.what());
    } catch (const std::exception& e) {
      throw std::runtime_error("case '" + plans[i].test->name + "': " + e.what());
    }
    progress.done_one();
  });
  return results;
}

/// --update: writes the goldens that need it (all with --all), each with its record.
void update_goldens(const std::vector<PlannedCase>& plans, std::vector<CaseResult>& results,
                    const TestArgs& args, const BuildInfo& build) {
  for (std::size_t i = 0; i < results.size(); ++i) {
    CaseResult& r = results[i];
    if (r.status == CaseStatus::Skipped) continue;
    if (r.status == CaseStatus::Passed && !args.all) continue;
    Image image = r.actual.width > 0 ? r.actual : render(*plans[i].scene, plans[i].options).color;
    make_directories(r.test->golden.parent_path());
    write_png(image, r.test->golden,
              {{kRecordKeyword, record_of(plans[i], build, image.width, image.height)}});
    std::cout << "updated " << r.test->name << ": " << r.test->golden.string() << " ("
              << (r.status == CaseStatus::Missing  ? "new"
                  : r.status == CaseStatus::Failed ? failure_text(r)
                                                   : "rewritten")
              << ")\n";
    r.updated = true;
  }
}

void print_results(const std::vector<CaseResult>& results, const RunSummary& summary) {
  for (const CaseResult& r : results) {
    // Updated cases were reported as they were written.
    if ((r.status != CaseStatus::Failed && r.status != CaseStatus::Missing) || r.updated) continue;
    std::cout << "FAIL " << r.test->name << ": " << failure_text(r) << '\n';
    if (!r.golden_record.empty()) std::cout << "  golden: " << r.golden_record << '\n';
    std::cout << "  actual: " << r.actual_record << '\n';
  }
  if (summary.updated > 0) std::cout << "covrast test: " << summary.updated << " goldens updated\n";
  std::cout << "covrast test: " << summary.passed << " passed, " << summary.failed << " failed, "
            << summary.skipped << " skipped\n";
}

void write_artifacts(const std::filesystem::path& dir, const std::vector<CaseResult>& results) {
  make_directories(dir);
  for (const CaseResult& r : results) {
    if (r.actual.width == 0) continue;
    const std::string base = safe_file_name(r.test->name);
    write_png(r.actual, dir / (base + ".actual.png"));
    if (r.heatmap.width > 0) write_png(r.heatmap, dir / (base + ".diff.png"));
  }
}

RunSummary summarize(const std::vector<CaseResult>& results, Clock::time_point start,
                     const BuildInfo& b) {
  RunSummary s;
  for (const CaseResult& r : results) {
    s.skipped += r.status == CaseStatus::Skipped;
    s.passed += r.status == CaseStatus::Passed;
    s.failed += (r.status == CaseStatus::Failed || r.status == CaseStatus::Missing) && !r.updated;
    s.updated += r.updated;
  }
  s.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  s.build_line =
      "covrast " + b.version + ", " + b.compiler + ", SIMD " + b.simd_target + ", " + b.cpu;
  return s;
}

}  // namespace

CLI::App* add_test_command(CLI::App& app, TestArgs& args) {
  CLI::App* sub = app.add_subcommand(
      "test",
      "Render every case of a golden manifest (docs/ci.md) and compare each with its golden "
      "image within its tolerance. Exit 0 when all pass or are skipped, 1 when any fails "
      "(a missing golden too), 2 for a bad manifest or scene.");
  sub->add_option("MANIFEST", args.manifest, "The manifest (JSON)")->required();
  sub->add_option("--junit", args.junit, "Write JUnit XML results")->type_name("FILE.xml");
  sub->add_option("--report", args.report,
                  "Write a self-contained HTML report, DIR/index.html (failures first)")
      ->type_name("DIR");
  sub->add_option("--artifacts", args.artifacts,
                  "Write each failing case's actual image and difference heat map here")
      ->type_name("DIR");
  sub->add_flag("--json", args.json, "Print a one-line JSON summary instead of text");
  sub->add_flag("--update", args.update,
                "Bless: write the goldens of failing and missing cases (atomically)");
  sub->add_flag("--all", args.all, "With --update: rewrite every golden");
  sub->add_option("--shard", args.shard,
                  "Run shard I of N (1-based): cases sorted by name, "
                  "every N-th from the I-th")
      ->type_name("I/N");
  sub->add_option("--filter", args.filter, "Only the cases whose name matches GLOB (*, ?, [])")
      ->type_name("GLOB");
  sub->add_option("--threads", args.threads, "Worker threads (0 = all cores)")
      ->check(CLI::Range(0, kMaxThreads))
      ->type_name("N");
  sub->add_flag("--strict", args.strict, "Treat scene warnings as errors (exit 2)");
  sub->add_flag("--quiet", args.quiet, "No progress and no warnings on stderr");
  return sub;
}

int run_test(TestArgs args) {
  if (!args.shard.empty()) std::tie(args.shard_index, args.shard_count) = parse_shard(args.shard);
  if (args.all && !args.update) throw InputError("--all goes with --update");
  if (!args.junit.empty()) check_output_path(args.junit, {".xml"});
  const Clock::time_point start = Clock::now();
  const Manifest manifest = load_manifest(args.manifest);
  const std::vector<PlannedCase> plans = plan_cases(select_cases(manifest, args), args);
  // What rendered this run (it reads /proc/cpuinfo): once, for the records and the summary.
  const BuildInfo build = build_info();
  std::vector<CaseResult> results = run_cases(plans, args, build);
  if (args.update) update_goldens(plans, results, args, build);
  const RunSummary summary = summarize(results, start, build);
  if (!args.artifacts.empty()) write_artifacts(args.artifacts, results);
  if (!args.junit.empty()) write_junit(args.junit, manifest, results, summary);
  if (!args.report.empty()) write_html_report(args.report, manifest, results, summary);
  if (args.json) {
    std::cout << summary_json(results, summary) << '\n';
  } else {
    print_results(results, summary);
  }
  return summary.failed == 0 ? 0 : 1;
}

}  // namespace covrast::cli
