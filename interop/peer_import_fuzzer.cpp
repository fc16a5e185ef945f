// Any JSON input either converts into a scene that loads, or is rejected with a SceneError.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "interop/peer_import.hpp"
#include "scene/load.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto doc = flatmarch::parse_json(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    const flatmarch::PeerImport imported = flatmarch::import_peer(doc, "fuzz.json");
    // The converted scene must load: a SceneError here is a bug of the converter.
    try {
      flatmarch::scene_from_json(imported.scene, "converted.json");
    } catch (const flatmarch::SceneError&) {
      __builtin_trap();
    }
  } catch (const flatmarch::SceneError&) {
  }
  return 0;
}
