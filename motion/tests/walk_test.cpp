// Walking and looking (motion/walk.hpp) against motions worked out by hand on the gallery scenes:
// crossings unfold to straight lines, a loop round a cone point turns the walker by 2 pi minus
// its angle, mirrors and vertices stop it. The web page's port of the walk: web/tests/.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "motion/walk.hpp"
#include "scene/load.hpp"
#include "tests/gallery.hpp"

namespace flatmarch::motion {
namespace {

// A crossing places the point kPush * scene.scale (at most 6e-9 here) inside the edge it came in
// by; positions after crossings are compared to this.
constexpr double kCrossTol = 1e-8;
constexpr double kTol = 1e-9;
const double kSqrt2 = std::sqrt(2.0);

Camera at(int polygon, Vec3 position, double yaw_deg) {
  return {.polygon = polygon, .position = position, .yaw_deg = yaw_deg};
}

void expect_at(const Camera& c, int polygon, Vec3 position, double tol) {
  EXPECT_EQ(c.polygon, polygon);
  EXPECT_NEAR(c.position.x, position.x, tol);
  EXPECT_NEAR(c.position.y, position.y, tol);
  EXPECT_NEAR(c.position.z, position.z, tol);
}

const Scene& gallery(const std::string& name) {
  return test::gallery_scene(name);
}

TEST(Walk, TorusWalkOutOfTheRightWallComesInAtTheLeft) {
  // From (3.5, 2) east by 1: (4.5, 2) in the plane, less the period (4, 0).
  const WalkResult r = walk(gallery("torus"), at(0, {3.5, 2, 1}, 0), 1, 0, 0);
  expect_at(r.camera, 0, {0.5, 2, 1}, kCrossTol);
  EXPECT_EQ(r.camera.yaw_deg, 0.0);
  EXPECT_EQ(r.crossings, 1);
  EXPECT_FALSE(r.blocked);
}

TEST(Walk, TorusDiagonalWalkCrossesTopThenRight) {
  // From (3.5, 3.8) along (1, 1) by sqrt 2: y = 4 at (3.7, 4), then x = 4 at (4, 4.1); the end
  // (4.5, 4.8) less (4, 4).
  const WalkResult r = walk(gallery("torus"), at(0, {3.5, 3.8, 1}, 45), kSqrt2, 0, 0);
  expect_at(r.camera, 0, {0.5, 0.8, 1}, kCrossTol);
  EXPECT_EQ(r.camera.yaw_deg, 45.0);
  EXPECT_EQ(r.crossings, 2);
}

TEST(Walk, LShapeWalksThroughItsGluedWalls) {
  // l_shape.json: edge 4 (x = 2, 2 <= y <= 4) is glued to edge 6 (x = 0) by (-2, 0), edge 5
  // (y = 4, 0 <= x <= 2) to edge 0 (y = 0) by (0, -4), edge 3 (y = 2, 2 <= x <= 4) to edge 1
  // (y = 0) by (0, -2).
  const Scene& s = gallery("l_shape");
  // From (1.5, 3.2) along (1, 1) by sqrt 2: x = 2 at (2, 3.7) -> (0, 3.7), then y = 4 at
  // (0.3, 4) -> (0.3, 0); the end (2.5, 4.2) less (2, 0) and (0, 4).
  WalkResult r = walk(s, at(0, {1.5, 3.2, 1}, 45), kSqrt2, 0, 0);
  expect_at(r.camera, 0, {0.5, 0.2, 1}, kCrossTol);
  EXPECT_EQ(r.crossings, 2);
  EXPECT_FALSE(r.blocked);
  // From (3, 1.5) north by 1: y = 2 at (3, 2) -> (3, 0), then on to (3, 0.5).
  r = walk(s, at(0, {3, 1.5, 1}, 90), 1, 0, 0);
  expect_at(r.camera, 0, {3, 0.5, 1}, kCrossTol);
  EXPECT_EQ(r.crossings, 1);
}

TEST(Walk, LoopRoundACubeCornerTurnsTheWalkerByTheAngleDeficit) {
  // cube.json: faces 0 [0,2]^2, 1 [2,4]x[0,2], 4 [0,2]x[2,4] meet at the corner (2, 2), a cone
  // point of angle 3 pi / 2. Face 0 -> 1 and 4 -> 0 are zero translations; face 1's top (edge 2)
  // goes to face 4's right (edge 1) by the rotation of +90 degrees about (2, 2). The loop below
  // stays within 0.71 of that corner and the other corners are 1.5 or more from it, so it goes
  // once round exactly one cone point, counterclockwise.
  const Scene& s = gallery("cube");
  const double cone = s.vertex_classes[static_cast<size_t>(s.corner_class[0][2])].cone_angle;
  EXPECT_NEAR(cone, 1.5 * kPi, 1e-12);

  const Camera start = at(0, {1.5, 1.5, 1}, 0);
  // East by 1 into face 1.
  WalkResult r = walk(s, start, 1, 0, 0);
  expect_at(r.camera, 1, {2.5, 1.5, 1}, kCrossTol);
  EXPECT_NEAR(r.camera.yaw_deg, 0.0, kTol);
  // Left (north) by 1: (2.5, 2) -> (2, 2.5) on face 4, the rest (0, 0.5) turned to (-0.5, 0),
  // and the yaw by the gluing's +90 degrees.
  r = walk(s, r.camera, 0, -1, 0);
  expect_at(r.camera, 4, {1.5, 2.5, 1}, kCrossTol);
  EXPECT_NEAR(r.camera.yaw_deg, 90.0, kTol);
  EXPECT_EQ(r.crossings, 1);
  // Back (now south, since the yaw is 90) by 1 into face 0, where the walk began.
  r = walk(s, r.camera, -1, 0, 0);
  expect_at(r.camera, 0, start.position, kCrossTol);
  EXPECT_NEAR(
      std::remainder(r.camera.yaw_deg - start.yaw_deg - (2.0 * kPi - cone) * 180.0 / kPi, 360.0),
      0.0, kTol);
}

TEST(Walk, OnceRoundAnInfiniteConesApexTurnsTheWalkerBy2PiLessItsAngle) {
  // The gallery's infinite cones: wedges from direction 0 to their angle, glued along their rays
  // by rotations about the apex (DESIGN.md section 1). The walker keeps its yaw and steps along
  // chords of the circle of radius 1.5 about the apex, 10 degrees of polar angle at a time in
  // the coordinates of the room it is in (a chord that runs past a glued ray continues into the
  // next wedge, as unfolding lays it out). Once round, the polar angles swept add up to the cone
  // angle, and it is back where it started, turned by the gluings' rotations: 2 pi - theta.
  for (const char* name : {"cone_half_pi", "cone_pi", "cone_three_half_pi", "cone_three_pi"}) {
    SCOPED_TRACE(name);
    const Scene& s = gallery(name);
    ASSERT_EQ(s.vertex_classes.size(), 1u);
    const double theta = s.vertex_classes[0].cone_angle;
    const double wedge = s.polygons[0].corner_angle(0);
    const double radius = 1.5, z = 1.0;
    const Camera start = at(0, {radius * std::cos(wedge / 2), radius * std::sin(wedge / 2), z}, 20);
    Camera c = start;
    const int steps = static_cast<int>(std::lround(theta / (kPi / 18)));
    const double step = theta / steps;
    int crossings = 0;
    for (int k = 0; k < steps; ++k) {
      const Vec2 p(c.position);
      double phi = std::atan2(p.y, p.x);
      if (phi < 0) phi += 2 * kPi;
      const Vec2 v = radius * Vec2(std::cos(phi + step), std::sin(phi + step)) - p;
      const double a = c.yaw_deg * kPi / 180;
      const WalkResult r = walk(s, c, glm::dot(v, Vec2(std::cos(a), std::sin(a))),
                                glm::dot(v, Vec2(std::sin(a), -std::cos(a))), 0);
      ASSERT_FALSE(r.blocked) << "step " << k;
      ASSERT_LE(r.crossings, 1);
      crossings += r.crossings;
      c = r.camera;
      EXPECT_NEAR(glm::length(Vec2(c.position)), radius, 1e-6) << "step " << k;
    }
    EXPECT_EQ(crossings, static_cast<int>(s.polygons.size()));  // each wedge's glued ray once
    expect_at(c, start.polygon, start.position, 1e-6);
    EXPECT_NEAR(std::remainder(c.yaw_deg - start.yaw_deg - (2 * kPi - theta) * 180 / kPi, 360.0),
                0.0, 1e-9);
  }
}

TEST(Walk, InfiniteCylinderAndTheEdgeOfTheModelledWorld) {
  // cylinder.json: circumference 3, the strip above y = 0 and the one below glued along it.
  // Walking down across y = 0 enters the lower half-strip; walking round (east by 3) comes back.
  const Scene& s = gallery("cylinder");
  WalkResult r = walk(s, at(0, {1.5, 1, 1}, -90), 2, 0, 0);
  expect_at(r.camera, 1, {1.5, -1, 1}, kCrossTol);
  EXPECT_EQ(r.crossings, 1);
  r = walk(s, r.camera, 0, -3, 0);  // facing -y, left is +x
  expect_at(r.camera, 1, {1.5, -1, 1}, kCrossTol);
  EXPECT_EQ(r.crossings, 1);
  // Far up the tube the walk stops where the rooms are modelled to (kWalkReach).
  r = walk(s, at(0, {1.5, 1, 1}, 90), 1e12, 0, 0);
  EXPECT_TRUE(r.blocked);
  EXPECT_LT(r.camera.position.y, 1e7);
  EXPECT_TRUE(s.polygons[0].contains(Vec2(r.camera.position)));
}

TEST(Walk, KleinBottleReflectionMirrorsTheYaw) {
  // klein_bottle.json: the bottom (edge 0) goes to the top by the reflection (x, y) ->
  // (4 - x, y + 4). From (1, 0.5) at yaw -45 by 1: y = 0 at (1.5, 0) after 1/sqrt 2; the end
  // (1 + 1/sqrt 2, 0.5 - 1/sqrt 2) maps to (3 - 1/sqrt 2, 4.5 - 1/sqrt 2), heading
  // (-1, -1)/sqrt 2: yaw -135.
  const WalkResult r = walk(gallery("klein_bottle"), at(0, {1, 0.5, 1}, -45), 1, 0, 0);
  expect_at(r.camera, 0, {3 - 1 / kSqrt2, 4.5 - 1 / kSqrt2, 1}, kCrossTol);
  EXPECT_NEAR(r.camera.yaw_deg, -135.0, kTol);
  EXPECT_EQ(r.crossings, 1);
}

TEST(Walk, SimilarityScalesTheRestOfTheWalk) {
  // Edge 1 of the unit square (x = 1) is glued to the left edge of the square [1, 3]^2 x [0, 2]
  // by x -> 2 (x - (1, 0)) + (1, 0). From (0.5, 0.25) east by 1: (1, 0.25) -> (1, 0.5), the rest
  // 0.5 doubled: (2, 0.5).
  const Scene s = parse_scene(R"({"polygons": [[[0, 0], [1, 0], [1, 1], [0, 1]],
                                               [[1, 0], [3, 0], [3, 2], [1, 2]]],
                                  "gluings": [{"edges": [[0, 1], [1, 3]], "map": "similarity"}]})",
                              "similarity.json");
  const WalkResult r = walk(s, at(0, {0.5, 0.25, 1}, 0), 1, 0, 0);
  expect_at(r.camera, 1, {2, 0.5, 1}, kCrossTol);
  EXPECT_NEAR(r.camera.yaw_deg, 0.0, kTol);
  EXPECT_EQ(r.crossings, 1);
}

TEST(Walk, MirrorStopsTheWalkerAMarginBeforeIt) {
  // mirror_square.json: [0, 3]^2, every edge a mirror.
  const Scene& s = gallery("mirror_square");
  WalkResult r = walk(s, at(0, {1.5, 1.5, 1}, 0), 5, 0, 0);
  expect_at(r.camera, 0, {3 - kWalkMargin, 1.5, 1}, kTol);
  EXPECT_TRUE(r.blocked);
  EXPECT_EQ(r.crossings, 0);
  EXPECT_TRUE(s.polygons[0].contains(Vec2(r.camera.position)));
  // At yaw 30 by 2 the walker meets x = 3 and slides up it: the whole of its northward
  // displacement, 2 sin 30 = 1, is kept.
  r = walk(s, at(0, {1.5, 1.5, 1}, 30), 2, 0, 0);
  expect_at(r.camera, 0, {3 - kWalkMargin, 2.5, 1}, kTol);
  EXPECT_TRUE(r.blocked);
  // By 4 it slides on into the top mirror and stops in the corner.
  r = walk(s, at(0, {1.5, 1.5, 1}, 30), 4, 0, 0);
  expect_at(r.camera, 0, {3 - kWalkMargin, 3 - kWalkMargin, 1}, kTol);
}

TEST(Walk, VertexStopsTheWalkerAMarginShortAlongItsPath) {
  // Straight into the mirror square's corner (3, 3).
  WalkResult r = walk(gallery("mirror_square"), at(0, {1.5, 1.5, 1}, 45), 3, 0, 0);
  const double back = kWalkMargin / kSqrt2;
  expect_at(r.camera, 0, {3 - back, 3 - back, 1}, kTol);
  EXPECT_TRUE(r.blocked);
  // Through the L-shape's reflex corner (2, 2), its cone point of angle 6 pi.
  r = walk(gallery("l_shape"), at(0, {1, 3, 1}, -45), 2 * kSqrt2, 0, 0);
  expect_at(r.camera, 0, {2 - back, 2 + back, 1}, kTol);
  EXPECT_TRUE(r.blocked);
  EXPECT_EQ(r.crossings, 0);
}

TEST(Walk, ManySmallStepsMakeOneBigStepWithinARoom) {
  const Scene& s = gallery("torus");
  const Camera start = at(0, {1, 1, 1}, 30);
  Camera small = start;
  for (int i = 0; i < 100; ++i) small = walk(s, small, 0.01, 0.005, 0.003).camera;
  const WalkResult big = walk(s, start, 1, 0.5, 0.3);
  // forward (cos 30, sin 30), right (sin 30, -cos 30).
  const Vec3 expected(1 + std::sqrt(3.0) / 2 + 0.25, 1 + 0.5 - std::sqrt(3.0) / 4, 1.3);
  expect_at(big.camera, 0, expected, kTol);
  expect_at(small, 0, expected, kTol);
  EXPECT_EQ(big.crossings, 0);
  EXPECT_FALSE(big.blocked);
}

TEST(Walk, UpStaysInTheBandOrWrapsInAPrism) {
  const Scene& mirror = gallery("mirror_square");  // height 4
  EXPECT_NEAR(walk(mirror, at(0, {1.5, 1.5, 1}, 0), 0, 0, 10).camera.position.z, 4 - kWalkMargin,
              kTol);
  EXPECT_NEAR(walk(mirror, at(0, {1.5, 1.5, 1}, 0), 0, 0, -10).camera.position.z, kWalkMargin,
              kTol);
  // torus_prism.json: period 2, so 1.3 + 1 is 0.3 and 1.3 - 2.5 is 0.8.
  const Scene& prism = gallery("torus_prism");
  EXPECT_NEAR(walk(prism, at(0, {1, 1, 1.3}, 0), 0, 0, 1).camera.position.z, 0.3, kTol);
  EXPECT_NEAR(walk(prism, at(0, {1, 1, 1.3}, 0), 0, 0, -2.5).camera.position.z, 0.8, kTol);
}

TEST(Walk, CameraAboveTheBandFliesAndComesDownIntoTheRoomUnderIt) {
  const Scene& s = gallery("mirror_square");  // its camera is at z 4.7, above the band (4)
  WalkResult r = walk(s, s.camera, 0, 0, -1);
  expect_at(r.camera, 0, {1.513, 1.507, 3.7}, kTol);
  // Over no room it stays above the band.
  r = walk(s, s.camera, 10, 0, 0);  // yaw 90: north
  expect_at(r.camera, 0, {1.513, 11.507, 4.7}, kTol);
  r = walk(s, r.camera, 0, 0, -1);
  EXPECT_NEAR(r.camera.position.z, 4 + kWalkMargin, kTol);
}

TEST(Walk, LongWalkEndsAfterTheSegmentLimit) {
  const Scene& s = gallery("torus");
  const WalkResult r = walk(s, at(0, {2, 2, 1}, 31), 1e6, 0, 0);
  EXPECT_EQ(r.crossings, kMaxSegments);
  EXPECT_TRUE(r.blocked);
  EXPECT_TRUE(s.polygons[0].contains(Vec2(r.camera.position)));
}

TEST(Walk, RandomWalksStayInsideTheirRooms) {
  // Whatever the path, every walk's end is a valid start for the next.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const std::string& name : test::gallery_names()) {
    SCOPED_TRACE(name);
    const Scene& s = gallery(name);
    Camera c = s.camera;
    if (!s.in_band(c.position.z))  // start in a room, where walks meet edges
      c = at(0, Vec3(s.polygons[0].centroid(), 0.5 * s.height), 0);
    for (int i = 0; i < 300; ++i) {
      c = look(c, 180 * unit(random), 0);
      const WalkResult r =
          walk(s, c, s.scale * unit(random), s.scale * unit(random), s.height * unit(random));
      c = r.camera;
      if (!s.in_band(c.position.z)) continue;
      ASSERT_TRUE(s.polygons[static_cast<size_t>(c.polygon)].contains(Vec2(c.position)))
          << "step " << i << " at (" << c.position.x << ", " << c.position.y << ")";
    }
  }
}

TEST(Walk, BadInputIsRejected) {
  const Scene& s = gallery("torus");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(walk(s, at(-1, {1, 1, 1}, 0), 1, 0, 0), std::invalid_argument);
  EXPECT_THROW(walk(s, at(1, {1, 1, 1}, 0), 1, 0, 0), std::invalid_argument);
  EXPECT_THROW(walk(s, at(0, {nan, 1, 1}, 0), 1, 0, 0), std::invalid_argument);
  EXPECT_THROW(walk(s, at(0, {1, 1, 1}, nan), 1, 0, 0), std::invalid_argument);
  EXPECT_THROW(walk(s, at(0, {1, 1, 1}, 0), nan, 0, 0), std::invalid_argument);
  EXPECT_THROW(walk(s, at(0, {1, 1, 1}, 0), 0, 0, std::numeric_limits<double>::infinity()),
               std::invalid_argument);
  // Within the band but outside its polygon.
  EXPECT_THROW(walk(s, at(0, {5, 1, 1}, 0), 1, 0, 0), std::invalid_argument);
  EXPECT_THROW(look(s.camera, nan, 0), std::invalid_argument);
}

TEST(Look, TurnsYawAndClampsPitch) {
  Camera c = at(0, {1, 1, 1}, 170);
  c.pitch_deg = 80;
  Camera turned = look(c, 20, 20);
  EXPECT_DOUBLE_EQ(turned.yaw_deg, -170.0);
  EXPECT_DOUBLE_EQ(turned.pitch_deg, kMaxPitchDeg);
  turned = look(turned, -10, -200);
  EXPECT_DOUBLE_EQ(turned.yaw_deg, -180.0);
  EXPECT_DOUBLE_EQ(turned.pitch_deg, -kMaxPitchDeg);
  EXPECT_EQ(turned.position, c.position);
}

}  // namespace
}  // namespace flatmarch::motion
