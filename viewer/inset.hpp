// The floor-plan inset drawn in a corner of the viewer: the polygons laid out as `flatmarch
// plan` lays them out (plan/floor_plan.hpp's PlanLayout), glued edges, mirrors and walls in three
// colours, the camera's polygon outlined brighter, the camera a dot with a line along its
// heading. Built as coloured triangles in window pixels; the viewer draws them.
#pragma once

#include <vector>

#include "scene/scene.hpp"

namespace flatmarch::viewer {

struct InsetVertex {
  float x, y;     // window pixels, y down from the top left corner
  float r, g, b;  // sRGB, as drawn
};

// The inset's box in window pixels: its top left corner and size.
struct InsetBox {
  double x = 0.0, y = 0.0, width = 0.0, height = 0.0;
};

// Where the inset goes in a window of this size: the top right corner, a quarter of the width
// at most, shaped like the plan.
InsetBox inset_box(const Scene& scene, int window_width, int window_height);

// The inset's triangles: a backdrop filling `box`, then the plan.
std::vector<InsetVertex> inset_triangles(const Scene& scene, const Camera& camera,
                                         const InsetBox& box);

}  // namespace flatmarch::viewer
