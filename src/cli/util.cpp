// Helpers shared by the covrast subcommands: output-path checks and number formatting.
#include "commands.hpp"

#include <covrast/error.hpp>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <system_error>

namespace covrast::cli {

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
}

std::string format_number(double value) {
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char text[64];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

}  // namespace covrast::cli
