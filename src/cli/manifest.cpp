// `covrast test`: reading and checking the golden manifest (manifest.hpp).
#include "manifest.hpp"

#include "commands.hpp"

#include <covrast/error.hpp>
#include <covrast/renderer.hpp>

#include <fnmatch.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>

namespace covrast::cli {
namespace {

using Json = nlohmann::json;

/// The manifest's largest size: a CI manifest is a few kilobytes; this bounds the read.
constexpr std::uintmax_t kMaxManifestBytes = 64u << 20;

/// `text` with control characters, quotes and backslashes escaped as JSON writes them, for
/// error messages, which must stay one line whatever the manifest's keys and names hold.
std::string escaped(const std::string& text) {
  const std::string quoted = Json(text).dump(-1, ' ', false, Json::error_handler_t::replace);
  return quoted.substr(1, quoted.size() - 2);
}

/// Where an error is: "manifest.json: case 'name'" or "manifest.json: defaults".
struct Where {
  const std::filesystem::path& file;
  std::string part;
  [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
    throw InputError(file.string() + ": " + part + ": " +
                     (field.empty() ? "" : "\"" + escaped(field) + "\" ") + problem);
  }
};

Json read_json(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) {
    throw InputError(path.string() + ": cannot read manifest: no such file");
  }
  if (!std::filesystem::is_regular_file(status)) {
    throw InputError(path.string() + ": cannot read manifest: not a regular file");
  }
  if (std::filesystem::file_size(path, ec) > kMaxManifestBytes) {
    throw InputError(path.string() + ": cannot read manifest: larger than 64 MiB");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot read manifest");
  // Nesting bounded while parsing: deeper values would make printing and copying recurse.
  const Json::parser_callback_t bounded = [&path](int depth, Json::parse_event_t, Json&) {
    if (depth > kMaxJsonDepth) {
      throw InputError(path.string() + ": malformed manifest JSON: arrays and objects nested " +
                       "deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    }
    return true;
  };
  try {
    return Json::parse(in, bounded);
  } catch (const Json::exception& e) {
    std::string detail = e.what();  // without nlohmann's "[json.exception.KIND.N] " prefix
    if (detail.rfind("[json.exception.", 0) == 0 && detail.find("] ") != std::string::npos) {
      detail.erase(0, detail.find("] ") + 2);
    }
    throw InputError(path.string() + ": malformed manifest JSON: " + detail);
  }
}

void check_keys(const Json& object, const std::set<std::string>& known, const Where& where) {
  for (const auto& item : object.items()) {
    if (known.count(item.key()) == 0) where.fail(item.key(), "is not a manifest key");
  }
}

std::string string_field(const Json& object, const char* key, const Where& where) {
  const Json& value = object.at(key);
  if (!value.is_string() || value.get<std::string>().empty()) {
    where.fail(key, "must be a non-empty string");
  }
  // "\u0000" in a path would quietly name the part before it.
  if (value.get<std::string>().find('\0') != std::string::npos) {
    where.fail(key, "contains a NUL byte (\\u0000)");
  }
  return value.get<std::string>();
}

double number_field(const Json& object, const char* key, double lo, double hi, const Where& where) {
  const Json& value = object.at(key);
  if (!value.is_number()) where.fail(key, "must be a number");
  const double x = value.get<double>();
  if (!(x >= lo && x <= hi)) {
    where.fail(key, "must be in " + format_number(lo) + ".." + format_number(hi));
  }
  return x;
}

void apply_tolerance(const Json& object, Tolerance& tolerance, const Where& where) {
  if (!object.is_object()) where.fail("tolerance", "must be an object");
  const Where inner{where.file, where.part + ": tolerance"};
  check_keys(object, {"max_diff", "max_pixels", "max_rmse"}, inner);
  if (object.contains("max_diff")) {
    const double d = number_field(object, "max_diff", 0, 255, inner);
    if (d != double(int(d))) inner.fail("max_diff", "must be a whole number");
    tolerance.max_diff = int(d);
  }
  if (object.contains("max_pixels")) {
    tolerance.max_pixels = number_field(object, "max_pixels", 0, 1, inner);
  }
  if (object.contains("max_rmse")) {
    tolerance.max_rmse = number_field(object, "max_rmse", 0, 1, inner);
  }
}

/// The fields a case and the defaults share: mode, size, tolerance.
void apply_settings(const Json& object, TestCase& settings, const Where& where) {
  if (object.contains("mode")) {
    settings.mode = string_field(object, "mode", where);
    try {
      parse_render_mode(settings.mode);
    } catch (const InputError& e) {
      where.fail("mode", e.what());
    }
  }
  if (object.contains("size")) {
    const std::string size = string_field(object, "size", where);
    try {
      const auto [w, h] = parse_size(size);
      settings.width = w;
      settings.height = h;
    } catch (const InputError& e) {
      where.fail("size", e.what());
    }
  }
  if (object.contains("tolerance"))
    apply_tolerance(object.at("tolerance"), settings.tolerance, where);
}

TestCase read_case(const Json& object, std::size_t index, const TestCase& defaults,
                   const std::filesystem::path& manifest) {
  Where where{manifest, "case " + std::to_string(index + 1)};
  if (!object.is_object()) where.fail("", "must be an object");
  if (object.contains("name") && object.at("name").is_string()) {
    where.part = "case '" + escaped(object.at("name").get<std::string>()) + "'";
  }
  check_keys(object, {"name", "scene", "golden", "mode", "size", "tolerance", "skip"}, where);
  for (const char* key : {"name", "scene", "golden"}) {
    if (!object.contains(key)) where.fail(key, "is missing");
  }
  TestCase c = defaults;
  c.name = string_field(object, "name", where);
  // Names go into messages, the runner's lines and report files: one printable line each.
  if (std::any_of(c.name.begin(), c.name.end(),
                  [](char ch) { return static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f; })) {
    where.fail("name", "contains a control character (a newline, a tab, ...)");
  }
  const std::filesystem::path folder = manifest.parent_path();
  c.scene = folder / string_field(object, "scene", where);
  c.golden = folder / string_field(object, "golden", where);
  apply_settings(object, c, where);
  if (object.contains("skip")) c.skip = string_field(object, "skip", where);
  return c;
}

}  // namespace

Manifest load_manifest(const std::filesystem::path& path) {
  const Json root = read_json(path);
  const Where top{path, "manifest"};
  if (!root.is_object()) top.fail("", "must be a JSON object with \"cases\"");
  check_keys(root, {"defaults", "cases"}, top);
  TestCase defaults;
  if (root.contains("defaults")) {
    const Where where{path, "defaults"};
    if (!root.at("defaults").is_object()) top.fail("defaults", "must be an object");
    check_keys(root.at("defaults"), {"mode", "size", "tolerance"}, where);
    apply_settings(root.at("defaults"), defaults, where);
  }
  if (!root.contains("cases") || !root.at("cases").is_array()) {
    top.fail("cases", "must be an array of cases");
  }
  Manifest manifest;
  manifest.path = path;
  std::set<std::string> names;
  const Json& cases = root.at("cases");
  for (std::size_t i = 0; i < cases.size(); ++i) {
    TestCase c = read_case(cases[i], i, defaults, path);
    if (!names.insert(c.name).second) {
      throw InputError(path.string() + ": case " + std::to_string(i + 1) + ": \"name\" '" + c.name +
                       "' is used by an earlier case");
    }
    manifest.cases.push_back(std::move(c));
  }
  return manifest;
}

bool name_matches(const std::string& name, const std::string& glob) {
  return fnmatch(glob.c_str(), name.c_str(), 0) == 0;
}

std::vector<const TestCase*> shard_cases(const std::vector<const TestCase*>& cases, int index,
                                         int count) {
  std::vector<const TestCase*> sorted = cases;
  std::sort(sorted.begin(), sorted.end(),
            [](const TestCase* a, const TestCase* b) { return a->name < b->name; });
  std::vector<const TestCase*> shard;
  for (std::size_t i = std::size_t(index - 1); i < sorted.size(); i += std::size_t(count)) {
    shard.push_back(sorted[i]);
  }
  return shard;
}

}  // namespace covrast::cli
