#include <cmath>
#include <filesystem>
#include <tuple>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "scene/load.hpp"
#ifdef FLATMARCH_WITH_VIEWER
#include "viewer/controls.hpp"
#include "viewer/viewer.hpp"
#endif

namespace flatmarch::cli {

#ifndef FLATMARCH_WITH_VIEWER
// A build without the OpenGL backend has no viewer (it draws with that backend's kernel).
void add_view(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "view",
      "Walk through a scene in a window: not in this build (built without the OpenGL "
      "backend, whose kernel the viewer draws with: FLATMARCH_WITH_OPENGL=OFF)");
  cmd->allow_extras();
  cmd->callback([] {
    throw UnavailableError(
        "view: this flatmarch was built without the viewer (FLATMARCH_WITH_OPENGL=OFF: it draws "
        "with the OpenGL backend's kernel); `flatmarch export-web` makes a page to walk in "
        "instead");
  });
}
#else
void add_view(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "view",
      "Walk through a scene in a window (OpenGL 4.5), first person, as in the paper.\n"
      "  W/A/S/D move forward/left/back/right, E/Q up/down, Shift faster; the mouse looks\n"
      "  (Esc releases the cursor, a click captures it again, Esc with it released quits)\n"
      "  1/2/3 method sphere/relaxed/analytic; [ ] eps / and x 10^0.25; ; ' offset likewise\n"
      "  (offset stays above eps); - = render scale / and x sqrt(2); Tab the next scene of the\n"
      "  folder (Shift+Tab the previous); F12 a screenshot (the view at the window's size).\n"
      "The title shows the scene, polygon, method, eps, offset, scale, frame time and mean\n"
      "steps per pixel; the inset the floor plan with the camera.\n"
      "--script FILE drives it instead, one command a line, at a fixed 1/30 s a frame:\n"
      "  hold KEY SECONDS | key KEY | mouse DX DY | click | frames N | screenshot PATH |\n"
      "  state PATH (JSON: scene, polygon, position, yaw_deg, pitch_deg, method, eps, offset)\n"
      "  | # comment. KEY: a letter, digit, - = [ ] ; ' or TAB, ESCAPE, SPACE, ENTER, SHIFT,\n"
      "  F1..F12. It exits when the script ends.\n"
      "Exit codes: 2 a bad scene, argument or script line; 3 no window or OpenGL 4.5 here.");
  struct Options {
    std::string scene, size = "1280x720", method = "analytic", screenshot_dir = ".", script;
    double scale = 0.5;
    int frames = 0;
    bool quiet = false;
    MarchParams params;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("SCENE", o->scene,
                  "Scene file (JSON), or a gallery scene's name; default l_shape");
  cmd->add_option("--size", o->size, "Window size WxH")->capture_default_str();
  cmd->add_option("--scale", o->scale,
                  "Rendered resolution as a fraction of the window's, in (0, 1]; keys - and =")
      ->capture_default_str();
  cmd->add_option("--method", o->method, "Method: " + kernel_method_names() + "; keys 1, 2, 3")
      ->capture_default_str();
  add_march_param_options(
      *cmd, o->params,
      {.eps = true, .offset = true, .max_steps = true, .max_distance = false, .omega = false});
  for (const auto& [name, keys] :
       {std::pair{"--eps", "; here within [1e-7, 1e-2], keys [ and ]"},
        std::pair{"--offset", ", above eps and at most 0.5 here; keys ; and '"}}) {
    CLI::Option* option = cmd->get_option(name);
    option->description(option->get_description() + keys);
  }
  cmd->add_option("--screenshot-dir", o->screenshot_dir,
                  "Folder of F12's flatmarch-screenshot-N.png")
      ->capture_default_str();
  cmd->add_option("--script", o->script, "Run this input script instead of reading input");
  cmd->add_option("--frames", o->frames, "Stop after this many frames (0: when closed)")
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", o->quiet, "Nothing on stderr but errors");
  cmd->callback([o] {
    viewer::ViewerOptions v;
    std::tie(v.width, v.height) = parse_size("--size", o->size);
    if (!(o->scale > 0.0 && o->scale <= 1.0)) throw UsageError("--scale: must lie in (0, 1]");
    const auto method = parse_method(o->method);
    if (!method || *method == Method::oracle)
      throw UsageError("--method: expected one of " + kernel_method_names() + ", got \"" +
                       o->method + "\"");
    o->params.method = *method;
    check_march_params(o->params);
    // The keys step eps and offset within these bounds, so the viewer starts within them.
    if (!(o->params.eps >= motion::kMinEps && o->params.eps <= motion::kMaxEps))
      throw UsageError("--eps: must lie in [1e-7, 1e-2]");
    if (!(o->params.offset > o->params.eps && o->params.offset <= motion::kMaxOffset))
      throw UsageError(
          "--offset: must lie above --eps (a ray placed no further than eps from the edge it "
          "came through crosses back) and at most 0.5");
    if (o->frames < 0) throw UsageError("--frames: must be 0 or more");
    if (!std::filesystem::is_directory(o->screenshot_dir))
      throw UsageError("--screenshot-dir: " + o->screenshot_dir + " is not a folder");
    o->scene = named_scene_file(o->scene.empty() ? "l_shape" : o->scene);
    if (!o->script.empty()) {
      try {
        v.script = viewer::load_script(o->script);
      } catch (const viewer::ScriptError& e) {
        throw UsageError(e.what());
      }
      v.scripted = true;
    }
    v.scene = load_scene(o->scene);
    v.scene_file = o->scene;
    v.scale = o->scale;
    v.params = o->params;
    v.screenshot_dir = o->screenshot_dir;
    v.frames = o->frames;
    v.quiet = o->quiet;
    try {
      viewer::run(v);
    } catch (const viewer::Unavailable& e) {
      throw UnavailableError(e.what());
    }
  });
}

#endif  // FLATMARCH_WITH_VIEWER

}  // namespace flatmarch::cli
