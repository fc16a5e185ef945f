// How the viewer's camera moves through a scene: walking carries it across glued edges as a ray
// is carried (DESIGN.md section 1), turning it by each gluing's linear part, and stops it at
// mirrors, walls and vertices; looking turns it in place. Pure geometry, no graphics.
#pragma once

#include "scene/scene.hpp"

namespace flatmarch::motion {

// Distance (scene units) at which a mirror, a wall or the top and bottom of the wall band stop
// the walker, so that it never stands on them.
inline constexpr double kWalkMargin = 1e-3;
// Room segments (the path between two crossings or slides) of one walk at most: the rest of a
// longer walk is dropped, so that a walk always ends.
inline constexpr int kMaxSegments = 64;
// How far from the origin (in units of the scene's scale) a walk may take the walker in an
// unbounded room (DESIGN.md section 1, "Infinite surfaces"): a walk that would go further stops
// there. The renderers model such rooms a thousand times further out (kernel::kReach).
inline constexpr double kWalkReach = 1e6;
// Pitch is kept within this many degrees of the horizon.
inline constexpr double kMaxPitchDeg = 89.0;

struct WalkResult {
  Camera camera;
  int crossings = 0;  // glued edges crossed
  // A mirror, wall or vertex (or kMaxSegments, or kWalkReach) cut the walk short.
  bool blocked = false;
};

// Moves `camera` by `forward` and `right` horizontally, in its yaw frame (forward = (cos a,
// sin a), right = (sin a, -cos a), DESIGN.md section 2), and by `up` in z, all in the current
// polygon's coordinates.
//
// In the wall band the horizontal path is followed across glued edges: each crossing maps the
// point and the rest of the path by the edge's gluing (a similarity scales the rest) and turns
// the yaw with it, so that walking round a cone point turns the walker by 2 pi minus its angle.
// A mirror or wall stops the walker kWalkMargin before it, and the rest of the path slides along
// it; passing within 1e-6 * scene.scale of a vertex, where no crossing is defined, stops it
// kWalkMargin short along the path. z stays kWalkMargin inside the band; in a translation prism
// it is taken modulo the period instead.
//
// A camera above or below the band (as a scene may start, seeing the plan from above) moves
// freely, and comes down into the room under it, if any, when `up` takes it into the band; an
// opaque floor keeps it out from below.
//
// Throws std::invalid_argument for a camera polygon that does not exist, a non-finite camera or
// displacement, or a camera within the band but not strictly inside its polygon.
WalkResult walk(const Scene& scene, const Camera& camera, double forward, double right, double up);

// Turns `camera`: yaw by `dyaw_deg` (kept in [-180, 180]), pitch by `dpitch_deg`, clamped to
// [-kMaxPitchDeg, kMaxPitchDeg]. Throws std::invalid_argument for non-finite angles.
Camera look(const Camera& camera, double dyaw_deg, double dpitch_deg);

}  // namespace flatmarch::motion
