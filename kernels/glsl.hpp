// The C++ side of the GLSL subset the kernel is written in (kernels/*.glsl). GLM mirrors GLSL's
// types and functions; what differs is spelled with the macros below, which a shader's prelude
// defines the GLSL way (`#define INOUT(T) inout T`, `#define KCONST const`, `#define ALIGN16`).
//
// Rules for kernel code, so that it compiles as both: no pointers, references, templates,
// overloading on return type, recursion or library calls; literals written as real(1.5); no
// swizzles (vec2(v) takes the first two components in both); structs filled field by field.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>

// A parameter the function writes back (GLSL `inout`).
#define INOUT(T) T&
// A constant at file scope (GLSL `const`).
#define KCONST inline constexpr
// A table member that a std140 block starts at a 16-byte boundary, as GLSL aligns a vec4 there
// by itself (kernels/tables.glsl's KernelParams).
#define ALIGN16 alignas(16)
// A function of kernels/maths.glsl: inline, and forced inline where maths.glsl is compiled for
// packets of rays (backends/simd/maths-inl.h redefines it).
#define KINLINE inline

namespace flatmarch::kernel {

using uint = unsigned;
using glm::ivec4;

// The GLSL built-ins the kernel calls, found unqualified from inside the kernel's structs.
using glm::abs;
using glm::clamp;
using glm::cross;
using glm::dot;
using glm::floor;
using glm::length;
using glm::max;
using glm::min;
using glm::mod;
using glm::normalize;
using glm::pow;
using glm::sqrt;

// A condition per ray, and the choice it makes (kernels/maths.glsl): one ray here, one per lane on
// packets (backends/simd/maths-inl.h).
using lane_bool = bool;
template <typename T>
T select(bool c, T a, T b) {
  return c ? a : b;
}

// The vector types of one precision, as the kernel names them.
template <typename real>
struct Types {
  using vec2 = glm::vec<2, real>;
  using vec3 = glm::vec<3, real>;
  using vec4 = glm::vec<4, real>;
};

}  // namespace flatmarch::kernel
