// The oracle against paths worked out by hand: unfolded straight lines in the universal cover,
// closed mirror orbits, great circles of the cube, exact intersections.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include "backends/oracle/intersect.hpp"
#include "backends/oracle/oracle.hpp"
#include "kernels/camera.hpp"
#include "kernels/compile.hpp"
#include "output/image_io.hpp"
#include "scene/load.hpp"
#include "tests/process.hpp"
#include "tests/test_scenes.hpp"

namespace flatmarch {
namespace {

constexpr double kTol = 1e-9;

Scene load(const std::string& json) {
  return parse_scene(json, "test.json");
}

OracleResult trace(const Scene& s, Vec3 from, Vec3 dir, int polygon = 0, MarchParams params = {}) {
  return oracle_trace(s, Ray{polygon, from, dir}, params,
                      {.max_events = 1000, .record_path = true});
}

void expect_near(Vec3 a, Vec3 b, double tol = kTol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

void expect_gluing(const Event& e, int polygon, int edge, int to_polygon, int to_edge, double t,
                   Vec3 at) {
  EXPECT_EQ(e.kind, EventKind::gluing);
  EXPECT_EQ(e.polygon, polygon);
  EXPECT_EQ(e.edge, edge);
  EXPECT_EQ(e.to_polygon, to_polygon);
  EXPECT_EQ(e.to_edge, to_edge);
  EXPECT_NEAR(e.t, t, kTol);
  expect_near(e.at, at);
}

TEST(OracleTransport, TorusRayCrossesTheEdgesOfItsUnfoldedLine) {
  // From (1, 1) along (3, 1): in the plane the line meets x = 4k at u = (4k - 1)/3 and y = 4m at
  // u = 4m - 1 (position (1 + 3u, 1 + u), t = u sqrt 10). In order: u = 1, 7/3 (x), 3 (y),
  // 11/3, 5, 19/3 (x), 7 (y), 23/3 (x); positions reduced mod 4 into the square.
  const Scene s = load(test::torus_json());
  const OracleResult r = trace(s, {1, 1, 1}, {3, 1, 0});
  const double k = std::sqrt(10.0);
  struct Crossing {
    double u;
    int edge;
    Vec2 at;
  };
  const Crossing expected[] = {
      {1, 1, {4, 2}}, {7.0 / 3, 1, {4, 10.0 / 3}},  {3, 2, {2, 4}}, {11.0 / 3, 1, {4, 2.0 / 3}},
      {5, 1, {4, 2}}, {19.0 / 3, 1, {4, 10.0 / 3}}, {7, 2, {2, 4}}, {23.0 / 3, 1, {4, 2.0 / 3}}};
  ASSERT_GE(r.trace.events.size(), 8u);
  for (size_t i = 0; i < 8; ++i) {
    const Crossing& c = expected[i];
    expect_gluing(r.trace.events[i], 0, c.edge, 0, (c.edge + 2) % 4, c.u * k, Vec3(c.at, 1.0));
  }
  // Nothing to hit and no way up or down: the ray runs out of distance.
  EXPECT_EQ(r.trace.events.back().kind, EventKind::max_distance);
  EXPECT_EQ(r.end.hit, kHitMaxDistance);
  EXPECT_NEAR(r.end.t, 100.0, kTol);
}

TEST(OracleTransport, MirrorSquarePathCloses) {
  // A unit mirror square; from (0.5, 0.25) at 45 degrees the ray bounces off the right, top,
  // left and bottom walls at (1, .75), (.75, 1), (0, .25), (.25, 0) and is back at its start
  // point and direction after a path of 2 sqrt 2.
  const Scene s = load(R"({"polygons": [[[0, 0], [1, 0], [1, 1], [0, 1]]]})");
  const OracleResult r = trace(s, {0.5, 0.25, 1}, {1, 1, 0});
  const double k = std::sqrt(2.0);
  const struct {
    int edge;
    double t;
    Vec2 at;
  } bounces[] = {{1, 0.5 * k, {1, 0.75}},
                 {2, 0.75 * k, {0.75, 1}},
                 {3, 1.5 * k, {0, 0.25}},
                 {0, 1.75 * k, {0.25, 0}},
                 {1, 2.5 * k, {1, 0.75}}};
  ASSERT_GE(r.trace.events.size(), 5u);
  for (size_t i = 0; i < 5; ++i) {
    const Event& e = r.trace.events[i];
    EXPECT_EQ(e.kind, EventKind::mirror);
    EXPECT_EQ(e.edge, bounces[i].edge);
    EXPECT_NEAR(e.t, bounces[i].t, kTol);
    expect_near(e.at, Vec3(bounces[i].at, 1.0));
  }
  // The fourth bounce sends it back through its start: the path passes (0.5, 0.25) heading (1,1).
  const PathSegment& back = r.path[4];
  EXPECT_NEAR(back.from.x, 0.25, kTol);
  EXPECT_NEAR(back.to.x - back.from.x, back.to.y - back.from.y, kTol);
}

TEST(OracleTransport, CubeBeltIsAClosedGeodesicOfLength4) {
  // Along +x through the centre face: right face, back face, (translation -4) left face, centre.
  const Scene s = load(test::cube_json());
  const OracleResult r = trace(s, {0.5, 0.5, 1}, {1, 0, 0});
  ASSERT_GE(r.trace.events.size(), 5u);
  expect_gluing(r.trace.events[0], 0, 1, 1, 3, 0.5, {1, 0.5, 1});
  expect_gluing(r.trace.events[1], 1, 1, 2, 3, 1.5, {2, 0.5, 1});
  expect_gluing(r.trace.events[2], 2, 1, 3, 3, 2.5, {3, 0.5, 1});
  expect_gluing(r.trace.events[3], 3, 1, 0, 3, 3.5, {0, 0.5, 1});
  expect_gluing(r.trace.events[4], 0, 1, 1, 3, 4.5, {1, 0.5, 1});  // once round: length 4
}

TEST(OracleTransport, CubeGreatCircleThroughTheTurnedFaces) {
  // Along +y: top face; its far edge meets the back face's top by a half turn
  // g(x, y) = (3 - x, 3 - y), so (0.5, 2) lands at (2.5, 1) heading down; the back face's
  // bottom meets the bottom face's bottom by a half turn, (x, y) -> (3 - x, -1 - y): (2.5, 0)
  // lands at (0.5, -1) heading up; then up through the bottom face into the centre face.
  const Scene s = load(test::cube_json());
  const OracleResult r = trace(s, {0.5, 0.5, 1}, {0, 1, 0});
  ASSERT_GE(r.trace.events.size(), 5u);
  expect_gluing(r.trace.events[0], 0, 2, 4, 0, 0.5, {0.5, 1, 1});
  expect_gluing(r.trace.events[1], 4, 2, 2, 2, 1.5, {0.5, 2, 1});
  expect_gluing(r.trace.events[2], 2, 0, 5, 0, 2.5, {2.5, 0, 1});
  expect_gluing(r.trace.events[3], 5, 2, 0, 0, 3.5, {0.5, 0, 1});
  expect_gluing(r.trace.events[4], 0, 2, 4, 0, 4.5, {0.5, 1, 1});
  // The path in the back face runs down from (2.5, 1) to (2.5, 0).
  expect_near(r.path[2].from, {2.5, 1, 1});
  expect_near(r.path[2].to, {2.5, 0, 1});
}

TEST(OracleTransport, RotatedGluingTurnsTheDirection) {
  // In the top face heading +x: its right edge maps by g(x, y) = (y, -x) + (0, 2), so (1, 1.5)
  // lands at (1.5, 1) on the right face's top and the direction (1, 0) turns into (0, -1): the
  // ray then crosses the right face downwards to (1.5, 0) on its bottom edge.
  const Scene s = load(test::cube_json());
  const OracleResult r = trace(s, {0.5, 1.5, 1}, {1, 0, 0}, 4);
  ASSERT_GE(r.trace.events.size(), 2u);
  expect_gluing(r.trace.events[0], 4, 1, 1, 2, 0.5, {1, 1.5, 1});
  expect_gluing(r.trace.events[1], 1, 0, 5, 1, 1.5, {1.5, 0, 1});
  expect_near(r.path[1].from, {1.5, 1, 1});
}

TEST(OracleTransport, RayThroughAVertexEndsThere) {
  // From (1, 1) along (1, 1) the ray meets the corner (4, 4) at t = 3 sqrt 2.
  const Scene s = load(test::torus_json());
  const OracleResult r = trace(s, {1, 1, 1}, {1, 1, 0});
  ASSERT_EQ(r.trace.events.size(), 1u);
  EXPECT_EQ(r.trace.events[0].kind, EventKind::vertex);
  EXPECT_NEAR(r.trace.events[0].t, 3 * std::sqrt(2.0), kTol);
  EXPECT_EQ(r.end.hit, kHitVertex);
  // 1e-9 above that line it passes 7e-10 from the corner, so it crosses the top edge first
  // (at x = 4 - 1e-9) and goes on.
  const OracleResult near_miss = trace(s, {1, 1 + 1e-9, 1}, {1, 1, 0});
  ASSERT_GE(near_miss.trace.events.size(), 2u);
  EXPECT_EQ(near_miss.trace.events[0].kind, EventKind::gluing);
  EXPECT_EQ(near_miss.trace.events[0].edge, 2);
  EXPECT_NEAR(near_miss.trace.events[0].at.x, 4 - 1e-9, 1e-12);
}

TEST(OracleTransport, VertexAtTheExitPointAfterGluingsIsAVertex) {
  // On the cube net of side 2 (scenes/cube.json) a ray along (-47, 17) from (3.4, 0.6) in the
  // right face is rational all the way: it enters the bottom face at (60/47, -2) heading
  // (17, 47) and so meets that face's corner (2, 0) exactly. In floating point it arrives a
  // rounding error below the corner; that is still the vertex, not a crossing of the edge.
  const Scene s = load_scene(FLATMARCH_SOURCE_DIR "/scenes/cube.json");
  const OracleResult r = trace(s, {3.4, 0.6, 1.2}, {-0.94, 0.34, 0}, 1);
  ASSERT_FALSE(r.trace.events.empty());
  const Event& last = r.trace.events.back();
  EXPECT_EQ(last.kind, EventKind::vertex);
  EXPECT_EQ(last.polygon, 5);
  expect_near(last.at, {2, 0, 1.2}, 1e-12);
  expect_near(r.path.back().from, {60.0 / 47.0, -2, 1.2}, 1e-12);
}

TEST(OracleTransport, EscapeFloorAndPeriod) {
  // Rising at slope 4/3 from z = 1, the ray leaves the band (height 2) at t = 1 / 0.8.
  const Scene torus = load(test::torus_json());
  OracleResult r = trace(torus, {1, 1, 1}, {0.6, 0, 0.8});
  ASSERT_EQ(r.trace.events.size(), 1u);
  EXPECT_EQ(r.trace.events[0].kind, EventKind::escape);
  EXPECT_NEAR(r.end.t, 1.25, kTol);
  expect_near(r.end.at, {1.75, 1, 2});
  EXPECT_EQ(r.end.hit, kHitEscape);
  // Falling onto a floor instead.
  const Scene floored = load(test::torus_json(R"("floor": true)"));
  r = trace(floored, {1, 1, 1}, {0.6, 0, -0.8});
  EXPECT_EQ(r.end.hit, kHitFloor);
  expect_near(r.end.at, {1.75, 1, 0});
  // In a translation prism of period 2 a ray going straight up from z = 1.5 wraps at z = 2
  // (t = 0.5) to z = 0 and meets the sphere (centre z = 1, radius 0.2) at z = 0.8: t = 1.3.
  const Scene prism = load(test::torus_json(
      R"("period": 2, "objects": [{"type": "sphere", "center": [2, 2, 1], "radius": 0.2}])"));
  r = trace(prism, {2, 2, 1.5}, {0, 0, 1});
  EXPECT_EQ(r.end.hit, 0);
  EXPECT_NEAR(r.end.t, 1.3, kTol);
  expect_near(r.end.at, {2, 2, 0.8});
  EXPECT_EQ(r.end.steps, 2);
  EXPECT_EQ(r.end.crossings, 0);  // wrapping in z is not a wall crossing
}

TEST(OracleTransport, SphereHitAfterThreeGluings) {
  // A sphere of radius 0.5 at (2, 2, 1) in the torus has copies at (2 + 4i, 2 + 4j). From
  // (1, 2.7) aimed at the copy (10, 6): the line x - 1 = 9s, y - 2.7 = 3.3s passes no other copy
  // within 1 and no corner; it crosses x = 4, y = 4, x = 8 and hits at |(9, 3.3)| - 0.5.
  const Scene s = load(
      test::torus_json(R"("objects": [{"type": "sphere", "center": [2, 2, 1], "radius": 0.5}])"));
  const Vec3 from{1, 2.7, 1}, dir = glm::normalize(Vec3(9, 3.3, 0));
  const OracleResult r = trace(s, from, dir);
  const double t = std::sqrt(81 + 3.3 * 3.3) - 0.5;
  EXPECT_EQ(r.end.hit, 0);
  EXPECT_EQ(r.end.crossings, 3);
  EXPECT_NEAR(r.end.t, t, kTol);
  const Vec3 cover = from + t * dir;  // the hit point in the plane, reduced by (8, 4)
  expect_near(r.end.at, cover - Vec3(8, 4, 0));
  // The normal points from the sphere's centre to the hit point: back along the ray.
  expect_near(r.end.normal, -dir);
  ASSERT_EQ(r.trace.events.size(), 4u);
  EXPECT_EQ(r.trace.events[0].edge, 1);
  EXPECT_EQ(r.trace.events[1].edge, 2);
  EXPECT_EQ(r.trace.events[2].edge, 1);
  EXPECT_EQ(r.trace.events[3].kind, EventKind::object);
  EXPECT_EQ(r.trace.events[3].object, 0);
}

TEST(OracleTransport, LimitsEndTheRay) {
  const Scene s = load(test::torus_json());
  MarchParams params;
  params.max_distance = 5;
  OracleResult r = trace(s, {1, 1, 1}, {1, 0.3, 0}, 0, params);
  EXPECT_EQ(r.end.hit, kHitMaxDistance);
  EXPECT_NEAR(r.end.t, 5, kTol);
  params = {};
  params.max_steps = 3;
  r = trace(s, {1, 1, 1}, {1, 0.3, 0}, 0, params);
  EXPECT_EQ(r.end.hit, kHitMaxSteps);
  EXPECT_EQ(r.end.steps, 3);
  ASSERT_EQ(r.trace.events.size(), 4u);  // three gluings, then max_steps
  EXPECT_EQ(r.trace.events[3].kind, EventKind::max_steps);
}

TEST(OracleTransport, CameraAboveSeesTheRoomsLaidOut) {
  // Two rooms side by side; straight down from (5, 1, 5) the ray crosses z = 2 inside the
  // second one (t = 3), enters it and lands on its floor at t = 5.
  const Scene s = load(
      R"({"polygons": [[[0, 0], [2, 0], [2, 2], [0, 2]], [[4, 0], [6, 0], [6, 2], [4, 2]]], "floor": true})");
  OracleResult r = trace(s, {5, 1, 5}, {0, 0, -1});
  ASSERT_EQ(r.trace.events.size(), 2u);
  EXPECT_EQ(r.trace.events[0].kind, EventKind::enter);
  EXPECT_EQ(r.trace.events[0].polygon, 1);
  EXPECT_NEAR(r.trace.events[0].t, 3, kTol);
  EXPECT_EQ(r.end.hit, kHitFloor);
  EXPECT_NEAR(r.end.t, 5, kTol);
  // Between the rooms nothing is entered.
  r = trace(s, {3, 1, 5}, {0, 0, -1});
  EXPECT_EQ(r.end.hit, kHitMiss);
  EXPECT_EQ(r.trace.events.back().kind, EventKind::miss);
  // Looking up from above sees nothing either.
  EXPECT_EQ(trace(s, {1, 1, 5}, {0, 0, 1}).end.hit, kHitMiss);
}

TEST(OracleTransport, SimilarityGluingSumsTInEachRoomsMetric) {
  // The unit square's right edge glued by the similarity g = 2 x to the left edge of [2,4]^2.
  // Direction (1, 0, 0.5): 0.5 across the first room (t = 0.5 |(1, 0, 0.5)|, z + 0.25); in the
  // second the horizontal part doubles, direction (2, 0, 0.5) normalised, 2 across it to the
  // mirror at x = 4 (t = 2 |(2, 0, 0.5)| / 2, z + 0.5).
  const Scene s =
      load(R"({"polygons": [[[0, 0], [1, 0], [1, 1], [0, 1]], [[2, 0], [4, 0], [4, 2], [2, 2]]],
      "gluings": [{"edges": [[0, 1], [1, 3]], "map": "similarity"}], "height": 3})");
  const OracleResult r = trace(s, {0.5, 0.5, 1}, {1, 0, 0.5});
  ASSERT_GE(r.trace.events.size(), 2u);
  const double t0 = 0.5 * std::sqrt(1.25), t1 = std::sqrt(4.25);
  expect_gluing(r.trace.events[0], 0, 1, 1, 3, t0, {1, 0.5, 1.25});
  EXPECT_EQ(r.trace.events[1].kind, EventKind::mirror);
  EXPECT_NEAR(r.trace.events[1].t, t0 + t1, kTol);
  expect_near(r.trace.events[1].at, {4, 1, 1.75});
}

TEST(OracleTransport, WallStopsTheRay) {
  const Scene s = load(R"({"polygons": [[[0, 0], [1, 0], [1, 1], [0, 1]]], "boundary": "wall"})");
  const OracleResult r = trace(s, {0.5, 0.5, 1}, {1, 0, 0});
  EXPECT_EQ(r.end.hit, kHitWall);
  EXPECT_NEAR(r.end.t, 0.5, kTol);
  EXPECT_EQ(r.trace.events[0].edge, 1);
}

TEST(OracleTransport, ConePointCylinder) {
  // The L's cone point at its reflex corner (2, 2) drawn as a cylinder of radius 0.1: straight
  // at it from (1, 1) the ray meets it at sqrt 2 - 0.1; the marker's index follows the objects.
  const Scene s =
      load(R"({"polygons": [[[0, 0], [2, 0], [4, 0], [4, 2], [2, 2], [2, 4], [0, 4], [0, 2]]],
      "gluings": [[[0, 0], [0, 5]], [[0, 1], [0, 3]], [[0, 2], [0, 7]], [[0, 4], [0, 6]]],
      "objects": [{"type": "sphere", "center": [3, 1, 1], "radius": 0.1}],
      "singularities": {"radius": 0.1}})");
  const OracleResult r = trace(s, {1, 1, 1}, {1, 1, 0});
  EXPECT_EQ(r.end.hit, 1);
  EXPECT_NEAR(r.end.t, std::sqrt(2.0) - 0.1, kTol);
  // From (1, 3) towards (0.05, 2) the line passes 0.05 / |(0.95, 1)| = 0.036 from the straight
  // corner (0, 2), which belongs to the cone point too: it hits that corner's sector.
  const OracleResult sector = trace(s, {1, 3, 1}, {-0.95, -1, 0});
  EXPECT_EQ(sector.end.hit, 1);
}

// ---- Infinite surfaces (DESIGN.md section 1) ---------------------------------------------

// A cone of angle theta: the wedge from direction 0 to direction theta, its rays glued.
std::string cone_json(double theta) {
  return R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [)" + std::to_string(std::cos(theta)) +
         ", " + std::to_string(std::sin(theta)) + R"(]}]], "gluings": [[[0, 0], [0, 2]]]})";
}

int count(const OracleResult& r, EventKind kind) {
  return static_cast<int>(std::count_if(r.trace.events.begin(), r.trace.events.end(),
                                        [&](const Event& e) { return e.kind == kind; }));
}

TEST(OracleInfinite, ConeRaysCrossWhereTheUnfoldedWedgesPutThem) {
  // Unfolded, a ray is a straight line p + s d; its polar angle about the apex runs from that of
  // p by the signed angle delta from p to d, |delta| < pi, and it crosses a glued ray each time
  // that angle passes a multiple of the wedge's angle: at most ceil(pi / theta) times. The
  // crossing with the copy of the ray at angle a is where cross(p + s d, (cos a, sin a)) = 0,
  // at distance |p + s d| from the apex on the glued ray. After it the ray runs out to
  // max_distance.
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const double theta : {kPi / 3, kPi / 2, 2 * kPi / 3, kPi, 1.2 * kPi, 3 * kPi / 2}) {
    SCOPED_TRACE("theta " + std::to_string(theta));
    const Scene s = load(cone_json(theta));
    // The cone angle, the wedge's, parsed from six decimals.
    ASSERT_EQ(s.vertex_classes.size(), 1u);
    EXPECT_NEAR(s.vertex_classes[0].cone_angle, theta, 1e-6);
    const double wedge = s.vertex_classes[0].cone_angle;
    int most = 0;
    for (int n = 0; n < 200; ++n) {
      const double phi0 = wedge * (0.05 + 0.9 * unit(random)), r0 = 0.5 + 3.0 * unit(random);
      const Vec2 p = r0 * Vec2(std::cos(phi0), std::sin(phi0));
      const double heading = 2.0 * kPi * unit(random);
      const Vec2 d(std::cos(heading), std::sin(heading));
      const double delta = std::atan2(cross(p, d), glm::dot(p, d));
      if (std::abs(std::abs(delta) - kPi) < 1e-3) continue;  // aimed at the apex
      std::vector<double> by_hand;  // path lengths of the crossings, in order
      for (int k = -8; k <= 8; ++k) {
        const double a = k * wedge;
        if ((a - phi0) * (a - phi0 - delta) >= 0.0) continue;  // not passed
        const Vec2 u(std::cos(a), std::sin(a));
        const double at = -cross(p, u) / cross(d, u);
        if (at < MarchParams{}.max_distance) by_hand.push_back(at);  // else beyond the end
      }
      std::sort(by_hand.begin(), by_hand.end());
      const OracleResult r = trace(s, Vec3(p, 1.0), Vec3(d, 0.0));
      std::vector<const Event*> crossings;
      for (const Event& e : r.trace.events)
        if (e.kind == EventKind::gluing) crossings.push_back(&e);
      ASSERT_EQ(crossings.size(), by_hand.size()) << "ray " << n;
      for (size_t k = 0; k < by_hand.size(); ++k) {
        EXPECT_NEAR(crossings[k]->t, by_hand[k], 1e-9);
        EXPECT_NEAR(glm::length(Vec2(crossings[k]->at)), glm::length(p + by_hand[k] * d), 1e-9);
      }
      most = std::max(most, static_cast<int>(by_hand.size()));
      EXPECT_LE(static_cast<int>(by_hand.size()), static_cast<int>(std::ceil(kPi / theta - 1e-9)));
      EXPECT_EQ(r.end.hit, kHitMaxDistance) << "ray " << n;
      EXPECT_NEAR(r.end.t, MarchParams{}.max_distance, 1e-9);
    }
    // Some rays cross as often as the bound allows.
    EXPECT_EQ(most, static_cast<int>(std::ceil(kPi / theta - 1e-9)));
  }
}

TEST(OracleInfinite, ARayAimedAtTheApexEndsThere) {
  const Scene s = load(cone_json(kPi / 2));
  const OracleResult r = trace(s, {1, 1, 1}, {-1, -1, 0});
  EXPECT_EQ(r.end.hit, kHitVertex);
  EXPECT_NEAR(r.end.t, std::sqrt(2.0), 1e-9);
  EXPECT_EQ(count(r, EventKind::gluing), 0);
}

TEST(OracleInfinite, TwoWedgesMakeAConeOf3Pi) {
  // Wedges of 3 pi / 2, each one's ray along -y glued to the other's along +x: a straight line
  // sweeps less than pi about the apex, so it crosses once at most, into the other wedge.
  const Scene s = load(R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, -1]}],
                                        [[0, 0], {"to": [1, 0]}, {"to": [0, -1]}]],
                           "gluings": [[[0, 2], [1, 0]], [[1, 2], [0, 0]]]})");
  ASSERT_EQ(s.vertex_classes.size(), 1u);
  EXPECT_NEAR(s.vertex_classes[0].cone_angle, 3 * kPi, 1e-12);
  // From (-1, -1) (angle 5 pi / 4) along +x: crosses the ray along -y at (0, -1), t = 1, into
  // wedge 1 at its ray along +x, (1, 0) (the quarter turn), then runs on along +y.
  const OracleResult r = trace(s, {-1, -1, 1}, {1, 0, 0});
  ASSERT_EQ(count(r, EventKind::gluing), 1);
  expect_gluing(r.trace.events[0], 0, 2, 1, 0, 1.0, {0, -1, 1});
  EXPECT_EQ(r.end.polygon, 1);
  expect_near(r.end.at, {1, MarchParams{}.max_distance - 1.0, 1});
}

TEST(OracleInfinite, CylinderRaysCrossItsGluedRaysKTimesAUnitOfY) {
  // Circumference 1: along (k, 1) from (0.5, 0.5) the unfolded line meets x = m at
  // y = 0.5 + (m - 0.5) / k, on the right ray (edge 1) at (1, y): k crossings a unit of y.
  const Scene s = load(R"({"polygons": [[[0, 0], [1, 0], {"to": [0, 1]}, {"to": [0, 1]}]],
                           "gluings": [[[0, 1], [0, 3]]]})");
  for (const int k : {1, 2, 3, 5}) {
    SCOPED_TRACE("k " + std::to_string(k));
    const double length = std::hypot(k, 1.0);
    MarchParams params;
    params.max_distance = 10.0 * length;  // 10 units of y
    const OracleResult r = trace(s, {0.5, 0.5, 1}, {k, 1, 0}, 0, params);
    ASSERT_EQ(count(r, EventKind::gluing), 10 * k);
    for (int m = 1; m <= 10 * k; ++m) {
      const double y = 0.5 + (m - 0.5) / k;
      expect_gluing(r.trace.events[static_cast<size_t>(m - 1)], 0, 1, 0, 3, (y - 0.5) * length,
                    {1, y, 1});
    }
    EXPECT_EQ(r.end.hit, kHitMaxDistance);
  }
}

TEST(OracleInfinite, NothingCrossesTheEdgeAtInfinity) {
  // The half-strip's edge at infinity is edge 2: a ray straight up the strip never meets it,
  // and the base below is a mirror (the default boundary).
  const Scene s = load(R"({"polygons": [[[0, 0], [1, 0], {"to": [0, 1]}, {"to": [0, 1]}]],
                           "gluings": [[[0, 1], [0, 3]]]})");
  EXPECT_EQ(s.polygons[0].edges[2].kind, EdgeKind::infinity);
  const OracleResult up = trace(s, {0.5, 0.5, 1}, {0, 1, 0});
  EXPECT_EQ(up.end.hit, kHitMaxDistance);
  EXPECT_TRUE(up.trace.events.size() == 1);
  // Straight down: the mirror at y = 0, 0.5 away, turns it back up, and it runs out 99.5 up.
  const OracleResult down = trace(s, {0.5, 0.5, 1}, {0, -1, 0});
  EXPECT_EQ(count(down, EventKind::mirror), 1);
  EXPECT_EQ(down.end.hit, kHitMaxDistance);
  expect_near(down.end.at, {0.5, MarchParams{}.max_distance - 0.5, 1});
}

TEST(Intersect, EachSolidExactly) {
  Object sphere;
  sphere.type = ObjectType::sphere;
  sphere.radius = 1;
  auto hit = intersect(sphere, {-3, 0, 0}, {1, 0, 0}, 0, 10);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 2, kTol);
  expect_near(hit->normal, {-1, 0, 0});
  EXPECT_FALSE(intersect(sphere, {-3, 1.01, 0}, {1, 0, 0}, 0, 10));
  EXPECT_FALSE(intersect(sphere, {-3, 0, 0}, {1, 0, 0}, 0, 1.9));  // beyond the segment

  Object box;
  box.type = ObjectType::box;
  box.half = {1, 2, 3};
  hit = intersect(box, {0, -5, 0}, {0, 1, 0}, 0, 10);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 3, kTol);
  expect_near(hit->normal, {0, -1, 0});
  // Diagonally from (-5, -5): x enters at 4 sqrt 2, y at 3 sqrt 2: the x face is hit.
  hit = intersect(box, {-5, -5, 0}, glm::normalize(Vec3(1, 1, 0)), 0, 20);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 4 * std::sqrt(2.0), kTol);
  expect_near(hit->normal, {-1, 0, 0});

  // A capped cylinder of radius 1 from z = 0 to 2: its side, its top cap, and its bottom.
  hit = intersect_cylinder({0, 0}, 1, 0, 2, {-3, 0, 1}, {1, 0, 0}, 0, 10);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 2, kTol);
  expect_near(hit->normal, {-1, 0, 0});
  hit = intersect_cylinder({0, 0}, 1, 0, 2, {0.5, 0, 5}, {0, 0, -1}, 0, 10);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 3, kTol);
  expect_near(hit->normal, {0, 0, 1});
  hit = intersect_cylinder({0, 0}, 1, 0, 2, {0, 0, -1}, {0, 0, 1}, 0, 10);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 1, kTol);
  expect_near(hit->normal, {0, 0, -1});
  // Sloping down from (3, 0, 2.2) along (-1, 0, -0.25): the side x = 1 at u = 2, z = 1.7.
  const Vec3 slope = glm::normalize(Vec3(-1, 0, -0.25));
  hit = intersect_cylinder({0, 0}, 1, 0, 2, {3, 0, 2.2}, slope, 0, 10);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 2 * std::sqrt(1.0625), kTol);
  expect_near(hit->normal, {1, 0, 0});
}

TEST(Intersect, HollowCubeIsTheCubeMinusTheSphere) {
  Object cube;
  cube.type = ObjectType::hollow_cube;
  cube.size = 1;    // the cube [-1, 1]^3
  cube.hole = 1.3;  // cuts a disk of radius sqrt(1.3^2 - 1) = 0.83 out of each face
  // A face point outside the hole: (-1, 0.95, 0.95) is 1.67 from the centre.
  auto hit = intersect(cube, {-3, 0.95, 0.95}, {1, 0, 0}, 0, 10);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 2, kTol);
  expect_near(hit->normal, {-1, 0, 0});
  // Along the axis the whole chord through the cube (x in [-1, 1]) lies inside the hole.
  EXPECT_FALSE(intersect(cube, {-3, 0, 0}, {1, 0, 0}, 0, 10));
  // From (-2, 0, 0) along (1, .45, .45): the cube spans u in [1, 20/9]; at u = 1 the face point
  // (-1, .45, .45) is in the hole (.45^2 + .45^2 < .69); the sphere (u - 2)^2 + 2 (.45 u)^2 =
  // 1.69 is left at u = (4 + sqrt(16 - 4 * 1.405 * 2.31)) / (2 * 1.405), inside the cube: the ray
  // hits the cavity's far wall, whose normal points to the centre.
  const Vec3 d = Vec3(1, 0.45, 0.45);
  const double u = (4 + std::sqrt(16 - 4 * 1.405 * 2.31)) / (2 * 1.405);
  hit = intersect(cube, {-2, 0, 0}, glm::normalize(d), 0, 10);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, u * glm::length(d), kTol);
  const Vec3 p = Vec3(-2, 0, 0) + u * d;
  expect_near(hit->normal, -p / 1.3);
}

TEST(Camera, RaysOfDesignSection2) {
  // An odd image's centre pixel looks along F.
  auto c = camera_basis(0.0, 0.0, 90.0, 3, 3);
  expect_near(camera_ray(c, 1, 1, 3, 3), {1, 0, 0});
  c = camera_basis(90.0, 0.0, 90.0, 3, 3);
  expect_near(camera_ray(c, 1, 1, 3, 3), {0, 1, 0});
  c = camera_basis(0.0, 90.0, 60.0, 3, 3);
  expect_near(camera_ray(c, 1, 1, 3, 3), {0, 0, 1});
  // The top-left pixel of 4x2 at fov 90: u = (2 * 0.5 / 4 - 1) * 2 = -1.5, v = 0.5, with
  // R = (0, -1, 0) and U = (0, 0, 1): normalize(1, 1.5, 0.5) -- up and to the left (+y).
  c = camera_basis(0.0, 0.0, 90.0, 4, 2);
  expect_near(camera_ray(c, 0, 0, 4, 2), glm::normalize(Vec3(1, 1.5, 0.5)));
}

// DESIGN.md section 1 (Appearance), by hand: the sky gradient seen along a direction rising dz,
// through the display curve (an exposure of 0.8, then Narkowicz's fit of ACES).
double display(double linear) {
  const double x = 0.8 * linear;
  return std::min(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 1.0);
}
Vec3 sky_seen(const Look& look, double dz) {
  const Vec3 c = look.fog + std::sqrt(dz) * (look.sky - look.fog);
  return {display(c.x), display(c.y), display(c.z)};
}

TEST(OracleRender, LookingStraightUpEverythingEscapes) {
  // From the centre of the 4x4 torus at z = 1 looking up with a 60 degree field of view, every
  // ray reaches z = 2 within 1 of its start horizontally: one step, no crossing, escape, and the
  // sky's colour at its height.
  const Scene s = load(test::torus_json());
  Camera cam{0, {2, 2, 1}, 0.0, 90.0, 60.0};
  const Frame f = OracleBackend().render(s, cam, 8, 6, {}, {});
  const CameraBasis<double> basis = camera_basis(0.0, 90.0, 60.0, 8, 6);
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 8; ++i) {
      const size_t px = f.pixel(i, j);
      EXPECT_EQ(f.hit[px], kHitEscape);
      EXPECT_EQ(f.steps[px], 1);
      EXPECT_EQ(f.crossings[px], 0);
      const Vec3 d = camera_ray(basis, i, j, 8, 6);
      EXPECT_FLOAT_EQ(f.t[px], static_cast<float>(1.0 / d.z));
      const Vec3 sky = sky_seen(s.look, d.z);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(f.rgb[3 * px + static_cast<size_t>(k)], sky[k], 1e-6);
    }
}

// DESIGN.md section 1 (Appearance), by hand: a torus whose gluing 0 (bottom to top) is red and
// gluing 1 (right to left) green, walls of opacity 0.2 at normal incidence, a black fog far
// away. A ray from the centre crosses one wall (max_distance ends it before the next): the
// light it gathers is the wall's opacity times its colour, and the share that passes 1 - a.
TEST(OracleRender, AGluedWallTintsInItsColourMoreAtGrazingIncidence) {
  const Scene s = load(test::torus_json(
      R"("look": {"wall_tint": 0.2, "fog": [0, 0, 0], "fog_distance": 1e9,
                  "gluings": [[1, 0, 0], [0, 1, 0]]})"));
  struct Case {
    Vec3 from, dir;
    double max_distance;
    Vec3 colour;
    double cosine;  // of the direction with the crossed wall's normal
  };
  const double c60 = std::cos(kPi / 3.0), s60 = std::sin(kPi / 3.0);
  const Case cases[] = {
      {{2, 2, 1}, {1, 0, 0}, 3.0, {0, 1, 0}, 1.0},      // the right wall (gluing 1) head-on
      {{2, 2, 1}, {c60, s60, 0}, 2.5, {1, 0, 0}, s60},  // the top (gluing 0) at 30 degrees
      {{2, 2, 1}, {s60, c60, 0}, 2.5, {0, 1, 0}, s60},  // the right at 30 degrees
      // The right wall at grazing incidence: about 3.4 times the opacity.
      {{3.99, 2, 1}, {0.1, 1, 0}, 1.5, {0, 1, 0}, 0.1 / std::hypot(0.1, 1.0)}};
  for (const Case& c : cases) {
    const double grazing = 1.0 - c.cosine;
    const double a = 0.2 * (1.0 + 3.0 * grazing * grazing);
    MarchParams params;
    params.max_distance = c.max_distance;
    const RayEnd end = trace(s, c.from, c.dir, 0, params).end;
    ASSERT_EQ(end.crossings, 1);
    ASSERT_EQ(end.hit, kHitMaxDistance);
    expect_near(end.light, a * c.colour, 1e-8);  // the fog 1e9 away: (1 - 2e-9) of the colour
    EXPECT_NEAR(end.clear, 1.0 - a, 1e-12);
    // The kernel (here in float64) gathers the same.
    params.method = Method::analytic;
    const auto tables = kernel::compile_scene<double>(s, params);
    // The torus's one feature set, the empty one (no objects, walls, mirrors, period, scaling
    // or floor): with_kernel here would compile all 64 (100 s under the sanitizers).
    auto k = kernel::bind_kernel<double, 0u>(tables);
    const auto r = k.march(0, c.from, glm::normalize(c.dir));
    EXPECT_EQ(r.crossings, 1);
    expect_near(Vec3(r.light), a * c.colour, 1e-8);
    EXPECT_NEAR(r.clear, 1.0 - a, 1e-12);
  }
}

// Seams (DESIGN.md section 1, Appearance), by hand: walls that tint nothing, a black fog far away,
// seams 0.1 radians wide of opacity 0.5, blue at corners and the band's ends, red at cone points.
// A ray that crosses a wall within 0.05 t (half the width at path length t) of a vertical edge
// of it, or of its bottom or top, gathers half the seam's colour and lets half through; elsewhere
// nothing. The torus's corners are one regular point; the L-shape's eight one cone point of 6 pi.
TEST(OracleRender, ASeamMarksACrossingNearACornerTheTopOrTheBottom) {
  const std::string look =
      R"("look": {"wall_tint": 0, "fog": [0, 0, 0], "fog_distance": 1e9,
                  "seams": {"width": 0.1, "opacity": 0.5, "colour": [0, 0, 1], "cones": [1, 0, 0]}})";
  const Scene torus = load(test::torus_json(look));
  const Scene l_shape = load(R"({"polygons": [[[0, 0], [2, 0], [4, 0], [4, 2], [2, 2], [2, 4],
                                               [0, 4], [0, 2]]],
      "gluings": [[[0, 0], [0, 5]], [[0, 1], [0, 3]], [[0, 2], [0, 7]], [[0, 4], [0, 6]]], )" +
                             look + "}");
  const Vec3 none(0.0), seam(0, 0, 0.5), cone(0.5, 0, 0);
  struct Case {
    const Scene* scene;
    Vec3 from, dir;
    Vec3 light;  // what the crossing gathers
  };
  const Case cases[] = {
      // The torus's right wall (x = 4) at t = 2: a seam within 0.1 of y = 0 or 4 and z = 0 or 2.
      {&torus, {2, 2, 1}, {1, 0, 0}, none},
      {&torus, {2, 0.09, 1}, {1, 0, 0}, seam},
      {&torus, {2, 0.11, 1}, {1, 0, 0}, none},
      {&torus, {2, 3.92, 1}, {1, 0, 0}, seam},
      {&torus, {2, 2, 0.05}, {1, 0, 0}, seam},
      {&torus, {2, 2, 1.95}, {1, 0, 0}, seam},
      {&torus, {2, 2, 1.85}, {1, 0, 0}, none},
      // The L-shape's right wall (x = 4, y in [0, 2]) at t = 1: a cone point's edge within 0.05.
      {&l_shape, {3, 1.96, 1}, {1, 0, 0}, cone},
      {&l_shape, {3, 0.03, 1}, {1, 0, 0}, cone},
      {&l_shape, {3, 1.9, 1}, {1, 0, 0}, none},
      {&l_shape, {3, 1, 0.02}, {1, 0, 0}, seam},  // its bottom: a seam, not a cone point
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(testing::Message() << "from " << c.from.x << ", " << c.from.y << ", " << c.from.z);
    MarchParams params;
    params.max_distance = c.from.x == 2 ? 3.0 : 1.5;  // past the wall, before the next
    const RayEnd end = trace(*c.scene, c.from, c.dir, 0, params).end;
    ASSERT_EQ(end.crossings, 1);
    expect_near(end.light, c.light, 1e-8);
    EXPECT_NEAR(end.clear, c.light == none ? 1.0 : 0.5, 1e-12);
    // The kernel, in float64, gathers the same.
    params.method = Method::analytic;
    const auto tables = kernel::compile_scene<double>(*c.scene, params);
    auto k = kernel::bind_kernel<double, 0u>(tables);
    const auto r = k.march(0, c.from, c.dir);
    EXPECT_EQ(r.crossings, 1);
    expect_near(Vec3(r.light), c.light, 1e-8);
    EXPECT_NEAR(r.clear, c.light == none ? 1.0 : 0.5, 1e-12);
  }
  // "seams": false draws none.
  const Scene plain = load(test::torus_json(R"("look": {"wall_tint": 0, "seams": false})"));
  MarchParams params;
  params.max_distance = 3.0;
  EXPECT_EQ(trace(plain, {2, 0.01, 1}, {1, 0, 0}, 0, params).end.light, Vec3(0.0));
}

// What the seams read of an edge (DESIGN.md section 1, Appearance), by hand: where its
// counterclockwise ends lie along it, (-n.y, n.x) with n its outward normal, and what they are.
// The L-shape's corners are one cone point, the torus's one regular point; the infinite cone of
// angle pi / 2 has its apex at the finite end of both its ray edges and nothing at infinity.
TEST(OracleRender, SeamRecordsSayWhereTheCornersAreAndWhichAreConePoints) {
  const Scene torus = load(test::torus_json());
  const Scene l_shape = load_scene(std::string(FLATMARCH_SOURCE_DIR) + "/scenes/l_shape.json");
  const Scene cone = load(R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, 1]}]],
                              "gluings": [[[0, 0], [0, 2]]], "camera": {"position": [1, 1, 1]}})");
  // The torus [0, 4]^2: bottom along +x, right along +y, top along -x, left along -y.
  EXPECT_EQ(kernel::seam_record(torus, 0, 0), glm::dvec4(0, 4, 1, 1));
  EXPECT_EQ(kernel::seam_record(torus, 0, 1), glm::dvec4(0, 4, 1, 1));
  EXPECT_EQ(kernel::seam_record(torus, 0, 2), glm::dvec4(-4, 0, 1, 1));
  EXPECT_EQ(kernel::seam_record(torus, 0, 3), glm::dvec4(-4, 0, 1, 1));
  // The L-shape's edge 3 runs from (4, 2) to (2, 2), along -x.
  EXPECT_EQ(kernel::seam_record(l_shape, 0, 3), glm::dvec4(-4, -2, 2, 2));
  for (int e = 0; e < 8; ++e) {
    EXPECT_EQ(kernel::seam_record(l_shape, 0, e).z, 2.0);
    EXPECT_EQ(kernel::seam_record(l_shape, 0, e).w, 2.0);
  }
  // The cone: edge 0 from the apex out along +x, edge 2 in along -y to the apex.
  EXPECT_EQ(kernel::seam_record(cone, 0, 0), glm::dvec4(0, 0, 2, 0));
  EXPECT_EQ(kernel::seam_record(cone, 0, 1), glm::dvec4(0, 0, 0, 0));
  EXPECT_EQ(kernel::seam_record(cone, 0, 2), glm::dvec4(0, 0, 0, 2));
  // The compiled tables hold them.
  const auto tables = kernel::compile_scene<float>(l_shape, MarchParams{});
  EXPECT_EQ(tables.edges[3].seam, glm::vec4(-4, -2, 2, 2));
}

// A translation prism's glued floor and ceiling tint too, in the colour one past the gluings'.
TEST(OracleRender, APrismsGluedCeilingTintsInTheColourAfterTheGluings) {
  const Scene s = load(test::torus_json(
      R"("period": 2, "look": {"wall_tint": 0.2, "fog": [0, 0, 0], "fog_distance": 1e9,
                               "gluings": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]})"));
  MarchParams params;
  params.max_distance = 1.5;  // from z = 1 straight up: through the ceiling at t = 1, once
  const RayEnd end = trace(s, {2, 2, 1}, {0, 0, 1}, 0, params).end;
  expect_near(end.light, 0.2 * Vec3(0, 0, 1), 1e-8);
  EXPECT_NEAR(end.clear, 0.8, 1e-12);
  EXPECT_THROW(load(test::torus_json(R"("look": {"gluings": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]})")),
               SceneError);
}

// A ray that fails is shaded as the fog, not black (issue 20); --show-failures paints it.
TEST(OracleRender, AFailedRayIsFogAndShowFailuresPaintsIt) {
  const Scene s = load(test::torus_json(R"("look": {"fog": [0.2, 0.3, 0.4]})"));
  MarchParams params;
  params.max_distance = 1.0;  // every ray from the centre ends inside the room
  Camera cam{0, {2, 2, 1}, 0.0, 0.0, 60.0};
  Frame f = OracleBackend().render(s, cam, 4, 2, params, {});
  for (size_t px = 0; px < f.hit.size(); ++px) {
    ASSERT_EQ(f.hit[px], kHitMaxDistance);
    EXPECT_NEAR(f.rgb[3 * px], display(0.2), 1e-6);
    EXPECT_NEAR(f.rgb[3 * px + 1], display(0.3), 1e-6);
    EXPECT_NEAR(f.rgb[3 * px + 2], display(0.4), 1e-6);
  }
  EXPECT_EQ(f.paint_failures({1, 0, 1}), 8);
  EXPECT_EQ(f.rgb[0], 1.0f);
  EXPECT_EQ(f.rgb[1], 0.0f);
}

// The floor's checks (DESIGN.md section 1), by hand: 0.5 wide, light (1) where the sum of the
// check indices is even, kFloorDark where odd; their contrast halves where a pixel's footprint
// t / |dz| reaches kFloorFade and vanishes into the mean far beyond, near the horizon.
TEST(OracleRender, FloorChecksFadeTowardsTheirMeanAsTheyShrinkBelowAPixel) {
  kernel::Kernel<double, 0u> k;
  const double dark = kFloorDark, mean = 0.5 * (1.0 + kFloorDark);
  EXPECT_NEAR(k.floor_tone({0.25, 0.25}, 0.0, -1.0), 1.0, 1e-6);
  EXPECT_NEAR(k.floor_tone({0.75, 0.25}, 0.0, -1.0), dark, 1e-6);
  EXPECT_NEAR(k.floor_tone({-0.25, 0.25}, 0.0, -1.0), dark, 1e-6);  // check -1
  EXPECT_NEAR(k.floor_tone({0.75, 0.75}, 0.0, -1.0), 1.0, 1e-6);
  // Seen from 2 straight above: nearly full contrast.
  EXPECT_NEAR(k.floor_tone({0.25, 0.25}, 2.0, -1.0), mean + (1 - mean) / (1 + 1.0 / 900), 1e-6);
  // t / |dz| = kFloorFade: half the contrast, whether near and steep or far and grazing.
  EXPECT_NEAR(k.floor_tone({0.75, 0.25}, kFloorFade / 2, -0.5), mean + (dark - mean) / 2, 1e-6);
  EXPECT_NEAR(k.floor_tone({0.75, 0.25}, 6.0, -6.0 / kFloorFade), mean + (dark - mean) / 2, 1e-6);
  // 100 away at a grazing 1%: the mean, to 4e-5.
  EXPECT_NEAR(k.floor_tone({0.25, 0.25}, 100.0, -0.01), mean, 1e-4);
}

TEST(OracleRender, AovExrRoundTrip) {
  const Scene s = load_scene(FLATMARCH_SOURCE_DIR "/scenes/l_shape.json");
  const Frame f = OracleBackend().render(s, s.camera, 24, 16, {}, {});
  const std::string dir = test::make_temp_dir();
  write_aov_exr(f, dir + "/frame.exr");
  write_png(f, dir + "/frame.png");
  const Frame back = read_aov_exr(dir + "/frame.exr");
  ASSERT_EQ(back.width, 24);
  ASSERT_EQ(back.height, 16);
  EXPECT_EQ(back.rgb, f.rgb);
  EXPECT_EQ(back.steps, f.steps);
  EXPECT_EQ(back.crossings, f.crossings);
  EXPECT_EQ(back.hit, f.hit);
  EXPECT_EQ(back.t, f.t);
  EXPECT_TRUE(std::filesystem::file_size(dir + "/frame.png") > 0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace flatmarch
