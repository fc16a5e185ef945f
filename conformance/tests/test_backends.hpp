// The backends the conformance tests run, by name: the GPU ones shared with the other tests (the
// Vulkan one under its validation layer), the CPU ones made once.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "tests/opengl_backend.hpp"
#include "tests/vulkan_backend.hpp"

namespace flatmarch::test {

inline const Backend& backend_named(const std::string& name) {
  if (name == "opengl") return opengl();
  if (name == "vulkan") return vulkan();
  static std::map<std::string, std::unique_ptr<Backend>> made;
  auto& b = made[name];
  if (!b) b = make_backend(name, {});
  return *b;
}

}  // namespace flatmarch::test
