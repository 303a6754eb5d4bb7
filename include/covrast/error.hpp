// covrast public API: error types. Every failure that is the user's fault (bad scene,
// bad mesh file, bad option, unwritable output) is an InputError: the CLI prints its
// message as one line and exits with code 2. Anything else is an internal error (exit 1).
#pragma once

#include <stdexcept>
#include <string>

namespace covrast {

/// Bad input or usage. what() is one line that names the file (when there is one) and
/// the problem, e.g. "scenes/a.json:3:14: expected ',' or '}'".
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace covrast
