// The GLSL side of the kernel's subset (see kernels/glsl.hpp) and the bindings of the compiled
// scene's tables; shader_source() puts it between the tables' definitions and the kernel.
#define INOUT(T) inout T

layout(std430, binding = 0) readonly buffer PolygonTable { ivec4 polygons[]; };
layout(std430, binding = 1) readonly buffer EdgeTable { EdgeRecord edges[]; };
layout(std430, binding = 2) readonly buffer ObjectTable { ObjectRecord objects[]; };
layout(std140, binding = 3) uniform ParamBlock { KernelParams params; };

// Shaders keep no transport trace.
void record_event(int kind, int polygon, int edge, int to_polygon, int to_edge, int object,
                  real t, vec3 at) {}
