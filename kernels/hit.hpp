// What ended a ray: the `hit` AOV of DESIGN.md section 4. An object index is >= 0.
#pragma once

namespace flatmarch {

inline constexpr int kHitMiss = -1;
inline constexpr int kHitEscape = -2;
inline constexpr int kHitWall = -3;
inline constexpr int kHitFloor = -4;
inline constexpr int kHitMaxSteps = -5;
inline constexpr int kHitMaxDistance = -6;
inline constexpr int kHitVertex = -7;

}  // namespace flatmarch
