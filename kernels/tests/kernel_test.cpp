// The kernel and its scene compiler against values worked out by hand: the tables of the torus,
// the feature sets of scenes, the GLSL the shaders will compile, and each defined failure mode
// (offset <= eps, max_steps, corners, grazing rays) ending with its documented event.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>

#include "backends/oracle/oracle.hpp"
#include "backends/scalar/scalar.hpp"
#include "kernels/compile.hpp"
#include "kernels/shader_source.hpp"
#include "scene/load.hpp"
#include "tests/process.hpp"
#include "tests/test_scenes.hpp"

namespace flatmarch {
namespace {

Scene load(const std::string& json) {
  return parse_scene(json, "test.json");
}

TEST(SceneCompiler, TorusTablesHoldItsEdgesAndMaps) {
  // The square [0, 4]^2: edge 0 (bottom) is glued to edge 2 (top) by (0, 4), edge 1 (right) to
  // edge 3 (left) by (-4, 0).
  const auto t = kernel::compile_scene<double>(load(test::torus_json()), {});
  EXPECT_EQ(t.features, 0u);  // no objects, mirrors, walls, period, floor or scaling
  ASSERT_EQ(t.polygons.size(), 1u);
  EXPECT_EQ(t.polygons[0], glm::ivec4(0, 4, 0, 0));
  ASSERT_EQ(t.edges.size(), 4u);
  EXPECT_TRUE(t.objects.empty());
  const auto& bottom = t.edges[0];
  EXPECT_EQ(bottom.segment, glm::dvec4(0, 0, 4, 0));
  EXPECT_EQ(bottom.line, glm::dvec4(0, -1, 0, 1.0 / 16));  // outward normal, n.a, 1/|ab|^2
  EXPECT_EQ(bottom.map_linear, glm::dvec4(1, 0, 0, 1));
  EXPECT_EQ(bottom.map_shift, glm::dvec4(0, 4, 0, 0));
  // For the seams: its ends at x = 0 and 4 along it (counterclockwise, (-n.y, n.x) = (1, 0)), both
  // corners of a regular point (the torus's one vertex class, of angle 2 pi).
  EXPECT_EQ(bottom.seam, glm::dvec4(0, 4, 1, 1));
  EXPECT_EQ(bottom.link, glm::ivec4(kEdgeGlued, 0, 2, 0));
  const auto& right = t.edges[1];
  EXPECT_EQ(right.line, glm::dvec4(1, 0, 4, 1.0 / 16));
  EXPECT_EQ(right.map_shift, glm::dvec4(-4, 0, 0, 0));
  EXPECT_EQ(right.seam, glm::dvec4(0, 4, 1, 1));  // along (0, 1), from y = 0 to 4
  EXPECT_EQ(right.link, glm::ivec4(kEdgeGlued, 0, 3, 0));
  EXPECT_EQ(t.params.height, 2.0);
  EXPECT_EQ(t.params.top, 2.0);
  EXPECT_EQ(t.params.polygon_count, 1);
  EXPECT_EQ(t.params.convex, 1);  // the square
}

// The parameters' convex flag is 1 where every room of the scene is convex, else 0: a room that
// turns right once anywhere (the L-shape's corner, a 270-degree wedge) clears it.
TEST(SceneCompiler, ParamsSayWhetherEveryRoomIsConvex) {
  const auto convex = [](const Scene& scene) {
    const int flag = kernel::compile_scene<float>(scene, {}).params.convex;
    EXPECT_EQ(kernel::compile_scene<double>(scene, {}).params.convex, flag);
    return flag;
  };
  EXPECT_EQ(convex(load(test::torus_json())), 1);
  EXPECT_EQ(convex(load(test::cube_json())), 1);
  EXPECT_EQ(convex(load_scene(std::filesystem::path(FLATMARCH_SOURCE_DIR) / "scenes/l_shape.json")),
            0);
  // A square beside a pentagon with a point on its bottom edge (a straight angle): both convex.
  EXPECT_EQ(convex(load(R"({"polygons": [[[0, 0], [1, 0], [1, 1], [0, 1]],
                                        [[0, 0], [1, 0], [2, 0], [2, 1], [0, 1]]],
                           "gluings": [[[0, 1], [1, 4]], [[0, 3], [1, 2]]]})")),
            1);
  // The same with the pentagon's second corner pushed in: the first room is convex, the
  // second not, so the scene is not.
  EXPECT_EQ(convex(load(R"({"polygons": [[[0, 0], [1, 0], [1, 1], [0, 1]],
                                        [[0, 0], [1, 0.5], [2, 0], [2, 1], [0, 1]]],
                           "gluings": [[[0, 1], [1, 4]], [[0, 3], [1, 2]]]})")),
            0);
  // A wedge of three quarter-turns.
  EXPECT_EQ(convex(load(R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, -1]}]],
                           "gluings": [[[0, 0], [0, 2]]]})")),
            0);
}

// In convex rooms the kernel's distance to the walls comes from the edges' lines, and so does
// the next nearest but at corners, within eps of two lines, where it is measured to the
// segments: the scene model's distance to the boundary, the nearest edge's number, and the
// distances to the other lines and edges worked out here.
TEST(Kernel, WallDistanceInAConvexRoomIsTheDistanceToItsBoundary) {
  const Scene s =
      load_scene(std::filesystem::path(FLATMARCH_SOURCE_DIR) / "scenes/double_pentagon.json");
  const auto t = kernel::compile_scene<double>(s, {});
  ASSERT_EQ(t.params.convex, 1);
  ASSERT_EQ(t.features, kFeatureObjects);  // a hollow cube
  auto k = kernel::bind_kernel<double, kFeatureObjects>(t);
  const double eps = t.params.eps;
  // The distance from p to edge e of `room`, by hand.
  const auto to_edge = [](const Polygon& room, int e, Vec2 p) {
    const Vec2 a = room.vertex(e), ab = room.vertex(e + 1) - a;
    const double h = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
    return glm::length(p - a - h * ab);
  };
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int far = 0;
  for (int p = 0; p < 2; ++p) {
    const Polygon& room = s.polygons[static_cast<size_t>(p)];
    for (int n = 0; n < 400; ++n) {
      // A point of the room, or one 1e-5 inside edge n % 5 (within eps = 1e-4), or 1e-5 inside
      // it near its end, within eps of the next edge too.
      Vec2 at;
      const int e = n % room.size();
      const Vec2 a = room.vertex(e), b = room.vertex(e + 1);
      const Vec2 inward = -room.edges[static_cast<size_t>(e)].normal;
      if (n % 3 == 0) {
        at = room.vertex(0) + unit(random) * (room.vertex(2) - room.vertex(0));
        at += 0.9 * unit(random) * (room.vertex(3) - at);
      } else if (n % 3 == 1) {
        at = a + (0.1 + 0.8 * unit(random)) * (b - a) + 1e-5 * inward;
      } else {
        at = b + 5e-5 * glm::normalize(a - b) + 1e-5 * inward;
      }
      ASSERT_TRUE(room.contains(at)) << p << " " << n;
      const auto d = k.wall_distance(p, glm::dvec2(at));
      EXPECT_NEAR(d.d, room.distance_to_boundary(at), 1e-12) << p << " " << n;
      int nearest = 0;
      for (int j = 1; j < room.size(); ++j)
        if (to_edge(room, j, at) < to_edge(room, nearest, at)) nearest = j;
      EXPECT_EQ(d.edge, nearest) << p << " " << n;
      // The next nearest: the nearest other line, or where that and the nearest edge are both
      // within eps, the nearest other edge.
      double next_line = 1e300, next_edge = 1e300;
      for (int j = 0; j < room.size(); ++j) {
        if (j == nearest) continue;
        const Vec2 normal = room.edges[static_cast<size_t>(j)].normal;
        next_line = std::min(next_line, glm::dot(normal, room.vertex(j) - at));
        next_edge = std::min(next_edge, to_edge(room, j, at));
      }
      far += d.d >= eps;
      const bool corner = d.d < eps && next_line < eps;
      EXPECT_NEAR(d.second, corner ? next_edge : next_line, 1e-12) << p << " " << n;
      if (n % 3 == 2) {
        EXPECT_TRUE(corner) << p << " " << n;
        EXPECT_LT(d.second, eps) << p << " " << n;
      }
    }
  }
  EXPECT_GT(far, 200);  // most of the room's own points are far from every edge
}

TEST(SceneCompiler, FeaturesAreWhatTheSceneUses) {
  const auto features = [](const std::string& extra) {
    return kernel::scene_features(load(test::torus_json(extra)));
  };
  EXPECT_EQ(features(R"("period": 3)"), kFeaturePeriod);
  EXPECT_EQ(features(R"("floor": true)"), kFeatureFloor);
  EXPECT_EQ(features(R"("objects": [{"type": "sphere", "polygon": 0, "center": [2, 2, 1],
                                      "radius": 0.5}])"),
            kFeatureObjects);
  EXPECT_EQ(features(R"("vertices": {"radius": 0.1})"), kFeatureObjects);
  // A unit square with mirrors below and on the left, a wall on the right, the top glued to the
  // bottom of a square twice its size by a similarity (scale 2).
  const Scene mixed = load(R"({"polygons": [[[0, 0], [1, 0], [1, 1], [0, 1]],
                                            [[0, 2], [2, 2], [2, 4], [0, 4]]],
                               "gluings": [{"edges": [[0, 2], [1, 0]], "map": "similarity"}],
                               "boundaries": [{"edge": [0, 1], "boundary": "wall"}]})");
  EXPECT_EQ(kernel::scene_features(mixed), kFeatureMirrors | kFeatureWalls | kFeatureScaled);
  // Rotations and reflections are isometries: the cube and the Klein bottle need no scaling.
  EXPECT_EQ(kernel::scene_features(load(test::cube_json())), 0u);
}

TEST(SceneCompiler, MarkersBecomeCylindersAtTheirCorners) {
  // Every corner of the torus is the one vertex class; with a marker it gets a cylinder of the
  // band's height at each of the square's four corners, numbered after the one object.
  const Scene s = load(test::torus_json(
      R"("objects": [{"type": "box", "polygon": 0, "center": [2, 2, 1], "half": [0.1, 0.2, 0.3]}],
         "vertices": {"radius": 0.25})"));
  const auto t = kernel::compile_scene<float>(s, {});
  ASSERT_EQ(t.objects.size(), 5u);
  EXPECT_EQ(t.polygons[0], glm::ivec4(0, 4, 0, 5));
  EXPECT_EQ(t.objects[0].info, glm::ivec4(kSolidBox, 0, 0, 0));
  EXPECT_FLOAT_EQ(t.objects[0].center.w, std::sqrt(0.01f + 0.04f + 0.09f));  // bounding radius
  for (int k = 1; k < 5; ++k) {
    EXPECT_EQ(t.objects[static_cast<size_t>(k)].info, glm::ivec4(kSolidCylinder, 1, 0, 0));
    EXPECT_EQ(t.objects[static_cast<size_t>(k)].shape, glm::vec4(0.25f, 1.0f, 0, 0));
  }
  EXPECT_EQ(glm::vec2(t.objects[2].center), glm::vec2(4, 0));  // the corner of vertex 1
}

// An unbounded room (DESIGN.md section 1, "Infinite surfaces") is compiled as its outline cut
// off kFarRadius out: the wedge of three quarter-turns from the ray along +x to the ray along -y
// has its two rays (finite end first) and its edge at infinity as the first of six far links,
// the other five after them.
TEST(SceneCompiler, AnUnboundedRoomIsItsOutlineCutOffFarOut) {
  const Scene s = load(R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, -1]}]],
                           "gluings": [[[0, 0], [0, 2]]]})");
  const auto t = kernel::compile_scene<double>(s, {});
  EXPECT_EQ(t.features, 0u);
  ASSERT_EQ(t.polygons.size(), 1u);
  EXPECT_EQ(t.polygons[0], glm::ivec4(0, 3 + 5, 0, 0));
  const double far = kernel::kFarRadius;
  EXPECT_EQ(t.edges[0].segment, glm::dvec4(0, 0, far, 0));
  EXPECT_EQ(t.edges[0].link, glm::ivec4(kEdgeGlued, 0, 2, 0));
  EXPECT_EQ(t.edges[2].segment, glm::dvec4(0, 0, 0, -far));  // from the apex, its finite end
  EXPECT_EQ(t.edges[2].line, glm::dvec4(1, 0, 0, 1 / (far * far)));  // outward normal +x
  // The links run round the arc at infinity, at least kFarRadius from the apex.
  for (int k : {1, 3, 4, 5, 6, 7}) {
    const glm::dvec4 seg = t.edges[static_cast<size_t>(k)].segment;
    EXPECT_GE(glm::length(glm::dvec2(seg.x, seg.y)), 0.99 * far) << k;
    EXPECT_EQ(t.edges[static_cast<size_t>(k)].link.x, kEdgeWall) << k;
  }
  // A finite scene's tables hold its edges only.
  EXPECT_EQ(kernel::compile_scene<double>(load(test::torus_json()), {}).edges.size(), 4u);
  // Rays are kept within kReach of the origin.
  MarchParams far_off;
  far_off.max_distance = 2 * kernel::kReach;
  EXPECT_THROW(kernel::compile_scene<float>(s, far_off), std::invalid_argument);
  EXPECT_NO_THROW(kernel::compile_scene<float>(load(test::torus_json()), far_off));
}

// Within reach, the kernel's distance to a ray edge is the distance to the half-line and its
// exit is the half-line's: the scene model's, in float64 to rounding and in float32 to its
// resolution at the distances involved.
TEST(Kernel, RayEdgesAreHalfLinesWithinReach) {
  const Scene s = load(R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, -1]}]],
                           "gluings": [[[0, 0], [0, 2]]]})");
  const Polygon& w = s.polygons[0];
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto check = [&]<typename real>(real tolerance) {
    const auto t = kernel::compile_scene<real>(s, {});
    // Its one feature set, the empty one (no objects, walls, mirrors, period, scaling or floor).
    auto k = kernel::bind_kernel<real, 0u>(t);
    EXPECT_THROW((kernel::bind_kernel<real, kFeatureFloor>(t)), std::invalid_argument);
    for (int n = 0; n < 300; ++n) {
      const double r = std::pow(10.0, 3.0 * (unit(random) + 1.0) / 2.0);  // 1 to 1000
      const Vec2 p = r * Vec2(unit(random), unit(random));
      if (!w.contains(p)) continue;
      const auto d = k.wall_distance(0, glm::vec<2, real>(p));
      EXPECT_NEAR(static_cast<double>(d.d), w.distance_to_boundary(p), tolerance * r) << n;
      const double angle = kPi * unit(random);
      const Vec2 dir(std::cos(angle), std::sin(angle));
      const auto x = k.exit_edge(0, glm::vec<2, real>(p), glm::vec<2, real>(dir));
      const Polygon::Exit want = w.exit(p, dir, 1e-9, 1e-9);
      // A far link (edge 1, the edge at infinity, and 3 on) is no exit.
      EXPECT_EQ(x.edge == 0 || x.edge == 2 ? x.edge : -1, want.edge) << n;
      if (want.edge >= 0) {
        EXPECT_NEAR(static_cast<double>(x.s), want.s, tolerance * (r + want.s)) << n;
      } else {
        EXPECT_GT(static_cast<double>(x.s), kernel::kReach) << n;
      }
    }
  };
  check(1e-12);
  check(1e-5f);
}

TEST(ShaderSource, IsValidGlslForEveryFeatureSet) {
  bool found = false;
  try {
    found = test::run_process({"glslangValidator", "--version"}).exit_code == 0;
  } catch (const std::runtime_error&) {
  }
  if (!found)
    GTEST_SKIP() << "glslangValidator is not installed (ci/install-deps.sh installs glslang-tools)";
  const std::filesystem::path dir = test::make_temp_dir();
  for (uint features = 0; features < kFeatureCount; ++features) {
    const std::filesystem::path shader = dir / ("kernel" + std::to_string(features) + ".comp");
    std::ofstream(shader) << kernel::shader_source(features)
                          << "layout(local_size_x = 1) in;\n"
                             "void main() { Ray r = march(0, vec3(0.5), vec3(1, 0, 0)); }\n";
    const test::ProcessResult r = test::run_process(
        {"glslangValidator", "-V", shader.string(), "-o", (dir / "kernel.spv").string()});
    EXPECT_EQ(r.exit_code, 0) << "features " << features << ":\n" << r.out << r.err;
  }
  std::filesystem::remove_all(dir);
}

// ---- Defined failure modes, on the torus [0, 4]^2 of height 2 --------------------------------

Trace scalar_trace(const Scene& s, Vec3 from, Vec3 dir, MarchParams params, int max_events = 64) {
  return ScalarBackend().trace(s, Ray{0, from, dir}, params, max_events);
}

MarchParams with(Method method, double eps = 1e-4, double offset = 2e-4, int max_steps = 1024) {
  MarchParams p;
  p.method = method;
  p.eps = eps;
  p.offset = offset;
  p.max_steps = max_steps;
  return p;
}

TEST(FailureModes, OffsetNotAboveEpsPingPongsUntilMaxSteps) {
  // Along +x from (2, 2): the right edge is reached at t = 2. Placed offset <= eps inside the
  // left edge, the point is within eps of it and crosses straight back, and so on.
  const Scene s = load(test::torus_json());
  for (Method m : {Method::sphere, Method::relaxed}) {
    for (double offset : {0.5e-4, 0.99e-4}) {
      const Trace tr = scalar_trace(s, {2, 2, 1}, {1, 0, 0}, with(m, 1e-4, offset, 200), 300);
      ASSERT_GE(tr.events.size(), 3u);
      EXPECT_EQ(tr.steps, 200);
      EXPECT_EQ(tr.events.back().kind, EventKind::max_steps);
      EXPECT_EQ(tr.events[0].edge, 1);
      EXPECT_EQ(tr.events[1].edge, 3);  // straight back through the left edge
      EXPECT_EQ(tr.events[2].edge, 1);
      EXPECT_NEAR(tr.events.back().t, 2.0, 1e-4);  // it never gets further
    }
    // Just above eps the same ray goes on: it crosses the right edge every 4 units.
    const Trace ok = scalar_trace(s, {2, 2, 1}, {1, 0, 0}, with(m, 1e-4, 1.5e-4), 3);
    ASSERT_EQ(ok.events.size(), 3u);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(ok.events[static_cast<size_t>(k)].edge, 1);
      EXPECT_NEAR(ok.events[static_cast<size_t>(k)].t, 2.0 + 4.0 * k, 1e-3);
    }
  }
}

TEST(FailureModes, MaxStepsEndsTheRayAfterExactlyThatManyIterations) {
  const Scene s = load(test::torus_json());
  // Analytic: one iteration per room, crossing the right edge at t = 2, 6, 10.
  const Trace a = scalar_trace(s, {2, 2, 1}, {1, 0, 0}, with(Method::analytic, 1e-4, 2e-4, 3));
  ASSERT_EQ(a.events.size(), 4u);
  EXPECT_EQ(a.steps, 3);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a.events[static_cast<size_t>(k)].t, 2.0 + 4.0 * k, 1e-6);
  EXPECT_EQ(a.events[3].kind, EventKind::max_steps);
  EXPECT_NEAR(a.events[3].t, 10.0, 1e-6);
  // Sphere tracing: one step of 2 to the right edge, the crossing, then steps that double away
  // from the left edge, 2e-4, 4e-4 and 8e-4, which end at x = 1.6e-3.
  const Trace sp = scalar_trace(s, {2, 2, 1}, {1, 0, 0}, with(Method::sphere, 1e-4, 2e-4, 5));
  EXPECT_EQ(sp.steps, 5);
  ASSERT_EQ(sp.events.size(), 2u);
  EXPECT_NEAR(sp.events[0].t, 2.0, 1e-6);
  EXPECT_EQ(sp.events[1].kind, EventKind::max_steps);
  EXPECT_NEAR(sp.events[1].t, 2.0014, 1e-6);
  EXPECT_NEAR(sp.events[1].at.x, 1.6e-3, 1e-6);
}

TEST(FailureModes, ARayIntoACornerEndsAtTheVertex) {
  // From (2, 2) along (1, 1): the corner (4, 4) at t = 2 sqrt 2.
  const Scene s = load(test::torus_json());
  const double corner = 2.0 * std::sqrt(2.0);
  const Trace truth = OracleBackend().trace(s, Ray{0, {2, 2, 1}, {1, 1, 0}}, {}, 8);
  ASSERT_EQ(truth.events.size(), 1u);
  EXPECT_EQ(truth.events[0].kind, EventKind::vertex);
  for (Method m : kKernelMethods) {
    const Trace tr = scalar_trace(s, {2, 2, 1}, {1, 1, 0}, with(m));
    ASSERT_EQ(tr.events.size(), 1u) << to_string(m);
    EXPECT_EQ(tr.events[0].kind, EventKind::vertex) << to_string(m);
    // Sphere tracing stops once within eps of both edges: up to eps sqrt 2 before the corner.
    EXPECT_NEAR(tr.events[0].t, corner - 0.75e-4, 0.75e-4) << to_string(m);
    EXPECT_LE(tr.steps, 64);
  }
  // Sphere tracing cannot tell a corner from a ray passing within eps of it. 3e-5 beside the
  // diagonal, the distance to the top edge shrinks by 1 - 1/sqrt 2 a step, from 2 to 3.2e-5
  // after 9 steps, when the right edge is 6.2e-5 away: both within eps, a vertex. The oracle
  // (and the analytic method) cross the top edge 3e-5 from the corner.
  const Vec3 beside{2, 2 + 3e-5, 1};
  EXPECT_EQ(scalar_trace(s, beside, {1, 1, 0}, with(Method::sphere)).events[0].kind,
            EventKind::vertex);
  const Trace analytic = scalar_trace(s, beside, {1, 1, 0}, with(Method::analytic), 1);
  EXPECT_EQ(analytic.events[0].kind, EventKind::gluing);
  EXPECT_EQ(analytic.events[0].edge, 2);
}

TEST(FailureModes, AGrazingRayCreepsAlongTheWallUntilMaxSteps) {
  const Scene s = load(test::torus_json());
  // Along +x, 1.5 eps above the bottom edge: every sphere step is 1.5e-4 long, so 1024 steps
  // cover 0.154 of the 3.5 to the right edge.
  const Trace creep = scalar_trace(s, {0.5, 1.5e-4, 1}, {1, 0, 0}, with(Method::sphere));
  ASSERT_EQ(creep.events.size(), 1u);
  EXPECT_EQ(creep.events[0].kind, EventKind::max_steps);
  EXPECT_EQ(creep.steps, 1024);
  EXPECT_NEAR(creep.events[0].t, 1024 * 1.5e-4, 1e-4);
  // Within eps of the edge it runs along, the ray is carried through it: into the top of the
  // square, placed offset below the top edge, where it creeps on.
  const Trace carried = scalar_trace(s, {0.5, 0.5e-4, 1}, {1, 0, 0}, with(Method::sphere));
  ASSERT_EQ(carried.events.size(), 2u);
  EXPECT_EQ(carried.events[0].kind, EventKind::gluing);
  EXPECT_EQ(carried.events[0].edge, 0);
  EXPECT_EQ(carried.events[0].t, 0.0);
  EXPECT_EQ(carried.events[1].kind, EventKind::max_steps);
  EXPECT_NEAR(carried.events[1].at.y, 4.0 - 2e-4, 1e-6);
  // The analytic method follows the oracle: out through the right edge at t = 3.5.
  const Trace exact = scalar_trace(s, {0.5, 1.5e-4, 1}, {1, 0, 0}, with(Method::analytic), 1);
  EXPECT_EQ(exact.events[0].edge, 1);
  EXPECT_NEAR(exact.events[0].t, 3.5, 1e-6);
}

TEST(Kernel, AnalyticInFloat64FollowsTheOracleExactly) {
  // A ray through the L-shape that crosses 40 rooms and no object: in float64 the analytic
  // method computes the same exit points as the oracle, up to rounding.
  const Scene s = load_scene(std::filesystem::path(FLATMARCH_SOURCE_DIR) / "scenes/l_shape.json");
  const Ray ray{0, {0.3, 1.7, 1.0}, {0.8, 0.6526979, 0.001}};
  MarchParams p = with(Method::analytic);
  p.precision = Precision::f64;
  const Trace truth = OracleBackend().trace(s, ray, {}, 40);
  const Trace got = ScalarBackend().trace(s, ray, p, 40);
  ASSERT_EQ(truth.events.size(), 40u);
  ASSERT_EQ(got.events.size(), truth.events.size());
  for (size_t k = 0; k < truth.events.size(); ++k) {
    EXPECT_EQ(got.events[k].kind, truth.events[k].kind) << k;
    EXPECT_EQ(got.events[k].edge, truth.events[k].edge) << k;
    EXPECT_NEAR(got.events[k].t, truth.events[k].t, 1e-9) << k;
    EXPECT_NEAR(glm::distance(got.events[k].at, truth.events[k].at), 0.0, 1e-9) << k;
  }
}

TEST(Kernel, ShadesLikeTheOracle) {
  // Same scene, same rays: in float64 the analytic method's colours are the oracle's.
  const Scene s = load_scene(std::filesystem::path(FLATMARCH_SOURCE_DIR) / "scenes/torus.json");
  MarchParams p = with(Method::analytic);
  p.precision = Precision::f64;
  const Frame truth = OracleBackend().render(s, s.camera, 32, 18, {}, {});
  const Frame got = ScalarBackend().render(s, s.camera, 32, 18, p, {});
  size_t close = 0;
  for (size_t k = 0; k < truth.rgb.size(); ++k)
    close += std::abs(truth.rgb[k] - got.rgb[k]) < 1e-3f;
  EXPECT_GE(static_cast<double>(close) / static_cast<double>(truth.rgb.size()), 0.99);
}

}  // namespace
}  // namespace flatmarch
