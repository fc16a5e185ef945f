#include <cstdio>
#include <fstream>
#include <sstream>

#include "backends/opengl/gl_kernel.hpp"
#include "backends/opengl/opengl.hpp"
#include "backends/vulkan/vulkan.hpp"
#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "kernels/compile.hpp"
#include "kernels/scene_shader.hpp"
#include "scene/load.hpp"

namespace flatmarch::cli {

void add_shader(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "shader",
      "Print the GLSL shader a GPU backend runs for a scene's whole frames: the opengl backend's\n"
      "fragment shader (--kernel-shape software) or compute shader (gpu), or the vulkan backend's\n"
      "compute shader (--backend vulkan), the kernel specialised on the features the scene uses,\n"
      "with its tables baked in as constants. The march parameters are baked in too (a change of\n"
      "method or eps is a new program). --compile compiles it (or a file of yours with --file)\n"
      "and shows any error with the lines around it.");
  struct Options {
    std::string scene, file, out, backend = "opengl", shape = "software";
    bool trace = false, compile = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("SCENE", o->scene, kSceneArgumentHelp)->required();
  cmd->add_option("-o,--output", o->out, "Write the source here instead of to stdout");
  cmd->add_flag("--trace", o->trace, "The variant that traces one probe ray (its events)");
  cmd->add_option("--backend", o->backend,
                  "opengl (a fragment shader) or vulkan (a compute shader)")
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
  cmd->callback([o] {
    const Scene scene = load_named_scene(o->scene);
    MarchParams params;
    params.method = Method::analytic;
    if (o->backend != "opengl" && o->backend != "vulkan")
      throw UsageError("--backend: expected opengl or vulkan, got \"" + o->backend + "\"");
    const bool vulkan = o->backend == "vulkan";
    if (o->shape != "software" && o->shape != "gpu")
      throw UsageError("--kernel-shape: expected software or gpu, got \"" + o->shape + "\"");
    const KernelShape shape = o->shape == "gpu" ? KernelShape::gpu : KernelShape::software;
    // The OpenGL backend's gpu shape is a compute shader too, but for its probe-ray traces.
    const bool compute = vulkan || (shape == KernelShape::gpu && !o->trace);
    const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
    const kernel::ShaderVariant variant{
        .trace = o->trace, .shape = shape, .readback = kernel::Readback::all};
    std::string source = compute ? kernel::scene_compute_shader(tables, variant,
                                                                vulkan ? kernel::ComputeApi::vulkan
                                                                       : kernel::ComputeApi::opengl)
                                 : kernel::scene_fragment_shader(tables, variant);
    if (!o->file.empty()) {
      if (!o->compile) throw UsageError("--file: goes with --compile");
      std::ifstream in(o->file, std::ios::binary);
      std::ostringstream text;
      text << in.rdbuf();
      source = text.str();
    }
    if (o->compile) {
      const OpenGlBackend opengl;
      const VulkanBackend vulkan_backend;
      const Backend& backend = vulkan ? static_cast<const Backend&>(vulkan_backend) : opengl;
      if (const Availability a = backend.availability(); !a.available)
        throw UnavailableError("backend " + o->backend + " is unavailable here: " + a.reason);
      try {
        if (vulkan)
          vulkan_backend.compile(source);
        else
          opengl.compile(source, compute);
      } catch (const kernel::ShaderError& e) {
        throw UsageError(std::string(o->file.empty() ? "the generated shader" : o->file) + ": " +
                         e.what());
      }
      std::fprintf(stderr, "%s compiles (%s, %zu lines)\n",
                   o->file.empty() ? "the generated shader" : o->file.c_str(),
                   vulkan ? vulkan_backend.description().c_str() : opengl.renderer().c_str(),
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
