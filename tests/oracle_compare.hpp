// What the backend tests share when they hold a kernel backend against the oracle: generic probe
// rays and event descriptions, from the conformance library.
#pragma once

#include <string>
#include <vector>

#include "conformance/suite.hpp"

namespace flatmarch::test {

constexpr int kEvents = 20;
constexpr int kRaysPerScene = 8;

// Generic rays (conformance::probe_rays): their first kEvents events are decided.
inline std::vector<Ray> generic_rays(const Scene& scene) {
  return conformance::probe_rays(scene, kRaysPerScene, kEvents);
}

inline std::string describe(const Event& e) {
  return conformance::describe(e);
}

}  // namespace flatmarch::test
