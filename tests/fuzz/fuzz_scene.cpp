// libFuzzer target: the scene reader returns a validated scene or throws InputError, nothing else.
#include <cstdint>
#include <string_view>

#include "meshes/foundation/errors.hpp"
#include "verification/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)vessel::parse_scene(std::string_view(reinterpret_cast<const char*>(data), size),
                              "fuzz.toml");
  } catch (const vessel::InputError&) {
  }
  return 0;
}
