#pragma once
/// Atomic file output: write to a temporary file beside the target, then rename it into place,
/// so a failed run never leaves a file that looks valid.
#include <filesystem>
#include <functional>
#include <ostream>

namespace vessel {

/// Calls `write(stream)` on a temporary file in the target's directory and renames it to `path`
/// when `write` returns normally. On any exception the temporary is removed and the exception
/// rethrown; an existing file at `path` is untouched. Throws InputError if the directory cannot be
/// written. Creates missing parent directories.
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write, bool binary = false);

}  // namespace vessel
