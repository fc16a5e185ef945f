// The appearance of DESIGN.md section 1: what colour a finished ray gives its pixel.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "kernels/hit.hpp"

namespace flatmarch {

// Light grey of opaque walls; the floor alternates it with a darker grey in unit checks.
inline constexpr double kWallGrey = 0.8;
inline constexpr double kFloorDarkGrey = 0.55;
inline constexpr double kFloorCheck = 0.5;  // side of a floor check, in scene units

// Linear colour of a pixel whose ray ended with `hit` after `crossings` gluings and mirror
// bounces. `normal` is the unit surface normal in the hit polygon's frame (objects), `at` the
// end point in that frame (floor checks), `object_color` the object's own colour if it has one.
template <typename T>
glm::vec<3, T> shade(int hit, int crossings, glm::vec<3, T> normal, glm::vec<3, T> at,
                     const glm::vec<3, T>* object_color, T wall_tint, glm::vec<3, T> fog,
                     glm::vec<3, T> background) {
  glm::vec<3, T> surface;
  if (hit >= 0) {
    surface = object_color ? *object_color : T(0.5) + T(0.5) * normal;
  } else if (hit == kHitWall) {
    surface = glm::vec<3, T>(T(kWallGrey));
  } else if (hit == kHitFloor) {
    const long check =
        std::lround(std::floor(at.x / T(kFloorCheck)) + std::floor(at.y / T(kFloorCheck)));
    surface = glm::vec<3, T>(T((check & 1) ? kFloorDarkGrey : kWallGrey));
  } else if (hit == kHitMaxSteps || hit == kHitVertex) {
    surface = glm::vec<3, T>(T(0));  // undecided rays show as black
  } else {
    surface = background;  // miss, escape, max_distance
  }
  const T transmittance = std::pow(T(1) - wall_tint, T(crossings));
  return transmittance * surface + (T(1) - transmittance) * fog;
}

}  // namespace flatmarch
