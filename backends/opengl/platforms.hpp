// The ways context.cpp makes a headless context: EGL (egl.cpp) and OSMesa (osmesa.cpp).
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "backends/opengl/context.hpp"

namespace flatmarch::gl {

// A device and how to make a context on it: make(device, profile) throws std::runtime_error
// saying why not. The device's index is set by the caller; its strings are filled in once a
// context is made.
struct Candidate {
  Device device;
  std::function<std::unique_ptr<Context>(const Device&, Profile)> make;
};

// EGL's devices, in its order (the device platform), or Mesa's surfaceless display where EGL
// lists none. Where libEGL cannot be loaded or has neither, one candidate whose make() says why.
std::vector<Candidate> egl_candidates();

// OSMesa, always software (Mesa's llvmpipe or softpipe).
Candidate osmesa_candidate();

}  // namespace flatmarch::gl
