// The backends the conformance tests run, by name, each made once a program (a GPU backend's
// context and compiled programs are reused), under its validation layer where it has one
// (BackendOptions::validation: the Vulkan backend's).
#pragma once

#include <map>
#include <memory>
#include <string>

#include "backends/backend.hpp"

namespace flatmarch::test {

inline const Backend& backend_named(const std::string& name) {
  static std::map<std::string, std::unique_ptr<Backend>> made;
  auto& b = made[name];
  if (!b) b = make_backend(name, {.validation = true});
  return *b;
}

}  // namespace flatmarch::test
