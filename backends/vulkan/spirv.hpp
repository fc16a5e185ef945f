// GLSL compute shaders to SPIR-V at run time, with glslang: what the Vulkan backend feeds the
// driver.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace flatmarch::vulkan {

// Compiles a GLSL 450 compute shader for Vulkan 1.1 (SPIR-V 1.3). Throws kernel::ShaderError
// with glslang's log and the source lines it names.
std::vector<uint32_t> compile_compute(const std::string& source);

// compile_compute's module, kept on disk between processes (a report compiles each program in
// its compile stage and again in its matrix, glslang with SPIRV-Tools' optimiser and validator
// about 50 ms a program on a 2-vCPU Intel Xeon): read from spirv_cache_folder() where an earlier
// process wrote it for the same source and compiler, else compiled and written there. A file
// that cannot be read or written is compiled again, never an error.
std::vector<uint32_t> compile_compute_cached(const std::string& source);

// $XDG_CACHE_HOME/flatmarch/spirv, else ~/.cache/flatmarch/spirv; empty (no cache) where
// FLATMARCH_SPIRV_CACHE is 0 or neither is set.
std::filesystem::path spirv_cache_folder();

// Where `folder` holds more than `most` modules, leaves the newest `keep` (by their last use).
void keep_newest_modules(const std::filesystem::path& folder, size_t most, size_t keep);

}  // namespace flatmarch::vulkan
