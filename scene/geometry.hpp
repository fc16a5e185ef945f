// Plane geometry in float64 shared by the scene model, the oracle and the floor plans.
#pragma once

#include <glm/glm.hpp>

namespace flatmarch {

using Vec2 = glm::dvec2;
using Vec3 = glm::dvec3;
using Mat2 = glm::dmat2;  // column-major, as GLSL: Mat2(column0, column1)

inline constexpr double kPi = 3.14159265358979323846;

// z-component of the 3D cross product: > 0 when b is counterclockwise of a.
inline double cross(Vec2 a, Vec2 b) {
  return a.x * b.y - a.y * b.x;
}

// Rotation by +90 degrees.
inline Vec2 perp(Vec2 v) {
  return {-v.y, v.x};
}

// An affine map of the plane, x -> linear * x + translation.
struct Affine2 {
  Mat2 linear{1.0};
  Vec2 translation{0.0};

  Vec2 apply(Vec2 p) const { return linear * p + translation; }
  Vec2 apply_direction(Vec2 v) const { return linear * v; }
  Affine2 inverse() const {
    const Mat2 inv = glm::inverse(linear);
    return {inv, -(inv * translation)};
  }
  double determinant() const { return glm::determinant(linear); }
};

// Distance from p to the segment [a, b].
inline double distance_to_segment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const double len2 = glm::dot(ab, ab);
  const double s = len2 > 0.0 ? glm::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + s * ab));
}

}  // namespace flatmarch
