// `covrast test`: what each case gave, and the reports made from it (golden_reports.cpp).
#pragma once

#include "manifest.hpp"

#include <covrast/compare.hpp>
#include <covrast/image.hpp>
#include <covrast/tools.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace covrast::cli {

enum class CaseStatus { Passed, Failed, Missing, Skipped };

struct CaseResult {
  const TestCase* test = nullptr;
  CaseStatus status = CaseStatus::Skipped;
  CompareResult measures;             ///< when a golden was compared
  std::vector<std::string> exceeded;  ///< e.g. "diff 3 > 0"; or why it failed
  std::string golden_record;          ///< what rendered the golden (its PNG text), if known
  std::string actual_record;          ///< what rendered this run
  double render_ms = 0;
  bool updated = false;  ///< --update wrote its golden
  /// Kept for failing cases only (artifacts and the HTML report).
  Image actual, golden, heatmap;
};

struct RunSummary {
  int passed = 0, failed = 0, skipped = 0, updated = 0;
  double seconds = 0;
  std::string build_line;  ///< build_info() in words
};

const char* status_name(CaseStatus status);
/// "diff 3 > 0, rmse 0.0012 > 0" or the reason a case failed.
std::string failure_text(const CaseResult& result);

/// JUnit XML: one testsuite, one testcase per case (name = the case's name), a <failure>
/// with the measures and both records, <skipped> with its reason.
void write_junit(const std::filesystem::path& path, const Manifest& manifest,
                 const std::vector<CaseResult>& results, const RunSummary& summary);
/// One JSON line: the counts and each case's status and measures.
std::string summary_json(const std::vector<CaseResult>& results, const RunSummary& summary);
/// DIR/index.html, self-contained (images inline, no external scripts): failures first, each
/// with golden, actual and heat map side by side and a zoom, then the rest in a table.
void write_html_report(const std::filesystem::path& dir, const Manifest& manifest,
                       const std::vector<CaseResult>& results, const RunSummary& summary);
/// create_directories, but a path that cannot be a directory (a regular file is there, or
/// above it) is an InputError naming it (exit 2), not a filesystem_error (exit 1).
void make_directories(const std::filesystem::path& dir);

}  // namespace covrast::cli
