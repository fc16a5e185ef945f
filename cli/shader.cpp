#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "backends/backend.hpp"
#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "kernels/shader_log.hpp"
#include "scene/load.hpp"

namespace flatmarch::cli {

namespace {

// The backends that run a GLSL shader of their own (BackendEntry::shader), in the registry's order.
std::vector<std::string> shader_backends() {
  std::vector<std::string> names;
  for (const BackendEntry& e : backend_registry())
    if (e.shader) names.push_back(e.name);
  return names;
}

}  // namespace

void add_shader(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "shader",
      "Print the GLSL shader a GPU backend runs for a scene's whole frames: the opengl backend's\n"
      "fragment shader (--kernel-shape software) or compute shader (gpu), or the vulkan backend's\n"
      "compute shader (--backend vulkan), the kernel specialised on the features the scene uses,\n"
      "with its tables baked in as constants (a scene of several rooms: read from a storage\n"
      "buffer, binding 6, which the backend fills). The march parameters are baked in either way\n"
      "(a change of method or eps is a new program). --compile compiles it (or a file of yours\n"
      "with --file) and shows any error with the lines around it.");
  struct Options {
    std::string scene, file, out, backend, shape = "software";
    bool trace = false, compile = false;
  };
  auto o = std::make_shared<Options>();
  const std::vector<std::string> backends = shader_backends();
  if (!backends.empty()) o->backend = backends.front();
  cmd->add_option("SCENE", o->scene, kSceneArgumentHelp)->required();
  cmd->add_option("-o,--output", o->out, "Write the source here instead of to stdout");
  cmd->add_flag("--trace", o->trace, "The variant that traces one probe ray (its events)");
  cmd->add_option("--backend", o->backend,
                  "The backend whose shader (this build's: " +
                      (backends.empty() ? std::string("none") : joined(backends)) +
                      "): opengl's fragment shader, vulkan's compute shader")
      ->capture_default_str();
  cmd->add_flag("--compile", o->compile,
                "Compile it with that backend (OSMesa's driver; glslang and the Vulkan device) and "
                "report errors");
  cmd->add_option("--kernel-shape", o->shape,
                  "software or gpu: the kernel shaped for a software rasteriser or a GPU (the "
                  "backends' --kernel-shape; auto picks by the device)")
      ->capture_default_str();
  cmd->add_option("--file", o->file,
                  "With --compile: compile this shader (of the same stage) instead of the "
                  "generated one")
      ->check(CLI::ExistingFile);
  cmd->callback([o, backends] {
    const Scene scene = load_named_scene(o->scene);
    MarchParams params;
    params.method = Method::analytic;
    if (backends.empty())
      throw UnavailableError(
          "shader: this flatmarch was built without a backend that runs a shader of its own "
          "(FLATMARCH_WITH_OPENGL and FLATMARCH_WITH_VULKAN are OFF)");
    const BackendEntry* entry = find_backend_entry(o->backend);
    if (!entry || !entry->shader)
      throw UsageError("--backend: expected one of " + joined(backends) + ", got \"" + o->backend +
                       "\"");
    if (o->shape != "software" && o->shape != "gpu")
      throw UsageError("--kernel-shape: expected software or gpu, got \"" + o->shape + "\"");
    const ShaderRequest request{
        .trace = o->trace, .shape = o->shape == "gpu" ? KernelShape::gpu : KernelShape::software};
    std::string source = entry->shader(scene, params, request);
    if (!o->file.empty()) {
      if (!o->compile) throw UsageError("--file: goes with --compile");
      std::ifstream in(o->file, std::ios::binary);
      std::ostringstream text;
      text << in.rdbuf();
      source = text.str();
    }
    if (o->compile) {
      const std::unique_ptr<Backend> backend = entry->make({});
      if (const Availability a = backend->availability(); !a.available)
        throw UnavailableError("backend " + o->backend + " is unavailable here: " + a.reason);
      std::string compiler;
      try {
        compiler = entry->compile_shader(*backend, source, request);
      } catch (const kernel::ShaderError& e) {
        throw UsageError(std::string(o->file.empty() ? "the generated shader" : o->file) + ": " +
                         e.what());
      }
      std::fprintf(stderr, "%s compiles (%s, %zu lines)\n",
                   o->file.empty() ? "the generated shader" : o->file.c_str(), compiler.c_str(),
                   static_cast<size_t>(std::count(source.begin(), source.end(), '\n')));
      if (!o->file.empty()) return;
    }
    if (o->out.empty()) {
      std::fwrite(source.data(), 1, source.size(), stdout);
      return;
    }
    std::ofstream out(o->out, std::ios::binary);
    out << source;
    if (!out.flush()) throw UsageError("--output: cannot write " + o->out);
  });
}

}  // namespace flatmarch::cli
