#include <chrono>
#include <cstdio>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "output/image_io.hpp"
#include "scene/load.hpp"

namespace flatmarch::cli {

void add_render(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "render",
      "Render a scene: the colour as an sRGB PNG and, beside it, a float EXR with the AOVs\n"
      "R, G, B (linear), steps, crossings, hit, t (DESIGN.md section 4).");
  struct Options {
    std::string scene, out, size = "640x360";
    bool quiet = false, show_failures = false;
    MarchOptions march;
    CameraOptions camera;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("SCENE", o->scene, kSceneArgumentHelp)->required();
  cmd->add_option("-o,--output", o->out, "Output PNG; the EXR goes beside it")->required();
  cmd->add_option("--size", o->size, "Image size WxH")->capture_default_str();
  cmd->add_flag("-q,--quiet", o->quiet, "No progress or summary on stderr");
  cmd->add_flag("--show-failures", o->show_failures,
                "Paint the pixels whose rays failed (max_steps, max_distance, vertex) magenta, in "
                "the PNG and the EXR's colour, rather than as the fog they are shaded as; the hit "
                "AOV says which failure each is");
  // The exact method and the fastest; the paper's sphere tracing is --method sphere.
  o->march.default_method = "analytic";
  o->march.add_to(*cmd, cpu_backend_names().front(), reference_cpu_backend());
  o->camera.add_to(*cmd);
  cmd->callback([o] {
    const auto [w, h] = parse_size("--size", o->size);
    check_frame_memory("--size", w, h, kRenderFrames, "a rendered image");
    const Backend& backend = o->march.resolve();
    const Scene scene = load_named_scene(o->scene);
    const Camera camera = o->camera.apply(scene);
    warn_about_resolution(scene, o->march.params);
    check_reach(scene, camera, o->march.params);
    const auto start = std::chrono::steady_clock::now();
    ProgressReporter progress("rendering " + scene.name + " " + o->size + " with " + backend.name(),
                              o->quiet);
    Frame frame =
        backend.render(scene, camera, w, h, o->march.params, [&](double f) { progress(f); });
    progress.done();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (o->show_failures) {
      const int failed = frame.paint_failures(Vec3(1.0, 0.0, 1.0));
      if (!o->quiet)
        std::fprintf(stderr, "%d of %d pixels failed (painted magenta)\n", failed, w * h);
    }
    write_png(frame, o->out);
    write_aov_exr(frame, aov_path(o->out));
    if (!o->quiet)
      std::fprintf(stderr, "wrote %s and %s (%dx%d, %s/%s, %.2f s)\n", o->out.c_str(),
                   aov_path(o->out).string().c_str(), w, h, backend.name().c_str(),
                   to_string(o->march.params.method), seconds);
  });
}

}  // namespace flatmarch::cli
