#include "backends/backend.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "backends/kernel_trace.hpp"
#include "backends/opengl/opengl.hpp"
#include "backends/oracle/oracle.hpp"
#include "backends/scalar/scalar.hpp"
#include "backends/simd/simd.hpp"
#include "backends/vulkan/vulkan.hpp"
#include "backends/webgl/webgl.hpp"

namespace flatmarch {

namespace {

constexpr std::array<std::pair<EventKind, const char*>, 11> kEventKinds{
    {{EventKind::gluing, "gluing"},
     {EventKind::mirror, "mirror"},
     {EventKind::enter, "enter"},
     {EventKind::object, "object"},
     {EventKind::wall, "wall"},
     {EventKind::floor, "floor"},
     {EventKind::escape, "escape"},
     {EventKind::vertex, "vertex"},
     {EventKind::max_steps, "max_steps"},
     {EventKind::max_distance, "max_distance"},
     {EventKind::miss, "miss"}}};

template <typename E, size_t N>
const char* name_of(const std::array<std::pair<E, const char*>, N>& table, E value) {
  for (const auto& [v, name] : table)
    if (v == value) return name;
  return "?";
}

}  // namespace

const char* to_string(EventKind k) {
  return name_of(kEventKinds, k);
}

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

namespace {

constexpr const char* kKernelShapeHelp =
    "auto, software or gpu: the kernel shaped for a software rasteriser (a fragment shader "
    "whose loops test at their end, rare work out of branches) or for a GPU (a compute shader, "
    "loops testing first); auto: software on llvmpipe and lavapipe, gpu on a GPU";

std::vector<BackendEntry>& registry() {
  static std::vector<BackendEntry> entries{
      {.name = "oracle",
       .kernel = false,
       .reference_for = "the true image and every ray's path (exact, analytic)",
       .make = [](const BackendOptions&) { return std::make_unique<OracleBackend>(); }},
      {.name = "scalar",
       .reference_for = "the kernel's steps: the other kernel backends' traces and frames are "
                        "compared with its",
       .make = [](const BackendOptions&) { return std::make_unique<ScalarBackend>(); }},
      {.name = "simd",
       .make = [](const BackendOptions& o) { return std::make_unique<SimdBackend>(o); },
       .variants =
           [] {
             std::vector<std::pair<std::string, BackendOptions>> v;
             for (const std::string& isa : simd::isa_names(false))
               v.push_back({isa, BackendOptions{.isa = isa}});
             return v;
           },
       .options = {{"--isa", &BackendOptions::isa,
                    "the instruction set, one of those `flatmarch backends` lists (default: the "
                    "best this CPU runs)"},
                   {"--threads", &BackendOptions::threads, "worker threads (0: all cores)"}}},
      {.name = "opengl",
       .make = [](const BackendOptions& o) { return std::make_unique<OpenGlBackend>(o); },
       .options = {{"--device", &BackendOptions::device,
                    "the device, by its index or a part of its name as `flatmarch backends` "
                    "lists them (default: a GPU, else the CPU: llvmpipe through EGL, then "
                    "OSMesa)"},
                   {"--kernel-shape", &BackendOptions::kernel_shape, kKernelShapeHelp}}},
      {.name = "vulkan",
       .make = [](const BackendOptions& o) { return std::make_unique<VulkanBackend>(o); },
       .options = {{"--device", &BackendOptions::device,
                    "likewise "
                    "(default: a discrete, integrated or virtual GPU, else lavapipe)"},
                   {"--vk-staging", &BackendOptions::vk_staging,
                    "read frames back through a staging buffer, as on a discrete GPU, even where "
                    "the device's memory is host-visible"},
                   {"--kernel-shape", &BackendOptions::kernel_shape, "likewise"}}},
      {.name = "webgl",
       .make = [](const BackendOptions& o) { return std::make_unique<WebGlBackend>(o); },
       .options = {{"--device", &BackendOptions::device,
                    "gpu or swiftshader (default: Chromium's choice, a GPU where it can "
                    "use one, else SwiftShader)"},
                   {"--kernel-shape", &BackendOptions::kernel_shape,
                    "likewise, the page's shader (auto: by the browser's renderer)"}}},
  };
  return entries;
}

bool backends_made = false;  // backends() has made its list: the registry is closed

}  // namespace

const std::vector<BackendEntry>& backend_registry() {
  return registry();
}

bool register_backend(BackendEntry entry) {
  if (backends_made)
    throw std::logic_error("register_backend(" + entry.name + "): after backends() was called");
  for (const BackendEntry& e : registry())
    if (e.name == entry.name)
      throw std::logic_error("register_backend: a backend named " + entry.name + " exists");
  registry().push_back(std::move(entry));
  return true;
}

std::vector<std::string> backend_names() {
  std::vector<std::string> names;
  for (const BackendEntry& e : registry()) names.push_back(e.name);
  return names;
}

std::vector<std::string> kernel_backend_names() {
  std::vector<std::string> names;
  for (const BackendEntry& e : registry())
    if (e.kernel) names.push_back(e.name);
  return names;
}

const BackendEntry* find_backend_entry(const std::string& name) {
  for (const BackendEntry& e : registry())
    if (e.name == name) return &e;
  return nullptr;
}

std::unique_ptr<Backend> make_backend(const std::string& name, const BackendOptions& options) {
  for (const BackendEntry& e : registry())
    if (e.name == name) return e.make(options);
  return nullptr;
}

const std::vector<std::unique_ptr<Backend>>& backends() {
  static const std::vector<std::unique_ptr<Backend>> all = [] {
    backends_made = true;
    std::vector<std::unique_ptr<Backend>> v;
    for (const BackendEntry& e : registry()) v.push_back(e.make({}));
    return v;
  }();
  return all;
}

const Backend* find_backend(const std::string& name) {
  for (const auto& b : backends())
    if (b->name() == name) return b.get();
  return nullptr;
}

}  // namespace flatmarch
