// The GLSL side of the kernel's subset (see kernels/glsl.hpp): shader_source() puts it between
// the tables and parameters (as buffers 0-2 and uniform block 3, or baked in as constants) and
// the kernel.
#define INOUT(T) inout T
#define FLATMARCH_SHADER

// A condition per ray, and the choice it makes (kernels/maths.glsl).
#define lane_bool bool
#define KINLINE
bool select(bool c, bool a, bool b) {
  return c ? a : b;
}
real select(bool c, real a, real b) {
  return c ? a : b;
}
vec3 select(bool c, vec3 a, vec3 b) {
  return c ? a : b;
}

#if defined(FLATMARCH_TRACE) || defined(FLATMARCH_TRACE_PICK)
struct EventRecord {
  ivec4 kind;  // kind, polygon, edge, to_polygon
  ivec4 more;  // to_edge, object, 0, 0
  vec4 at;     // the point (xyz) and t (w)
};
#endif

#ifdef FLATMARCH_TRACE
// A probe ray's transport trace: one invocation marches it and appends its events here.
layout(std430, binding = 4) buffer EventBuffer {
  int event_count;
  int max_events;
  int trace_steps;
  int trace_pad;
  EventRecord trace_events[];
};
void record_event(int kind, int polygon, int edge, int to_polygon, int to_edge, int object,
                  real t, vec3 at) {
  if (event_count < max_events) {
    trace_events[event_count] = EventRecord(ivec4(kind, polygon, edge, to_polygon),
                                            ivec4(to_edge, object, 0, 0), vec4(at, t));
  }
  event_count += 1;
}
#elif defined(FLATMARCH_TRACE_PICK)
// WebGL2 has no storage buffers: each fragment marches the probe ray and keeps one event, the
// trace_pick-th (kernels/scene_shader.hpp, WebShader::trace).
int trace_pick = 0;
int event_count = 0;
EventRecord picked_event = EventRecord(ivec4(-1), ivec4(-1), vec4(0.0));
void record_event(int kind, int polygon, int edge, int to_polygon, int to_edge, int object,
                  real t, vec3 at) {
  if (event_count == trace_pick) {
    picked_event = EventRecord(ivec4(kind, polygon, edge, to_polygon),
                               ivec4(to_edge, object, 0, 0), vec4(at, t));
  }
  event_count += 1;
}
#else
// Frames keep no transport trace.
void record_event(int kind, int polygon, int edge, int to_polygon, int to_edge, int object,
                  real t, vec3 at) {}
#endif
