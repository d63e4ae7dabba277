#include "meshes/foundation/atomic_file.hpp"

#include <fstream>
#include <random>
#include <system_error>

#include "meshes/foundation/errors.hpp"

namespace vessel {

namespace fs = std::filesystem;

void write_file_atomically(const fs::path& path, const std::function<void(std::ostream&)>& write,
                           bool binary) {
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) {
    throw InputError("cannot create output directory '" + dir.string() + "': " + ec.message());
  }
  std::random_device rd;
  std::string tmp_name = ".";
  tmp_name += path.filename().string();
  tmp_name += ".tmp";
  tmp_name += std::to_string(rd());
  const fs::path tmp = dir / tmp_name;
  try {
    {
      std::ofstream out(tmp, binary ? std::ios::binary : std::ios::out);
      if (!out) {
        throw InputError("cannot write output file '" + path.string() +
                         "': the directory is not writable");
      }
      out.exceptions(std::ios::badbit | std::ios::failbit);
      write(out);
      out.flush();
    }
    fs::rename(tmp, path);
  } catch (const std::ios_base::failure& e) {
    fs::remove(tmp, ec);
    throw InputError("writing '" + path.string() + "' failed: " + e.what());
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

}  // namespace vessel
