// The kernel as GLSL, specialised on a scene's features: what the OpenGL and Vulkan backends
// compile. The caller supplies the tables and parameters (`polygons`, `edges`, `objects`,
// `params`: as buffers and a uniform block, or baked in as constants, kernels/scene_shader.hpp)
// and appends its main().
#pragma once

#include <string>

#include "kernels/constants.hpp"

namespace flatmarch::kernel {

// The tables as std430 buffers 0-2 and the parameters as std140 uniform block 3 (their records
// lay out as in C++).
extern const char* const kBufferTables;

// `#version 450`, the constants, the table records, `tables` (GLSL that declares `polygons`,
// `edges`, `objects` and `params`) and the kernel's functions (march, shade). With
// `trace`, record_event appends to the event buffer (binding 4) instead of doing nothing.
// `features` kFeaturesInTables: `tables` defines FEATURES itself (a value read at run time).
constexpr uint kFeaturesInTables = 0xffffffffu;
std::string shader_source(uint features, const std::string& tables, bool trace = false);

// The kernel's constants and per-lane maths (kernels/maths.glsl) alone, without `#version`, for a
// shader of its own that calls them (the viewer's window: srgb()).
std::string maths_source();

// With the tables as buffers.
inline std::string shader_source(uint features) {
  return shader_source(features, kBufferTables);
}

}  // namespace flatmarch::kernel
