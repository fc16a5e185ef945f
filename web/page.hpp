// A scene as a self-contained web page that marches it with WebGL2 (issue 23): the kernel's
// shader (kernels/march.glsl) in GLSL ES 3.00, specialised on the scene with its tables baked in,
// the scene's camera, and the viewer's controls and walking (motion/walk.cpp) ported to the
// page's script (web/page.js). Nothing is fetched when it opens. `flatmarch export-web` writes
// it; the webgl backend (backends/webgl) loads it in headless Chromium in read-back mode.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "kernels/march_params.hpp"
#include "scene/scene.hpp"

namespace flatmarch::web {

// The floor-plan inset: the plan of `flatmarch plan` (plan/floor_plan.hpp, which the caller
// draws: the backends' side of the project cannot link it) and how a point of the scene's plane
// maps to its pixels: (origin_x + scale * x, origin_y - scale * y).
struct FloorPlan {
  std::string svg;
  double width = 0.0, height = 0.0;  // its size in pixels
  double title_height = 0.0;         // the title and summary at its top, left out of the inset
  double origin_x = 0.0, origin_y = 0.0, scale = 1.0;
};

struct PageOptions {
  // The methods the page can switch between (a shader each); the page starts with the march
  // parameters' method, which must be among them.
  std::vector<Method> methods{kKernelMethods.begin(), kKernelMethods.end()};
  // Read-back mode: the page also carries the parameters' method's shaders that draw linear
  // colour and the AOVs into float targets and trace one probe ray, and offers them to a driver
  // as window.flatmarchReadback (web/page.js).
  bool readback = false;
  // Drawn in a corner with the camera on it (M shows and hides it); none without.
  std::optional<FloorPlan> floor_plan;
};

// The page's HTML, whole.
std::string page(const Scene& scene, const MarchParams& params, const PageOptions& options = {});

}  // namespace flatmarch::web
