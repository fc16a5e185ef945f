// GLSL compute shaders to SPIR-V at run time, with glslang: what the Vulkan backend feeds the
// driver.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace flatmarch::vulkan {

// Compiles a GLSL 450 compute shader for Vulkan 1.1 (SPIR-V 1.3). Throws kernel::ShaderError
// with glslang's log and the source lines it names.
std::vector<uint32_t> compile_compute(const std::string& source);

}  // namespace flatmarch::vulkan
