// The kernel's constants (kernels/constants.glsl) for C++: hit codes, methods, edge kinds,
// solids, events, features.
#pragma once

#include "kernels/glsl.hpp"

namespace flatmarch {
using kernel::uint;
#include "kernels/constants.glsl"
}  // namespace flatmarch
