// The kernel as GLSL, specialised on a scene's features: what the OpenGL and Vulkan backends
// compile, with the tables of kernels/compile.hpp bound as buffers 0-2 and the parameters as
// uniform block 3 (std430/std140 lay the float tables out as C++ does).
#pragma once

#include <string>

#include "kernels/constants.hpp"

namespace flatmarch::kernel {

// `#version 450` and everything up to and including the kernel's functions (march, shade);
// the caller appends its main().
std::string shader_source(uint features);

}  // namespace flatmarch::kernel
