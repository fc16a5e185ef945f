#include <cstdio>
#include <fstream>
#include <sstream>

#include "backends/opengl/gl_kernel.hpp"
#include "backends/opengl/opengl.hpp"
#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "kernels/compile.hpp"
#include "kernels/scene_shader.hpp"
#include "scene/load.hpp"

namespace flatmarch::cli {

void add_shader(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "shader",
      "Print the GLSL fragment shader the opengl backend runs for a scene: the kernel specialised "
      "on\n"
      "the features the scene uses, with its tables baked in as constants. The march parameters "
      "are\n"
      "baked in too (a change of method or eps is a new program). --compile "
      "compiles it\n"
      "(or a file of yours with --file) and shows any error with the lines around it.");
  struct Options {
    std::string scene, file, out;
    bool trace = false, compile = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("SCENE", o->scene, "Scene file (JSON)")->required();
  cmd->add_option("-o,--output", o->out, "Write the source here instead of to stdout");
  cmd->add_flag("--trace", o->trace, "The variant that traces one probe ray (its events)");
  cmd->add_flag("--compile", o->compile,
                "Compile it with the opengl backend (OSMesa) and report errors");
  cmd->add_option("--file", o->file,
                  "With --compile: compile this fragment shader instead of the generated one")
      ->check(CLI::ExistingFile);
  cmd->callback([o] {
    const Scene scene = load_scene(o->scene);
    MarchParams params;
    params.method = Method::analytic;
    std::string source =
        kernel::scene_fragment_shader(kernel::compile_scene<float>(scene, params), o->trace);
    if (!o->file.empty()) {
      if (!o->compile) throw UsageError("--file: goes with --compile");
      std::ifstream in(o->file, std::ios::binary);
      std::ostringstream text;
      text << in.rdbuf();
      source = text.str();
    }
    if (o->compile) {
      const OpenGlBackend backend;
      if (const Availability a = backend.availability(); !a.available)
        throw UnavailableError("backend opengl is unavailable here: " + a.reason);
      try {
        backend.compile(source);
      } catch (const gl::ShaderError& e) {
        throw UsageError(std::string(o->file.empty() ? "the generated shader" : o->file) + ": " +
                         e.what());
      }
      std::fprintf(stderr, "%s compiles (%s, %zu lines)\n",
                   o->file.empty() ? "the generated shader" : o->file.c_str(),
                   backend.renderer().c_str(),
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
