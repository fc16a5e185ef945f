#include "backends/backend.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <string>

#include "backends/kernel_trace.hpp"

namespace flatmarch {

Trace kernel_trace(const std::vector<kernel::KernelEvent>& events, int steps) {
  Trace trace;
  trace.steps = steps;
  for (const kernel::KernelEvent& e : events)
    trace.events.push_back({.kind = static_cast<EventKind>(e.kind),
                            .polygon = e.polygon,
                            .edge = e.edge,
                            .to_polygon = e.to_polygon,
                            .to_edge = e.to_edge,
                            .object = e.object,
                            .t = e.t,
                            .at = e.at});
  return trace;
}

size_t shader_trace_bytes(int max_events) {
  return sizeof(ShaderEventHeader) +
         sizeof(ShaderEventRecord) * static_cast<size_t>(std::max(max_events, 0));
}

Trace shader_trace(const unsigned char* buffer, int max_events) {
  ShaderEventHeader header;
  std::memcpy(&header, buffer, sizeof header);
  std::vector<kernel::KernelEvent> events;
  for (int k = 0; k < std::min(header.count, max_events); ++k) {
    ShaderEventRecord e;
    std::memcpy(&e, buffer + sizeof header + sizeof e * static_cast<size_t>(k), sizeof e);
    events.push_back({e.kind[0], e.kind[1], e.kind[2], e.kind[3], e.more[0], e.more[1],
                      static_cast<double>(e.at[3]), glm::dvec3(e.at[0], e.at[1], e.at[2])});
  }
  return kernel_trace(events, header.steps);
}

const char* const kKernelShapeHelp =
    "auto, software or gpu: the kernel shaped for a software rasteriser (a fragment shader "
    "whose loops test at their end, rare work out of branches) or for a GPU (a compute shader, "
    "loops testing first); auto: software on llvmpipe and lavapipe, gpu on a GPU";

}  // namespace flatmarch

namespace flatmarch {

MarchParams ExternalInfo::marches_with(MarchParams asked) const {
  for (const auto& [name, value] : fixed) {
    if (name == "eps") asked.eps = value;
    if (name == "offset") asked.offset = value;
    if (name == "max_steps") asked.max_steps = static_cast<int>(value);
    if (name == "max_distance") asked.max_distance = value;
    if (name == "omega") asked.omega = value;
  }
  return asked;
}

std::string ExternalInfo::cannot_read(const Scene& scene) const {
  const auto reads = [&](const char* format) {
    return std::find(scene_formats.begin(), scene_formats.end(), format) != scene_formats.end();
  };
  if (reads("flatmarch") || (reads("peer-app") && !scene.imported_from.empty())) return {};
  return "it reads only the web app's geometry files, and scene " + scene.name +
         " was not converted from one";
}

}  // namespace flatmarch
