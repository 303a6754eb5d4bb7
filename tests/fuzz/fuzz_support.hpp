// Shared by the fuzz targets: a private scratch folder for the readers that take a path (the
// scene loader, the PNG reader, the manifest), and the rule for what an input may do.
#pragma once

#include <covrast/error.hpp>

#include <unistd.h>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace covrast::fuzz {

/// A folder of this process's own under $TMPDIR (or /tmp), made on first use and removed at
/// exit: each target writes its input there as a file and may put fixed companion files
/// beside it (a scene's meshes).
inline const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern =
        std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/covrast-fuzz-XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("covrast fuzz: mkdtemp");
      std::abort();
    }
    static const std::filesystem::path made = pattern;
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(made, ec);
    });
    return made;
  }();
  return dir;
}

/// Writes `bytes` to scratch_dir() / name (replacing it) and returns the path.
inline std::filesystem::path write_scratch(const std::string& name, std::string_view bytes) {
  const std::filesystem::path path = scratch_dir() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) {
    std::perror("covrast fuzz: cannot write the input file");
    std::abort();
  }
  return path;
}

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// Runs `read` on one input. An InputError is the expected answer to bad input; its message
/// must be one line (the CLI prints it as one). Any other exception escapes and libFuzzer
/// reports it as a crash: it would be an "internal error" (exit 1) of the command line.
template <class Read>
void expect_input_error_only(Read read) {
  try {
    read();
  } catch (const InputError& e) {
    const std::string_view message = e.what();
    if (message.empty() || message.find('\n') != std::string_view::npos) {
      std::fprintf(stderr, "covrast fuzz: InputError message not one line: [%s]\n", e.what());
      std::abort();
    }
  }
}

}  // namespace covrast::fuzz
