// Exact ray/solid intersection in float64 for every object type. Each solid is the set of ray
// parameters t where the ray is inside it; the hit is the first such t in [t0, t1].
#pragma once

#include <optional>

#include "scene/scene.hpp"

namespace flatmarch {

struct SolidHit {
  double t = 0.0;
  Vec3 normal{0.0};  // outward unit normal of the solid at the hit
};

// `o + t d` with `d` a unit vector; `lift` shifts the object up by that much (translation
// prisms intersect the copies of an object one period apart).
std::optional<SolidHit> intersect(const Object& object, Vec3 o, Vec3 d, double t0, double t1,
                                  double lift = 0.0);

// A vertical capped cylinder around `axis` from z0 to z1 (objects and vertex markers).
std::optional<SolidHit> intersect_cylinder(Vec2 axis, double radius, double z0, double z1, Vec3 o,
                                           Vec3 d, double t0, double t1);

}  // namespace flatmarch
