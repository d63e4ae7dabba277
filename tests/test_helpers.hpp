#pragma once
/// Shared helpers for the test executables.
#include <filesystem>
#include <string>

#include "test_paths.hpp"

namespace vessel::test {

/// A fresh, empty directory under the system temp dir, unique per test; removed on destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// Writes `text` to `path` (test inputs only; not atomic).
void write_text(const std::filesystem::path& path, const std::string& text);
std::string read_text(const std::filesystem::path& path);

struct CommandResult {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};
/// Runs a shell command and captures its combined output and exit code.
CommandResult run_command(const std::string& command);

/// Runs the vesselverify program built with the tests (test_paths.hpp) with `args`.
inline CommandResult vv(const std::string& args) {
  return run_command(VESSELVERIFY_EXE + " " + args);
}

}  // namespace vessel::test
