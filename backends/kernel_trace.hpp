// What the kernel's backends share around it.
#pragma once

#include <vector>

#include "backends/backend.hpp"
#include "kernels/kernel.hpp"

namespace flatmarch {

// A ray's trace from the events the kernel recorded (kernel::KernelEvent) and its steps.
Trace kernel_trace(const std::vector<kernel::KernelEvent>& events, int steps);

}  // namespace flatmarch
