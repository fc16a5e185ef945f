// A scene as a self-contained web page that marches it with WebGL2 (issue 23): the kernel's
// shader (kernels/march.glsl) in GLSL ES 3.00, specialised on the scene with its tables baked in,
// the scene's camera, and the viewer's controls and walking (viewer/walk.cpp) ported to the
// page's script (web/page.js). Nothing is fetched when it opens. `flatmarch export-web` writes
// it; the webgl backend (backends/webgl) loads it in headless Chromium in read-back mode.
#pragma once

#include <string>
#include <vector>

#include "kernels/march_params.hpp"
#include "scene/scene.hpp"

namespace flatmarch::web {

struct PageOptions {
  // The methods the page can switch between (a shader each); the page starts with the march
  // parameters' method, which must be among them.
  std::vector<Method> methods{kKernelMethods.begin(), kKernelMethods.end()};
  // Read-back mode: the page also carries the parameters' method's shaders that draw linear
  // colour and the AOVs into float targets and trace one probe ray, and offers them to a driver
  // as window.flatmarchReadback (web/page.js).
  bool readback = false;
};

// The page's HTML, whole.
std::string page(const Scene& scene, const MarchParams& params, const PageOptions& options = {});

}  // namespace flatmarch::web
