// covrast public API: error types. Every failure that is the user's fault (bad scene,
// bad mesh file, bad option, unwritable output) is an InputError: the CLI prints its
// message as one line and exits with code 2. Anything else is an internal error (exit 1).
#pragma once

#include <stdexcept>
#include <string>

namespace covrast {

/// Bad input or usage. what() is one line that names the file (when there is one) and
/// the problem, e.g. "scenes/a.json:3:14: expected ',' or '}'". Messages quote what the
/// input said (a mode, a size, a key), so the constructor makes sure of the one line: each
/// control character (a newline, a tab, ...) becomes '?'.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(one_line(message)) {}
  explicit InputError(const char* message) : InputError(std::string(message)) {}

 private:
  static std::string one_line(std::string text) {
    for (char& c : text) {
      const auto byte = static_cast<unsigned char>(c);
      if (byte < 0x20 || byte == 0x7f) c = '?';
    }
    return text;
  }
};

}  // namespace covrast
