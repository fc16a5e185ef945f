// The faults the test programs' `faulty` backend (faulty.cpp) acts, as FLATMARCH_FAULTY asks:
// a comma-separated list of FAULT, FAULT=SCENE or FAULT=SCENE/METHOD (the frames and traces of
// that scene, or of that scene by that method, alone; without a scene, of every scene), FAULT one
// of
//   crash     SIGSEGV                    abort   std::abort()
//   hang      sleeps (an hour at most)   oom     allocates and touches memory until refused
//   nan       the scalar backend's frame with NaN colours and distances (its traces' too)
//   flip      the scalar backend's frame upside down
//   sleep:S   sleeps S seconds, then the scalar backend's frame
// e.g. FLATMARCH_FAULTY="crash=torus/analytic,hang=cube,sleep:0.5". The first fault naming the
// scene and method applies, else the first naming the scene alone, else the first naming none.
// Unset or empty: no fault (blank frames and empty traces).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace flatmarch::test {

struct Fault {
  enum class Kind { crash, abort, hang, oom, nan, flip, sleep };
  Kind kind = Kind::crash;
  std::string scene;     // empty: every scene
  std::string method;    // empty: every method
  double seconds = 0.0;  // sleep
};

// Parses a FLATMARCH_FAULTY list; throws std::invalid_argument naming what is wrong.
std::vector<Fault> parse_faults(const std::string& text);
// FLATMARCH_FAULTY's faults (none if unset).
std::vector<Fault> faults_from_environment();
// The fault for a frame or trace of `scene` by `method`, if any.
std::optional<Fault> fault_for(const std::vector<Fault>& faults, const std::string& scene,
                               const std::string& method);

}  // namespace flatmarch::test
