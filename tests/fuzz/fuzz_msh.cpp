// libFuzzer target: the .msh reader must either return a mesh or throw InputError, never crash,
// hang or throw anything else.
#include <cstdint>
#include <sstream>
#include <string>

#include "meshes/foundation/errors.hpp"
#include "meshes/msh_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    (void)vessel::parse_msh(in, "fuzz.msh");
  } catch (const vessel::InputError&) {
  }
  return 0;
}
