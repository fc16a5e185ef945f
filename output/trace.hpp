// A ray's transport trace (DESIGN.md section 4): the events of its path, as every backend records
// them and `flatmarch trace` writes them (trace_json.hpp).
#pragma once

#include <vector>

#include "kernels/constants.hpp"
#include "kernels/march_params.hpp"
#include "scene/geometry.hpp"

namespace flatmarch {

// One ray, in the coordinates of `polygon` (ignored when `from` lies outside every wall band).
struct Ray {
  int polygon = 0;
  Vec3 from{0.0};
  Vec3 dir{1.0, 0.0, 0.0};
};

// Events of a transport trace. `enter` (a ray from a camera outside the band entering a room)
// and `miss` (never entering one) extend DESIGN.md's list.
enum class EventKind {
  gluing,
  mirror,
  enter,
  object,
  wall,
  floor,
  escape,
  vertex,
  max_steps,
  max_distance,
  miss
};
// Its name in a trace's JSON ("gluing", ...).
const char* to_string(EventKind k);
// The kernel reports events by these numbers (kEvent*, kernels/constants.glsl).
static_assert(static_cast<int>(EventKind::gluing) == kEventGluing &&
              static_cast<int>(EventKind::enter) == kEventEnter &&
              static_cast<int>(EventKind::object) == kEventObject &&
              static_cast<int>(EventKind::vertex) == kEventVertex &&
              static_cast<int>(EventKind::miss) == kEventMiss);

struct Event {
  EventKind kind = EventKind::gluing;
  int polygon = 0;
  int edge = -1;        // gluing, mirror, wall
  int to_polygon = -1;  // gluing
  int to_edge = -1;     // gluing
  int object = -1;      // object (index in the hit AOV's numbering)
  double t = 0.0;
  Vec3 at{0.0};  // in the coordinates of `polygon`, before any map
};

struct Trace {
  std::vector<Event> events;  // the last one is final unless the trace was cut at max_events
  int steps = 0;
};

}  // namespace flatmarch
