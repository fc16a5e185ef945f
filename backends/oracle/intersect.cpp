#include "backends/oracle/intersect.hpp"

#include <cmath>
#include <limits>

namespace flatmarch {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The ray is inside a convex solid for t in [lo, hi]; the normals are the solid's outward
// normals where the ray enters and leaves.
struct Span {
  double lo = -kInf, hi = kInf;
  Vec3 n_lo{0.0}, n_hi{0.0};
  bool empty() const { return !(lo <= hi); }
};

Span intersect_spans(const Span& a, const Span& b) {
  Span s;
  s.lo = a.lo >= b.lo ? a.lo : b.lo;
  s.n_lo = a.lo >= b.lo ? a.n_lo : b.n_lo;
  s.hi = a.hi <= b.hi ? a.hi : b.hi;
  s.n_hi = a.hi <= b.hi ? a.n_hi : b.n_hi;
  return s;
}

// The slab lo <= o[axis] + t d[axis] <= hi.
Span slab(int axis, double lo, double hi, Vec3 o, Vec3 d) {
  Span s;
  if (d[axis] == 0.0) {
    if (o[axis] < lo || o[axis] > hi) s.lo = kInf, s.hi = -kInf;
    return s;
  }
  const double ta = (lo - o[axis]) / d[axis], tb = (hi - o[axis]) / d[axis];
  Vec3 n(0.0);
  n[axis] = d[axis] > 0.0 ? -1.0 : 1.0;  // the face the ray meets first faces against it
  s.lo = std::min(ta, tb);
  s.hi = std::max(ta, tb);
  s.n_lo = n;
  s.n_hi = -n;
  return s;
}

Span box_span(Vec3 center, Vec3 half, Vec3 o, Vec3 d) {
  Span s;
  for (int axis = 0; axis < 3; ++axis)
    s = intersect_spans(s, slab(axis, center[axis] - half[axis], center[axis] + half[axis], o, d));
  return s;
}

// Roots of a t^2 + 2 b t + c = 0 in increasing order, computed without cancellation.
bool quadratic(double a, double b, double c, double& t0, double& t1) {
  const double disc = b * b - a * c;
  if (disc < 0.0) return false;
  const double q = -(b + std::copysign(std::sqrt(disc), b));
  if (q == 0.0) {
    t0 = t1 = 0.0;  // b == 0 and c == 0: the ray touches at its origin
    return true;
  }
  t0 = q / a;
  t1 = c / q;
  if (t0 > t1) std::swap(t0, t1);
  return true;
}

Span sphere_span(Vec3 center, double r, Vec3 o, Vec3 d) {
  Span s;
  const Vec3 oc = o - center;
  if (!quadratic(glm::dot(d, d), glm::dot(oc, d), glm::dot(oc, oc) - r * r, s.lo, s.hi)) {
    s.lo = kInf, s.hi = -kInf;
    return s;
  }
  s.n_lo = (o + s.lo * d - center) / r;
  s.n_hi = (o + s.hi * d - center) / r;
  return s;
}

Span cylinder_span(Vec2 axis, double r, double z0, double z1, Vec3 o, Vec3 d) {
  Span radial;
  const Vec2 oc = Vec2(o) - axis, dh = Vec2(d);
  const double a = glm::dot(dh, dh), c = glm::dot(oc, oc) - r * r;
  if (a == 0.0) {
    if (c > 0.0) radial.lo = kInf, radial.hi = -kInf;
  } else if (quadratic(a, glm::dot(oc, dh), c, radial.lo, radial.hi)) {
    radial.n_lo = Vec3((oc + radial.lo * dh) / r, 0.0);
    radial.n_hi = Vec3((oc + radial.hi * dh) / r, 0.0);
  } else {
    radial.lo = kInf, radial.hi = -kInf;
  }
  return intersect_spans(radial, slab(2, z0, z1, o, d));
}

// The first point of the span in [t0, t1]; a ray that starts inside hits at t0, facing itself.
std::optional<SolidHit> first_hit(const Span& s, Vec3 d, double t0, double t1) {
  if (s.empty() || s.hi < t0 || s.lo > t1) return std::nullopt;
  if (s.lo >= t0) return SolidHit{s.lo, s.n_lo};
  return SolidHit{t0, -d};
}

}  // namespace

std::optional<SolidHit> intersect_cylinder(Vec2 axis, double radius, double z0, double z1, Vec3 o,
                                           Vec3 d, double t0, double t1) {
  return first_hit(cylinder_span(axis, radius, z0, z1, o, d), d, t0, t1);
}

std::optional<SolidHit> intersect(const Object& object, Vec3 o, Vec3 d, double t0, double t1,
                                  double lift) {
  const Vec3 c = object.center + Vec3(0.0, 0.0, lift);
  switch (object.type) {
    case ObjectType::sphere:
      return first_hit(sphere_span(c, object.radius, o, d), d, t0, t1);
    case ObjectType::box:
      return first_hit(box_span(c, object.half, o, d), d, t0, t1);
    case ObjectType::cylinder:
      return intersect_cylinder(Vec2(c), object.radius, object.z0 + lift, object.z1 + lift, o, d,
                                t0, t1);
    case ObjectType::hollow_cube: {
      // CSG difference: the cube's span minus the open span of the sphere, which leaves at most
      // two pieces, before and after the hole.
      const Span cube = box_span(c, Vec3(object.size), o, d);
      const Span hole = sphere_span(c, object.hole, o, d);
      if (hole.empty()) return first_hit(cube, d, t0, t1);
      Span before = cube, after = cube;
      if (hole.lo < before.hi) before.hi = hole.lo, before.n_hi = -hole.n_lo;
      if (hole.hi > after.lo) after.lo = hole.hi, after.n_lo = -hole.n_hi;
      if (auto hit = first_hit(before, d, t0, t1)) return hit;
      return first_hit(after, d, t0, t1);
    }
  }
  return std::nullopt;
}

}  // namespace flatmarch
