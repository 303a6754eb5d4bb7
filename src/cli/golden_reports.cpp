// `covrast test`: the reports of a run (golden_results.hpp): JUnit XML for CI systems, a JSON
// summary line, and one self-contained HTML page (images as data: URLs, no external scripts),
// failures first with golden, actual and heat map side by side and a zoom.
#include "commands.hpp"
#include "golden_results.hpp"

#include <covrast/error.hpp>

#include <nlohmann/json.hpp>

#include <sstream>
#include <system_error>

namespace covrast::cli {
namespace {

/// Escapes text for XML and HTML text and attribute values.
std::string escaped(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        // XML 1.0 forbids most control characters, even escaped.
        out += (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t') ? '?' : c;
    }
  }
  return out;
}

/// RFC 4648 base64, for the images inlined as data: URLs.
std::string base64(const std::vector<std::uint8_t>& bytes) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t b0 = bytes[i];
    const std::uint32_t b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0;
    const std::uint32_t b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0;
    const std::uint32_t triple = b0 << 16 | b1 << 8 | b2;
    out += kDigits[triple >> 18 & 63];
    out += kDigits[triple >> 12 & 63];
    out += i + 1 < bytes.size() ? kDigits[triple >> 6 & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[triple & 63] : '=';
  }
  return out;
}

std::string data_url(const Image& image) {
  return "data:image/png;base64," + base64(encode_png(image));
}

std::string seconds(double ms) { return format_number(ms / 1000.0); }

void junit_case(std::ostringstream& xml, const std::string& suite, const CaseResult& r) {
  xml << "  <testcase name=\"" << escaped(r.test->name) << "\" classname=\"" << escaped(suite)
      << "\" time=\"" << seconds(r.render_ms) << "\"";
  if (r.status == CaseStatus::Passed) {
    xml << "/>\n";
    return;
  }
  xml << ">\n";
  if (r.status == CaseStatus::Skipped) {
    xml << "    <skipped message=\"" << escaped(*r.test->skip) << "\"/>\n";
  } else {
    xml << "    <failure message=\"" << escaped(failure_text(r)) << "\" type=\""
        << (r.status == CaseStatus::Missing ? "missing golden" : "mismatch") << "\">"
        << escaped("golden: " + (r.golden_record.empty() ? "none" : r.golden_record) +
                   "\nactual: " + r.actual_record + "\nscene: " + r.test->scene.string() +
                   "\ngolden file: " + r.test->golden.string())
        << "</failure>\n";
  }
  xml << "  </testcase>\n";
}

const char* kReportStyle = R"(
body { font: 14px/1.4 sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.4em; } h2 { font-size: 1.1em; margin-top: 2em; }
.build { color: #555; } .failed { color: #b00; } .passed { color: #070; } .skipped { color: #777; }
.case { border-top: 1px solid #ccc; padding: 0.8em 0; }
.images { display: flex; gap: 1em; overflow-x: auto; align-items: flex-start; }
figure { margin: 0; } figcaption { color: #555; font-size: 0.9em; }
img { image-rendering: pixelated; border: 1px solid #999; }
table { border-collapse: collapse; } td, th { padding: 0.2em 0.8em; text-align: left; }
tr:nth-child(even) { background: #f3f3f3; }
)";

/// The zoom: one slider scales every image by an integer factor (nearest-neighbour).
const char* kReportScript = R"(
function zoom(factor) {
  document.getElementById('zoom-value').textContent = factor + 'x';
  for (const img of document.querySelectorAll('img[data-width]')) {
    img.style.width = (img.dataset.width * factor) + 'px';
  }
}
const slider = document.getElementById('zoom');
slider.addEventListener('input', e => zoom(e.target.value));
// Start at the largest factor that keeps golden, actual and heat map side by side.
let widest = 1;
for (const img of document.querySelectorAll('img[data-width]')) {
  widest = Math.max(widest, Number(img.dataset.width));
}
slider.value = Math.max(1, Math.min(8, Math.floor((window.innerWidth - 80) / (3 * widest))));
zoom(slider.value);
)";

void html_figure(std::ostringstream& html, const char* caption, const Image& image) {
  if (image.width == 0) return;
  html << "<figure><img alt=\"" << caption << "\" data-width=\"" << image.width << "\" src=\""
       << data_url(image) << "\"><figcaption>" << caption << "</figcaption></figure>";
}

void html_failure(std::ostringstream& html, const CaseResult& r) {
  html << "<div class=\"case\" id=\"" << escaped(r.test->name) << "\"><h3 class=\"failed\">"
       << escaped(r.test->name) << (r.status == CaseStatus::Missing ? " (no golden)" : "")
       << (r.updated ? " (golden updated)" : "") << "</h3>\n<p>" << escaped(failure_text(r))
       << "</p>\n<p>golden: <code>" << escaped(r.golden_record.empty() ? "none" : r.golden_record)
       << "</code><br>actual: <code>" << escaped(r.actual_record) << "</code><br>scene: <code>"
       << escaped(r.test->scene.string()) << "</code></p>\n<div class=\"images\">";
  html_figure(html, "golden", r.golden);
  html_figure(html, "actual", r.actual);
  html_figure(html, "difference (black = equal, red = 32/255 or more)", r.heatmap);
  html << "</div></div>\n";
}

void html_table(std::ostringstream& html, const std::vector<CaseResult>& results) {
  html << "<h2>All cases</h2>\n<table><tr><th>case</th><th>status</th><th>diff</th>"
          "<th>pixels</th><th>rmse</th><th>render ms</th></tr>\n";
  for (const CaseResult& r : results) {
    const bool compared = r.measures.width > 0;
    html << "<tr><td>" << escaped(r.test->name) << "</td><td class=\""
         << (r.status == CaseStatus::Passed    ? "passed"
             : r.status == CaseStatus::Skipped ? "skipped"
                                               : "failed")
         << "\">" << status_name(r.status) << "</td><td>"
         << (compared ? std::to_string(r.measures.max_diff_srgb8) : "") << "</td><td>"
         << (compared ? format_number(r.measures.share_over_1) : "") << "</td><td>"
         << (compared ? format_number(r.measures.rmse_linear) : "") << "</td><td>"
         << (r.status == CaseStatus::Skipped ? escaped(*r.test->skip) : format_number(r.render_ms))
         << "</td></tr>\n";
  }
  html << "</table>\n";
}

}  // namespace

const char* status_name(CaseStatus status) {
  switch (status) {
    case CaseStatus::Passed:
      return "passed";
    case CaseStatus::Failed:
      return "failed";
    case CaseStatus::Missing:
      return "missing golden";
    case CaseStatus::Skipped:
      return "skipped";
  }
  return "?";
}

std::string failure_text(const CaseResult& result) {
  std::string text;
  for (const std::string& part : result.exceeded) text += (text.empty() ? "" : ", ") + part;
  return text;
}

void write_junit(const std::filesystem::path& path, const Manifest& manifest,
                 const std::vector<CaseResult>& results, const RunSummary& summary) {
  const std::string suite = manifest.path.stem().string();
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites>\n<testsuite name=\""
      << escaped(suite) << "\" tests=\"" << results.size() << "\" failures=\"" << summary.failed
      << "\" errors=\"0\" skipped=\"" << summary.skipped << "\" time=\""
      << format_number(summary.seconds) << "\">\n  <properties><property name=\"build\" value=\""
      << escaped(summary.build_line) << "\"/></properties>\n";
  for (const CaseResult& r : results) junit_case(xml, suite, r);
  xml << "</testsuite>\n</testsuites>\n";
  write_text_file(path, xml.str());
}

std::string summary_json(const std::vector<CaseResult>& results, const RunSummary& summary) {
  nlohmann::ordered_json out;
  out["passed"] = summary.passed;
  out["failed"] = summary.failed;
  out["skipped"] = summary.skipped;
  out["updated"] = summary.updated;
  out["seconds"] = summary.seconds;
  out["build"] = summary.build_line;
  out["cases"] = nlohmann::ordered_json::array();
  for (const CaseResult& r : results) {
    nlohmann::ordered_json c;
    c["name"] = r.test->name;
    c["status"] = status_name(r.status);
    if (r.measures.width > 0) {
      c["diff"] = r.measures.max_diff_srgb8;
      c["pixels"] = r.measures.share_over_1;
      c["rmse"] = r.measures.rmse_linear;
    }
    if (!r.exceeded.empty()) c["failure"] = failure_text(r);
    if (r.test->skip) c["skip"] = *r.test->skip;
    c["render_ms"] = r.render_ms;
    out["cases"].push_back(c);
  }
  return out.dump();
}

void make_directories(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir.string() + ": cannot create the directory: " + ec.message());
}

void write_html_report(const std::filesystem::path& dir, const Manifest& manifest,
                       const std::vector<CaseResult>& results, const RunSummary& summary) {
  make_directories(dir);
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>covrast "
          "test: "
       << escaped(manifest.path.filename().string()) << "</title><style>" << kReportStyle
       << "</style></head><body>\n<h1>covrast test: " << escaped(manifest.path.string())
       << "</h1>\n<p id=\"counts\"><span class=\"passed\">" << summary.passed
       << " passed</span>, <span class=\"failed\">" << summary.failed << " failed</span>, "
       << summary.skipped << " skipped" << (summary.updated ? ", " : "")
       << (summary.updated ? std::to_string(summary.updated) + " goldens updated" : "") << " in "
       << format_number(summary.seconds) << " s</p>\n<p class=\"build\">"
       << escaped(summary.build_line)
       << "</p>\n<p><label>zoom <input id=\"zoom\" type=\"range\" min=\"1\" max=\"8\" value=\"2\"> "
          "<span id=\"zoom-value\"></span></label></p>\n<h2>Failures</h2>\n";
  int shown = 0;
  for (const CaseResult& r : results) {
    if (r.status == CaseStatus::Failed || r.status == CaseStatus::Missing) {
      html_failure(html, r);
      ++shown;
    }
  }
  if (shown == 0) html << "<p>none</p>\n";
  html_table(html, results);
  html << "<script>" << kReportScript << "</script>\n</body></html>\n";
  write_text_file(dir / "index.html", html.str());
}

}  // namespace covrast::cli
