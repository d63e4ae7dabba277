// libFuzzer target: the STL reader returns a surface or throws InputError, nothing else.
#include <cstdint>
#include <string_view>

#include "meshes/foundation/errors.hpp"
#include "meshes/stl_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)vessel::parse_stl(std::string_view(reinterpret_cast<const char*>(data), size),
                            "fuzz.stl");
  } catch (const vessel::InputError&) {
  }
  return 0;
}
