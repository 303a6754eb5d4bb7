// Helpers shared by the covrast subcommands: output-path checks and number formatting.
#include "commands.hpp"

#include <covrast/error.hpp>
#include <covrast/scene.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <system_error>

namespace covrast::cli {

namespace {

/// A mesh file by its extension (any case).
bool is_mesh_file(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".obj" || ext == ".gltf" || ext == ".glb";
}

}  // namespace

SceneChoices scene_choices(const ViewArgs& view) {
  SceneChoices choices;
  choices.material_variant = view.variant;
  std::optional<AnimationTime>& pose = choices.pose;
  if (view.time_s || !view.animation.empty()) {
    pose.emplace();
    pose->time_s = view.time_s.value_or(0.0);
    if (!(pose->time_s >= 0.0) || !std::isfinite(pose->time_s)) {
      throw InputError("--time: expected a finite number of seconds >= 0");
    }
    const std::string& a = view.animation;
    if (!a.empty() && a.size() <= 9 &&
        std::all_of(a.begin(), a.end(), [](unsigned char c) { return std::isdigit(c) != 0; })) {
      pose->index = std::stoi(a);
    } else {
      pose->name = a;
    }
  }
  return choices;
}

Scene load_scene_or_model(const std::string& path, const ViewArgs& view, int width, int height) {
  const SceneChoices choices = scene_choices(view);
  if (!is_mesh_file(path)) return load_scene(path, choices);
  return load_mesh_scene(path, width > 0 ? width : 640, height > 0 ? height : 360, choices);
}

void report_scene_warnings(const std::string& what, const std::vector<std::string>& warnings,
                           bool strict) {
  if (strict && !warnings.empty()) {
    const std::size_t count = warnings.size();
    throw StrictWarningsError(
        what + ": --strict treats warnings as errors: " + warnings.front() +
            (count > 1 ? " (" + std::to_string(count) + " warnings below)" : ""),
        warnings);
  }
  for (const std::string& warning : warnings) std::cerr << "warning: " << warning << '\n';
}

void check_output_path(const std::filesystem::path& path,
                       const std::vector<std::string_view>& extensions) {
  namespace fs = std::filesystem;
  const std::string shown = path.string();
  if (!path.has_filename()) throw InputError(shown + ": cannot write: not a file name");

  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (std::find(extensions.begin(), extensions.end(), ext) == extensions.end()) {
    std::string accepted;
    for (std::string_view e : extensions)
      accepted += (accepted.empty() ? "" : " or ") + std::string(e);
    throw InputError(shown + ": unsupported output extension '" + ext + "' (expected " + accepted +
                     ")");
  }

  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  const fs::file_status dir_status = fs::status(dir, ec);
  if (!fs::exists(dir_status)) {
    throw InputError(shown + ": cannot write: directory '" + dir.string() + "' does not exist");
  }
  if (!fs::is_directory(dir_status)) {
    throw InputError(shown + ": cannot write: '" + dir.string() + "' is not a directory");
  }
  // Creating the temporary file and renaming it needs write and search permission on dir.
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    const std::string why = std::error_code(errno, std::generic_category()).message();
    throw InputError(shown + ": cannot write: directory '" + dir.string() + "': " + why);
  }
  if (fs::is_directory(fs::status(path, ec))) {
    throw InputError(shown + ": cannot write: is a directory");
  }
  // Permission bits do not tell everything (root passes access(); /proc and read-only mounts
  // refuse new files): create and remove a file beside the output, as writing will, so that a
  // bad output path fails before rendering rather than after.
  fs::path probe = path;
  probe += ".probe-" + std::to_string(::getpid());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    const std::string why = std::error_code(errno, std::generic_category()).message();
    throw InputError(shown + ": cannot write: " + why);
  }
  ::close(fd);
  ::unlink(probe.c_str());
}

/// Parses "WxH" (decimal, each side 1..kMaxImageSide).
std::pair<int, int> parse_size(const std::string& text) {
  const auto fail = [&]() -> std::pair<int, int> {
    throw InputError("expected WxH with each side in 1.." + std::to_string(kMaxImageSide) +
                     ", got '" + text + "'");
  };
  const std::size_t x = text.find_first_of("xX");
  if (x == std::string::npos || x == 0 || x + 1 == text.size()) return fail();
  const auto parse_side = [&](const char* first, const char* last) {
    int value = 0;
    const auto [end, error] = std::from_chars(first, last, value);
    if (error != std::errc() || end != last || value < 1 || value > kMaxImageSide) fail();
    return value;
  };
  const char* begin = text.data();
  return {parse_side(begin, begin + x), parse_side(begin + x + 1, begin + text.size())};
}

std::pair<int, int> parse_shard(const std::string& text) {
  const auto fail = [&]() -> std::pair<int, int> {
    throw InputError("--shard: expected I/N with 1 <= I <= N <= 10000, got '" + text + "'");
  };
  const std::size_t slash = text.find('/');
  if (slash == std::string::npos) return fail();
  int index = 0, count = 0;
  const char* begin = text.data();
  const char* end = begin + text.size();
  const auto a = std::from_chars(begin, begin + slash, index);
  const auto b = std::from_chars(begin + slash + 1, end, count);
  if (a.ec != std::errc() || a.ptr != begin + slash || b.ec != std::errc() || b.ptr != end ||
      index < 1 || count < index || count > 10000) {
    return fail();
  }
  return {index, count};
}

std::string safe_file_name(const std::string& name) {
  std::string out;
  for (const unsigned char c : name) {
    out += std::isalnum(c) || c == '-' || c == '_' || c == '.' ? char(c) : '_';
  }
  if (out.empty() || out == "." || out == "..") out = "_" + out;
  return out;
}

void write_text_file(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::path temp = path;
  temp += ".tmp-" + std::to_string(::getpid());
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(temp, ec);
      throw InputError(path.string() + ": cannot write");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    throw InputError(path.string() + ": cannot write: " + ec.message());
  }
}

std::string format_number(double value) {
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char text[64];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

}  // namespace covrast::cli
