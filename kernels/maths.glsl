// The kernel's per-lane maths: what march.glsl computes for one ray from numbers it has already
// read, with no table reads, loops or branches on the ray's values. Written once and compiled
// three ways:
//   GLSL           real is float, lane_bool is bool (kernels/shader_prelude.glsl);
//   C++ with GLM   inside Kernel<real> (kernels/kernel.hpp, kernels/glsl.hpp), for the scalar
//                  backend in float and double;
//   Highway        real, vec2, vec3, vec4 and lane_bool are vectors of lanes, one ray per lane
//                  (backends/simd/maths-inl.h), for the SIMD backend.
// So the SIMD backend takes the scalar backend's steps by construction: the same operations in
// the same order. A choice that depends on the ray is select(c, a, b): a ternary in GLSL and C++,
// a blend of lanes on packets (both sides are computed; they must be safe to compute, and a
// division by zero or a square root of a negative number is, its lane discarded). A choice on
// a value that is the same for every lane of a packet (a solid's kind) may be an `if`.
//
// Not here: the maths of a room's step (distance to the walls and the crossing test, the exit
// edge's parameters, the band exit, a ray's entry into a solid's bounding sphere). Written over these packet types they made the SIMD backend
// 15-37% slower (the L-shape's analytic frame 11.2 -> 15.3 ms, 2 cores, AVX2; why was not found),
// so march.glsl and backends/simd/walls-inl.h each spell them out, and tests/simd_test.cpp holds
// them to the same bits. KINLINE marks each function to be inlined where the compiler would not on its own (on packets: each is
// a handful of vector operations, and a call would pass its vectors through memory).

// The camera's unit ray through the image point (x, y), in pixels from the top left corner of an
// image `size` pixels wide and high (DESIGN.md section 2): forward, right and up are the camera's
// basis, tan_half_fov the tangent of half its vertical field of view, aspect width / height.
KINLINE vec3 camera_ray(vec3 forward, vec3 right, vec3 up, real tan_half_fov, real aspect,
                        vec2 at, vec2 size) {
  real u = (real(2) * at.x / size.x - real(1)) * aspect * tan_half_fov;
  real v = (real(1) - real(2) * at.y / size.y) * tan_half_fov;
  return normalize(forward + u * right + v * up);
}

// Moves p along the normal of an edge's line so that it lies `inside` within it (negative:
// beyond it). line: the unit normal (x, y) and offset (z) of the edge's line.
KINLINE vec2 place(vec2 p, vec4 line, real inside) {
  vec2 n = vec2(line.x, line.y);
  return p - (dot(p, n) - line.z + inside) * n;
}

// A direction d reflected by a mirror along the line `line` (unit normal x, y).
KINLINE vec2 mirror_direction(vec2 d, vec4 line) {
  vec2 n = vec2(line.x, line.y);
  return d - real(2) * dot(d, n) * n;
}

// A gluing's map (DESIGN.md section 1) applied to a point: the linear part m (columns (x, y) and
// (z, w)), then the shift (x, y).
KINLINE vec2 glue_point(vec4 m, vec4 shift, vec2 p) {
  return vec2(m.x * p.x + m.z * p.y, m.y * p.x + m.w * p.y) + vec2(shift.x, shift.y);
}

// ... and to a direction: the linear part only.
KINLINE vec2 glue_direction(vec4 m, vec2 d) {
  return vec2(m.x * d.x + m.z * d.y, m.y * d.x + m.w * d.y);
}

// Signed distance from p to a solid of kind `solid` centred at c, of size `shape` (the paper's
// SDFs; kernels/tables.glsl's ObjectRecord says what shape holds per kind).
KINLINE real solid_sdf(int solid, vec3 c, vec4 shape, vec3 p) {
  vec3 q = p - c;
  if (solid == kSolidSphere) return length(q) - shape.x;
  if (solid == kSolidCylinder) {
    vec2 w = vec2(length(vec2(q)) - shape.x, abs(q.z) - shape.y);
    return min(max(w.x, w.y), real(0)) + length(max(w, vec2(real(0))));
  }
  vec3 w = abs(q) - vec3(shape);
  real box = length(max(w, vec3(real(0)))) + min(max(w.x, max(w.y, w.z)), real(0));
  if (solid == kSolidBox) return box;
  return max(box, shape.w - length(q));  // hollow cube: the cube minus the sphere
}

// The solid's unit normal at p: the gradient of its distance by central differences on a
// tetrahedron of size h.
KINLINE vec3 solid_gradient(int solid, vec3 c, vec4 shape, vec3 p, real h) {
  vec3 a = vec3(real(1), real(-1), real(-1));
  vec3 b = vec3(real(-1), real(-1), real(1));
  vec3 f = vec3(real(-1), real(1), real(-1));
  vec3 e = vec3(real(1), real(1), real(1));
  return normalize(a * solid_sdf(solid, c, shape, p + h * a) +
                   b * solid_sdf(solid, c, shape, p + h * b) +
                   f * solid_sdf(solid, c, shape, p + h * f) +
                   e * solid_sdf(solid, c, shape, p + h * e));
}

// A solid's own colour when it has one (w > 0), else its normal's (DESIGN.md section 1).
KINLINE vec3 solid_surface(vec4 color, vec3 normal) {
  return select(color.w > real(0), vec3(color), real(0.5) + real(0.5) * normal);
}
