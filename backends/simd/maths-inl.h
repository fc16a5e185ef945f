// The kernel's per-lane maths (kernels/maths.glsl) on packets of rays: GLSL's types as vectors of
// lanes, one ray per lane, and the built-ins the maths calls, each the one Highway operation
// that computes what GLM computes for one ray (so a lane's result is the scalar backend's, bit
// for bit, with no fused multiply-add). lane::glue_point, lane::solid_sdf, ... are then
// kernels/maths.glsl's functions, for whole packets.

// Per-target include guard: this file is included once per instruction set (hwy/foreach_target.h
// re-includes packet.cpp for each), so the guard toggles with HWY_TARGET_TOGGLE.
#if defined(FLATMARCH_BACKENDS_SIMD_MATHS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef FLATMARCH_BACKENDS_SIMD_MATHS_INL_H_
#undef FLATMARCH_BACKENDS_SIMD_MATHS_INL_H_
#else
#define FLATMARCH_BACKENDS_SIMD_MATHS_INL_H_
#endif

#include <hwy/highway.h>

#include "backends/simd/lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace flatmarch::simd {
namespace HWY_NAMESPACE {
namespace lane {

// A condition per lane.
struct lane_bool {
  M m;
};
// A number per lane; from a float, the same number in every lane.
struct real {
  V v;
  HWY_INLINE real(V x) : v(x) {}             // NOLINT(google-explicit-constructor)
  HWY_INLINE real(float x) : v(Splat(x)) {}  // NOLINT(google-explicit-constructor)
};
struct vec4 {
  real x, y, z, w;
};
struct vec3 {
  real x, y, z;
  HWY_INLINE vec3(real a, real b, real c) : x(a), y(b), z(c) {}
  HWY_INLINE explicit vec3(real a) : x(a), y(a), z(a) {}
  HWY_INLINE explicit vec3(const vec4& a) : x(a.x), y(a.y), z(a.z) {}
};
struct vec2 {
  real x, y;
  HWY_INLINE vec2(real a, real b) : x(a), y(b) {}
  HWY_INLINE explicit vec2(real a) : x(a), y(a) {}
  HWY_INLINE explicit vec2(const vec3& a) : x(a.x), y(a.y) {}
};

// A record of the tables or the camera, the same in every lane.
HWY_INLINE vec4 Broadcast(const glm::vec4& a) {
  return {real(a.x), real(a.y), real(a.z), real(a.w)};
}
HWY_INLINE vec3 Broadcast(const glm::vec3& a) {
  return {real(a.x), real(a.y), real(a.z)};
}

HWY_INLINE real operator+(real a, real b) {
  return a.v + b.v;
}
HWY_INLINE real operator-(real a, real b) {
  return a.v - b.v;
}
HWY_INLINE real operator*(real a, real b) {
  return a.v * b.v;
}
HWY_INLINE real operator/(real a, real b) {
  return a.v / b.v;
}
HWY_INLINE real operator-(real a) {
  return hn::Neg(a.v);
}
HWY_INLINE lane_bool operator>(real a, real b) {
  return {a.v > b.v};
}
HWY_INLINE lane_bool operator>=(real a, real b) {
  return {a.v >= b.v};
}
HWY_INLINE lane_bool operator<(real a, real b) {
  return {a.v < b.v};
}
HWY_INLINE lane_bool operator<=(real a, real b) {
  return {a.v <= b.v};
}
// GLSL's logic on conditions per lane. Both sides are computed (no short circuit), as maths.glsl
// expects of every choice.
HWY_INLINE lane_bool operator&&(lane_bool a, lane_bool b) {
  return {hn::And(a.m, b.m)};
}
HWY_INLINE lane_bool operator||(lane_bool a, lane_bool b) {
  return {hn::Or(a.m, b.m)};
}
HWY_INLINE lane_bool operator!(lane_bool a) {
  return {hn::Not(a.m)};
}

HWY_INLINE vec2 operator+(const vec2& a, const vec2& b) {
  return {a.x + b.x, a.y + b.y};
}
HWY_INLINE vec2 operator-(const vec2& a, const vec2& b) {
  return {a.x - b.x, a.y - b.y};
}
HWY_INLINE vec2 operator*(real s, const vec2& a) {
  return {s * a.x, s * a.y};
}
HWY_INLINE vec3 operator+(const vec3& a, const vec3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
HWY_INLINE vec3 operator-(const vec3& a, const vec3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
HWY_INLINE vec3 operator+(real s, const vec3& a) {
  return {s + a.x, s + a.y, s + a.z};
}
HWY_INLINE vec3 operator*(real s, const vec3& a) {
  return {s * a.x, s * a.y, s * a.z};
}
HWY_INLINE vec3 operator*(const vec3& a, real s) {
  return {a.x * s, a.y * s, a.z * s};
}

// GLSL's built-ins, as GLM computes them.
HWY_INLINE real sqrt(real a) {
  return hn::Sqrt(a.v);
}
HWY_INLINE real abs(real a) {
  return hn::Abs(a.v);
}
HWY_INLINE real min(real a, real b) {
  return hn::Min(a.v, b.v);
}
HWY_INLINE real max(real a, real b) {
  return hn::Max(a.v, b.v);
}
HWY_INLINE real clamp(real a, real lo, real hi) {  // GLM: min(max(a, lo), hi)
  return min(max(a, lo), hi);
}
HWY_INLINE real floor(real a) {
  return hn::Floor(a.v);
}
HWY_INLINE real mod(real a, real b) {  // GLM: a - b * floor(a / b)
  return a - b * floor(a / b);
}
HWY_INLINE vec2 max(const vec2& a, const vec2& b) {
  return {max(a.x, b.x), max(a.y, b.y)};
}
HWY_INLINE vec3 max(const vec3& a, const vec3& b) {
  return {max(a.x, b.x), max(a.y, b.y), max(a.z, b.z)};
}
HWY_INLINE vec3 abs(const vec3& a) {
  return {abs(a.x), abs(a.y), abs(a.z)};
}
HWY_INLINE real dot(const vec2& a, const vec2& b) {
  return a.x * b.x + a.y * b.y;
}
HWY_INLINE real dot(const vec3& a, const vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
HWY_INLINE real length(const vec2& a) {
  return sqrt(dot(a, a));
}
HWY_INLINE real length(const vec3& a) {
  return sqrt(dot(a, a));
}
HWY_INLINE vec3 normalize(const vec3& a) {  // GLM: a * inversesqrt(dot(a, a))
  return a * (real(1.0f) / sqrt(dot(a, a)));
}
HWY_INLINE lane_bool select(lane_bool c, lane_bool a, lane_bool b) {
  return {hn::Or(hn::And(c.m, a.m), hn::AndNot(c.m, b.m))};
}
HWY_INLINE real select(lane_bool c, real a, real b) {
  return Select(c.m, a.v, b.v);
}
HWY_INLINE vec3 select(lane_bool c, const vec3& a, const vec3& b) {
  return {select(c, a.x, b.x), select(c, a.y, b.y), select(c, a.z, b.z)};
}

#undef KINLINE
#define KINLINE FLATMARCH_PACKET_INLINE
#include "kernels/maths.glsl"
#undef KINLINE
#define KINLINE inline

}  // namespace lane

// (x, y, z) scaled to length 1: lane::normalize on three vectors.
HWY_INLINE void Normalize(V& x, V& y, V& z) {
  const lane::vec3 n = lane::normalize(lane::vec3(x, y, z));
  x = n.x.v;
  y = n.y.v;
  z = n.z.v;
}

// The rays of `m` at a glued wall or mirror, about to cross it, pass its seam where they are near
// one of its vertical edges, its top or its bottom (march.glsl's seam_ray; the caller checks that
// the look has seams): `line` and `seam` are the edge table's.
HWY_INLINE void Seam(Packet& r, M m, const KernelParams& params, const lane::vec4& line,
                     const lane::vec4& seam) {
  const lane::real kind =
      lane::seam_kind(lane::vec3(r.ox, r.oy, r.oz), line, seam,
                      lane::real(0.5f) * lane::real(params.seams.x) * lane::real(r.t), params.top);
  // Most crossings pass no seam, and a seam of kind 0 leaves the light as it is, bit for bit.
  if (hn::AllFalse(D(), hn::And(m, kind.v > Splat(0.0f)))) return;
  const lane::real a = lane::seam_opacity(kind, lane::Broadcast(params.seams));
  const lane::vec3 colour =
      lane::fogged(lane::seam_colour(kind, lane::Broadcast(params.seam_colour),
                                     lane::Broadcast(params.cone_colour)),
                   lane::vec3(lane::Broadcast(params.fog)), r.t, params.fog_distance);
  const lane::vec3 light = lane::tint_light(lane::vec3(r.lr, r.lg, r.lb), r.clear, a, colour);
  r.lr = Select(m, light.x.v, r.lr);
  r.lg = Select(m, light.y.v, r.lg);
  r.lb = Select(m, light.z.v, r.lb);
  r.clear = Select(m, (lane::real(r.clear) * (lane::real(1.0f) - a)).v, r.clear);
}

// The rays of `m` cross a glued wall or mirror of tint `tint` (the edge table's) whose outward
// unit normal is n: march.glsl's cross_edge mixes its colour, fogged, into what they see.
HWY_INLINE void Tint(Packet& r, M m, const KernelParams& params, const lane::vec4& tint,
                     lane::real cosine) {
  const lane::real a = lane::wall_opacity(tint.w, cosine);
  const lane::vec3 colour = lane::fogged(lane::vec3(tint), lane::vec3(lane::Broadcast(params.fog)),
                                         r.t, params.fog_distance);
  const lane::vec3 light = lane::tint_light(lane::vec3(r.lr, r.lg, r.lb), r.clear, a, colour);
  r.lr = Select(m, light.x.v, r.lr);
  r.lg = Select(m, light.y.v, r.lg);
  r.lb = Select(m, light.z.v, r.lb);
  r.clear = Select(m, (lane::real(r.clear) * (lane::real(1.0f) - a)).v, r.clear);
}
// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace flatmarch::simd
HWY_AFTER_NAMESPACE();

#endif  // FLATMARCH_BACKENDS_SIMD_MATHS_INL_H_
