// Tests: running the built covrast executable (COVRAST_CLI_PATH) with arguments, capturing
// its exit code, stdout and stderr; and small file helpers the command-line tests share.
#pragma once

#include <sys/wait.h>

#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <string>
#include <vector>

namespace covrast::test {

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  REQUIRE(out.good());
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// Single-quotes an argument for /bin/sh.
inline std::string quoted(const std::string& arg) {
  std::string out = "'";
  for (char c : arg) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  return out + "'";
}

struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

/// Runs the CLI with `args`, capturing stdout and stderr in files inside `dir`; with
/// `cd_into_dir` it runs in `dir`, so that relative paths in `args` are relative to it.
inline RunResult run_cli_in(const std::filesystem::path& dir, const std::vector<std::string>& args,
                            bool cd_into_dir = false) {
  const std::filesystem::path out_file = dir / "stdout.txt";
  const std::filesystem::path err_file = dir / "stderr.txt";
  std::string command = cd_into_dir ? "cd " + quoted(dir.string()) + " && " : "";
  command += quoted(COVRAST_CLI_PATH);
  // Appending piecewise (not `" " + quoted(...)`) also avoids a g++ 12 -Wrestrict false positive.
  for (const std::string& arg : args) {
    command += ' ';
    command += quoted(arg);
  }
  command += " >";
  command += quoted(out_file.string());
  command += " 2>";
  command += quoted(err_file.string());
  command += " </dev/null";
  const int status = std::system(command.c_str());
  RunResult result;
  REQUIRE(status != -1);
  REQUIRE(WIFEXITED(status));
  result.exit_code = WEXITSTATUS(status);
  result.out = read_text(out_file);
  result.err = read_text(err_file);
  std::filesystem::remove(out_file);
  std::filesystem::remove(err_file);
  return result;
}

}  // namespace covrast::test
