#pragma once
/// Errors for bad input: every message names the file (or key) and line, what was found and what
/// was expected, so the command-line program can print it and exit non-zero.
#include <stdexcept>
#include <string>

namespace vessel {

/// Input that cannot be used: a malformed or missing file, a missing physical group, a parameter
/// out of range. The message is complete and meant for the user.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace vessel
