// Any input either loads or is rejected with a SceneError; anything else (a crash, another
// exception, a sanitizer report, a hang) is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "scene/load.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    flatmarch::parse_scene(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
  } catch (const flatmarch::SceneError&) {
  }
  return 0;
}
