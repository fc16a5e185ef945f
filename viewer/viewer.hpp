// The interactive first-person viewer (`flatmarch view`): a GLFW window with an OpenGL 4.5 core
// context in which the OpenGL backend's kernel program (backends/opengl/gl_kernel.hpp) draws
// each frame at a fraction of the window's resolution, shown encoded to sRGB as `flatmarch
// render` encodes its PNGs, with a floor-plan inset (viewer/inset.hpp). The camera walks through
// glued walls (motion/walk.hpp). Input comes from the keyboard and mouse or from a script
// (viewer/script.hpp) through the same handlers.
//
// Controls, as in the paper's "Simulation Controls" plus the renderer's settings:
//   W/A/S/D move forward/left/back/right, E/Q up/down, Shift faster; the mouse looks (the cursor
//   is captured; Esc releases it, a click captures it again, Esc with it released quits);
//   1/2/3 method sphere/relaxed/analytic; [ and ] eps / and x 10^0.25; ; and ' offset likewise
//   (offset is kept above eps); - and = render scale / and x sqrt(2); Tab the next scene of the
//   folder (Shift+Tab the previous); F12 a screenshot.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <vector>

#include "kernels/march_params.hpp"
#include "scene/scene.hpp"
#include "viewer/script.hpp"

namespace flatmarch::viewer {

// No window with an OpenGL 4.5 core context can be opened here (no display, no GLFW, an older
// OpenGL); what() says which.
class Unavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ViewerOptions {
  Scene scene;
  std::filesystem::path scene_file;  // its folder's *.json are the scenes Tab cycles through
  int width = 1280, height = 720;    // of the window
  double scale = 0.5;                // of the rendered image, in (0, 1]
  MarchParams params;                // method sphere, relaxed or analytic; offset > eps
  std::filesystem::path screenshot_dir = ".";
  bool scripted = false;  // run `script` instead of reading the keyboard and mouse
  std::vector<ScriptStep> script;
  int frames = 0;  // > 0: stop after this many frames
  bool quiet = false;
};

// Opens the window and runs until it is closed, Esc is pressed with the cursor released, the
// script ends or the frames are drawn. Throws Unavailable as above, kernel::ShaderError for a
// kernel that does not compile, std::runtime_error for OpenGL errors and for screenshots and
// state files that cannot be written.
void run(const ViewerOptions& options);

}  // namespace flatmarch::viewer
