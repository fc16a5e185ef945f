// Shader compile errors as a user can act on them: the compiler's log with the generated source
// lines it names. The OpenGL backend (the driver's compiler) and the Vulkan backend (glslang) share
// them.
#pragma once

#include <stdexcept>
#include <string>

namespace flatmarch::kernel {

// A shader that does not compile or link. what() has the compiler's log and, for each line it
// names, the generated source around it.
class ShaderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The compiler's log with the lines of `source` it refers to, `context` lines either side,
// numbered, the named line marked with `>`. It reads Mesa's "0:LINE(COLUMN): error: ...",
// NVIDIA's "0(LINE) : error C1503: ..." and glslang's "ERROR: 0:LINE: ...". Lines that warnings
// name are shown only when there is no error.
std::string annotate_log(const std::string& source, const std::string& log, int context = 3);

}  // namespace flatmarch::kernel
