// What the kernel's backends share around it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "backends/backend.hpp"
#include "kernels/kernel.hpp"

namespace flatmarch {

// A ray's trace from the events the kernel recorded (kernel::KernelEvent) and its steps.
Trace kernel_trace(const std::vector<kernel::KernelEvent>& events, int steps);

// The event buffer a shader's trace variant fills (binding 4, kernels/shader_prelude.glsl, std430):
// this header, then ShaderEventRecords.
struct ShaderEventHeader {
  int32_t count, max_events, steps, pad;
};
struct ShaderEventRecord {
  int32_t kind[4];  // kind, polygon, edge, to_polygon
  int32_t more[4];  // to_edge, object, 0, 0
  float at[4];      // the point and t
};
// Bytes of an event buffer with room for `max_events` events.
size_t shader_trace_bytes(int max_events);
// The trace in an event buffer of shader_trace_bytes(max_events) bytes.
Trace shader_trace(const unsigned char* buffer, int max_events);

}  // namespace flatmarch
