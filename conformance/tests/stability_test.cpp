// Where methods fail: grazing rays, cone points, reflex corners, long paths, nearly parallel
// mirrors, tiny objects, offset <= eps, eps below float32's resolution. Each test asserts the
// documented behaviour (kernels/march.glsl, "Defined failures"): the right answer, or a failure
// of a named kind that the conformance library detects and reports, never silence.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>

#include "backends/oracle/oracle.hpp"
#include "backends/scalar/scalar.hpp"
#include "conformance/suite.hpp"
#include "conformance/tests/test_backends.hpp"
#include "kernels/compile.hpp"
#include "scene/load.hpp"
#include "tests/gallery.hpp"
#include "tests/test_scenes.hpp"

namespace flatmarch::conformance {
namespace {

constexpr int kEvents = 20;

// The backend under test (the test's parameter), and one that marches in float64 for the
// comparisons that need it: the backend itself where it can, else the scalar backend.
const Backend* g_kernel = nullptr;
const Backend& kernel() {
  return *g_kernel;
}
const Backend& f64_kernel() {
  static const ScalarBackend scalar;
  const std::vector<Precision> p = g_kernel->precisions();
  return std::find(p.begin(), p.end(), Precision::f64) != p.end() ? *g_kernel : scalar;
}

class Stability : public testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    if (const BackendEntry* e = find_backend_entry(GetParam()); e && !e->wrong_on_purpose.empty())
      GTEST_SKIP() << "the " << GetParam()
                   << " backend is wrong on purpose: " << e->wrong_on_purpose;
    g_kernel = &test::backend_named(GetParam());
    if (const Availability a = g_kernel->availability(); !a.available)
      GTEST_SKIP() << "the " << GetParam() << " backend is unavailable here: " << a.reason;
  }
};

MarchParams with(Method method, Precision precision = Precision::f32) {
  MarchParams p;
  p.method = method;
  p.precision = precision;
  return p;
}

Scene torus(const std::string& extra = "") {
  return parse_scene(test::torus_json(extra), "torus.json");
}

// The kernel's trace of `ray` against the oracle's, by the conformance library.
TraceComparison against_oracle(const Scene& scene, const Ray& ray, const MarchParams& p,
                               int events = kEvents) {
  const Trace got = kernel().trace(scene, ray, p, events);
  MarchParams exact = p;
  exact.method = Method::oracle;
  const Trace want = OracleBackend().trace(scene, ray, exact, events);
  return compare_traces(scene, got, want, p.eps);
}

uint8_t ambiguity(const Scene& scene, const Ray& ray, const MarchParams& p) {
  return ray_truth(scene, ray, p, ambiguity_delta(scene, p)).ambiguity;
}

int kernel_hit(const Scene& scene, const Ray& ray, const MarchParams& p) {
  const Trace t = kernel().trace(scene, ray, p, 5000);
  return end_code(t.events.back()).value_or(kHitMiss);  // cut short: no end
}

// --- Grazing rays along walls -----------------------------------------------------------------

TEST_P(Stability, GrazingAlongAnEdge) {
  // The torus: a ray along y = d, parallel to the bottom edge (glued to the top), d away from it.
  // Twenty units: five crossings of the right edge.
  const Scene scene = torus();
  const auto ray = [](double d) { return Ray{0, Vec3(0.5, d, 1.0), Vec3(1.0, 0.0, 0.0)}; };
  MarchParams sphere = with(Method::sphere), analytic = with(Method::analytic);
  sphere.max_distance = analytic.max_distance = 20.0;

  // Closer than eps: sphere tracing takes the bottom edge for one it reaches and crosses it, the
  // first event already another edge than the oracle's. The mask calls the ray ambiguous.
  const TraceComparison close = against_oracle(scene, ray(0.5 * sphere.eps), sphere);
  EXPECT_EQ(close.first_divergence, 0);
  EXPECT_EQ(close.failure, Failure::wrong_edge) << close.divergence;
  EXPECT_NE(ambiguity(scene, ray(0.5 * sphere.eps), sphere) & kNearEdge, 0);

  // A thousandth away, outside eps: the ray is decided, but sphere tracing creeps along the edge
  // in steps of its distance to it and runs out of steps: `stuck`, reported as such.
  EXPECT_EQ(ambiguity(scene, ray(1e-3), sphere), 0);
  const TraceComparison creep = against_oracle(scene, ray(1e-3), sphere);
  EXPECT_EQ(creep.failure, Failure::stuck) << creep.divergence;

  // A tenth away it follows the oracle; the analytic method, which has no eps for walls, follows
  // it at every distance that is not within rounding of the edge.
  EXPECT_FALSE(against_oracle(scene, ray(0.1), sphere).failure);
  for (const double d : {0.1, 1e-3, 0.5 * sphere.eps}) {
    EXPECT_EQ(ambiguity(scene, ray(d), analytic), 0) << d;
    const TraceComparison c = against_oracle(scene, ray(d), analytic);
    EXPECT_FALSE(c.failure) << d << ": " << c.divergence;
  }
}

// The gallery's L-shape without its object: nothing in the way of rays aimed at corners.
Scene empty_l_shape() {
  std::ifstream in(std::filesystem::path(FLATMARCH_SOURCE_DIR) / "scenes" / "l_shape.json");
  nlohmann::json doc = nlohmann::json::parse(in);
  doc.erase("objects");
  return scene_from_json(doc, "l_shape.json");
}

// --- Rays through and near cone points --------------------------------------------------------

// A corner of the scene's first singular vertex class, and where it lies.
std::pair<Corner, Vec2> cone_point(const Scene& scene) {
  for (const VertexClass& c : scene.vertex_classes)
    if (c.singular && !c.boundary) {
      const Corner k = c.corners.front();
      return {k, scene.polygons[static_cast<size_t>(k.polygon)].vertex(k.vertex)};
    }
  return {{-1, -1}, Vec2(0.0)};
}

TEST_P(Stability, ThroughAndNearAConePoint) {
  const Scene scene = empty_l_shape();  // one cone point, of angle 6 pi
  const auto [corner, v] = cone_point(scene);
  ASSERT_GE(corner.polygon, 0);
  const Polygon& polygon = scene.polygons[static_cast<size_t>(corner.polygon)];
  // From 0.3 inside the corner along its bisector.
  const int n = polygon.size();
  Vec2 inward = glm::normalize(glm::normalize(polygon.vertex(corner.vertex + 1) - v) +
                               glm::normalize(polygon.vertex(corner.vertex - 1) - v));
  if (!polygon.contains(v + 0.3 * inward)) inward = -inward;
  const Vec3 from(v + 0.3 * inward, 1.0);
  for (const Method m : kKernelMethods) {
    const MarchParams p = with(m);
    const double delta = ambiguity_delta(scene, p);
    const Vec2 to_v = glm::normalize(v - Vec2(from));
    const Vec2 side(-to_v.y, to_v.x);
    // Straight at it: the oracle ends with `vertex`; so may the kernel, or it crosses one of the
    // two edges that meet there. Either way the mask calls the pixel ambiguous.
    const Ray at{corner.polygon, from, Vec3(to_v, 0.0)};
    EXPECT_NE(ambiguity(scene, at, p) & kNearVertex, 0) << to_string(m);
    const Trace t = kernel().trace(scene, at, p, 2);
    const Event& first = t.events.front();
    const bool adjacent = first.edge == corner.vertex || first.edge == (corner.vertex + n - 1) % n;
    EXPECT_TRUE(first.kind == EventKind::vertex || adjacent)
        << to_string(m) << ": " << describe(first);
    // Passing it at ten times delta on either side: decided, and followed event by event.
    for (const double sign : {-1.0, 1.0}) {
      const Vec2 aim = v + sign * 10.0 * delta * side;
      const Ray past{corner.polygon, from, Vec3(glm::normalize(aim - Vec2(from)), 0.0)};
      if (ambiguity(scene, past, p) != 0) continue;  // ambiguous further on, at another vertex
      const TraceComparison c = against_oracle(scene, past, p);
      EXPECT_FALSE(c.failure) << to_string(m) << " side " << sign << ": " << c.divergence;
    }
  }
}

// --- Reflex corners --------------------------------------------------------------------------

TEST_P(Stability, PastAReflexCorner) {
  const Scene scene = empty_l_shape();  // the L's inner corner (2, 2), 270 degrees
  const Polygon& polygon = scene.polygons[0];
  int reflex = -1;
  for (int k = 0; k < polygon.size(); ++k)
    if (polygon.corner_angle(k) > kPi + 1e-9) reflex = k;
  ASSERT_GE(reflex, 0);
  const Vec2 v = polygon.vertex(reflex);
  // From (0.5, 0.5) diagonally past the corner, d to the side of it: beyond it, one side goes
  // on into the upper arm, the other into the lower one.
  for (const Method m : kKernelMethods) {
    const MarchParams p = with(m);
    for (const double d : {-0.3 * p.eps, 0.3 * p.eps, -10.0 * ambiguity_delta(scene, p),
                           10.0 * ambiguity_delta(scene, p), 0.05}) {
      const Vec2 from(0.5, 0.5);
      const Vec2 aim = v + d * glm::normalize(Vec2(-1.0, 1.0));
      const Ray ray{0, Vec3(from, 1.0), Vec3(glm::normalize(aim - from), 0.0)};
      const uint8_t a = ambiguity(scene, ray, p);
      const TraceComparison c = against_oracle(scene, ray, p);
      const Trace t = kernel().trace(scene, ray, p, kEvents);
      if (std::abs(d) < p.eps && m != Method::analytic) {
        // Within eps of both edges at once: the documented `vertex` end, at the first event;
        // the mask calls the ray ambiguous.
        EXPECT_EQ(t.events.front().kind, EventKind::vertex) << to_string(m) << " d " << d;
        EXPECT_NE(a & kNearVertex, 0) << to_string(m) << " d " << d;
      } else if (std::abs(d) < 0.01) {
        // Ten times delta away (and the analytic method, which has no eps for walls, at a third
        // of eps): decided, and followed event by event.
        EXPECT_EQ(a, 0) << to_string(m) << " d " << d;
        EXPECT_FALSE(c.failure) << to_string(m) << " d " << d << ": " << c.divergence;
      } else {
        // Further away the path itself comes near other corners; where it does not, it agrees.
        if (a == 0) {
          EXPECT_FALSE(c.failure) << to_string(m) << ": " << c.divergence;
        }
      }
    }
  }
}

// A convex room with two edges on one line (a straight angle at (0, -1)), glued to each other
// about that point, as the web app's pillowcase is: near the bottom both edges' lines are within
// eps, but only one segment. A ray meeting the bottom a tenth away from that point crosses
// the edge it meets (the oracle's path), not a `vertex` end: the kernel once took two near lines
// for a corner.
TEST_P(Stability, ThroughEdgesOnOneLine) {
  const Scene scene = parse_scene(R"({
    "polygons": [[[0, 1], [-2, 1], [-2, -1], [0, -1], [2, -1], [2, 1]]],
    "gluings": [[[0, 0], [0, 5]], [[0, 1], [0, 4]], [[0, 2], [0, 3]]],
    "height": 4, "camera": {"position": [0.5, 0.5, 2]}})",
                                  "straight_angle.json");
  ASSERT_EQ(kernel::compile_scene<float>(scene, with(Method::sphere)).params.convex, 1);
  for (const Method m : kKernelMethods) {
    const MarchParams p = with(m);
    for (const double x : {0.1, -0.1, 0.5}) {
      const Ray ray{0, Vec3(0.0, 0.0, 2.0), glm::normalize(Vec3(x, -1.0, 0.05))};
      const TraceComparison c = against_oracle(scene, ray, p, 6);
      EXPECT_FALSE(c.failure) << to_string(m) << " x " << x << ": " << c.divergence;
      const Trace t = kernel().trace(scene, ray, p, 1);
      ASSERT_FALSE(t.events.empty());
      EXPECT_EQ(t.events.front().kind, EventKind::gluing) << to_string(m) << " x " << x;
    }
  }
}

// --- Long paths, float32 against float64 -----------------------------------------------------

TEST_P(Stability, AThousandCrossingsInFloat32AndFloat64) {
  const Scene scene = torus();
  // An irrational slope: the path never closes, and stays far from the corners for long.
  const Ray ray{0, Vec3(1.3, 0.7, 1.0), Vec3(1.0, 0.6180339887498949, 0.0)};
  MarchParams p32 = with(Method::analytic), p64 = with(Method::analytic, Precision::f64);
  for (MarchParams* p : {&p32, &p64}) {
    p->max_distance = 4000.0;
    p->max_steps = 100000;
  }
  constexpr int kMany = 1500;
  MarchParams exact = p64;
  exact.method = Method::oracle;
  const Trace want = OracleBackend().trace(scene, ray, exact, kMany);
  ASSERT_GE(want.events.size(), 1000u);
  const Trace got64 = f64_kernel().trace(scene, ray, p64, kMany);
  const Trace got32 = kernel().trace(scene, ray, p32, kMany);
  const TraceComparison c64 = compare_traces(scene, got64, want, p64.eps);
  const TraceComparison c32 = compare_traces(scene, got32, want, p32.eps);
  std::cout << "crossings " << want.events.size() << "; float64 agrees on " << c64.compared
            << " events, position error " << c64.max_position_error << "; float32 on "
            << (c32.first_divergence < 0 ? c32.compared : c32.first_divergence)
            << ", position error " << c32.max_position_error << "\n";
  // float64 follows every crossing, to within its rounding.
  EXPECT_EQ(c64.first_divergence, -1) << c64.divergence;
  EXPECT_LT(c64.max_position_error, 1e-9);
  // float32 drifts, within the mask's bound for the analytic method: 32 u scale + 16 u scale a
  // crossing + 4 u a unit of length (u = 2^-24).
  const double u = 0x1p-24, scale = scene.scale;
  const double bound = 32.0 * u * scale + 16.0 * u * scale * kMany + 4.0 * u * p32.max_distance;
  EXPECT_LT(c32.max_position_error, bound);
  EXPECT_GT(c32.max_position_error, 1000.0 * c64.max_position_error);
}

// --- Nearly parallel mirrors ---------------------------------------------------------------

TEST_P(Stability, IntoTheCornerOfNearlyParallelMirrors) {
  // A mirror triangle with a 2.9 degree corner at the origin: a ray into it bounces about 60
  // times before it comes back out.
  const Scene scene = parse_scene(R"({"polygons": [[[0, 0], [4, 0], [4, 0.2]]],
                                      "boundaries": [{"edge": [0, 1], "boundary": "wall"}]})",
                                  "acute.json");
  int decided = 0, stuck = 0, vertex = 0;
  for (int k = 0; k < 16; ++k) {
    const double y = 0.02 + 0.01 * k;
    const Ray ray{0, Vec3(3.9, y * 3.9 / 4.0 * 0.5, 1.0), Vec3(-1.0, -0.001 * k, 0.0)};
    for (const Method m : {Method::sphere, Method::analytic}) {
      const MarchParams p = with(m);
      if (ambiguity(scene, ray, p) != 0) continue;
      ++decided;
      MarchParams exact = p;
      exact.method = Method::oracle;
      const int want = oracle_trace(scene, ray, exact).end.hit;
      const int hit = kernel_hit(scene, ray, p);
      stuck += hit == kHitMaxSteps;
      vertex += hit == kHitVertex;
      if (m == Method::analytic)
        EXPECT_EQ(hit, want) << k;
      else
        EXPECT_TRUE(hit == want || hit == kHitMaxSteps) << k << ": " << hit << " for " << want;
    }
  }
  std::cout << decided << " decided rays; sphere tracing stuck on " << stuck << ", vertex on "
            << vertex << "\n";
  EXPECT_GT(decided, 8);
}

// --- Tiny objects ------------------------------------------------------------------------------

TEST_P(Stability, TinyObjects) {
  for (const double radius : {1e-2, 1e-4, 3e-5}) {
    const Scene scene = torus(R"("objects": [{"type": "sphere", "polygon": 0, "center": [2, 2, 1],
                                             "radius": )" +
                              std::to_string(radius) + "}]");
    for (const Method m : {Method::sphere, Method::analytic}) {
      const MarchParams p = with(m);
      const double delta = ambiguity_delta(scene, p);
      // Straight at it: every method hits it, however small.
      const Ray at{0, Vec3(1.0, 2.0, 1.0), Vec3(1.0, 0.0, 0.0)};
      EXPECT_EQ(kernel_hit(scene, at, p), 0) << radius << " " << to_string(m);
      // Passing it at half eps outside: the kernel, which stops within eps of a solid, hits it
      // where the oracle does not (a phantom hit); the mask calls the ray ambiguous.
      const Ray grazing{0, Vec3(1.0, 2.0 + radius + 0.5 * p.eps, 1.0), Vec3(1.0, 0.0, 0.0)};
      EXPECT_NE(ambiguity(scene, grazing, p) & kSilhouette, 0) << radius;
      MarchParams short_p = p;  // ends past the sphere, well clear of the edge at x = 4
      short_p.max_distance = 2.5;
      EXPECT_EQ(classify(kernel_hit(scene, grazing, short_p), 0, kHitMaxDistance, 0),
                Failure::phantom_hit)
          << radius << " " << to_string(m);
      // Three times (delta + eps) away: decided, and missed.
      const Ray clear{0, Vec3(1.0, 2.0 + radius + 3.0 * (delta + p.eps), 1.0), Vec3(1, 0, 0)};
      EXPECT_EQ(ambiguity(scene, clear, short_p), 0) << radius;
      EXPECT_EQ(kernel_hit(scene, clear, short_p), kHitMaxDistance) << radius;
    }
  }
}

// --- offset <= eps -----------------------------------------------------------------------------

TEST_P(Stability, OffsetNotAboveEpsCrossesBackAndForthUntilMaxSteps) {
  const Scene& scene = test::gallery_scene("torus");
  // Half eps: every ray that reaches a gluing crosses back and forth until max_steps; the suite
  // reports about half the frame stuck (the rest escape or meet the cube first).
  MarchParams half = with(Method::sphere);
  half.offset = 0.5 * half.eps;
  const Ray ray{0, Vec3(1.0, 2.0, 1.0), Vec3(1.0, 0.3, 0.0)};
  EXPECT_EQ(kernel().trace(scene, ray, half, 5000).events.back().kind, EventKind::max_steps);
  // Its trace shows where: right after the first crossing it crosses back (wrong_edge).
  EXPECT_EQ(against_oracle(scene, ray, half).failure, Failure::wrong_edge);
  Suite suite;
  CaseResult r = suite.run(kernel(), scene, half, 48, 27);
  EXPECT_FALSE(r.passed);
  EXPECT_GT(r.aov.failures[static_cast<size_t>(Failure::stuck)], r.aov.decided() / 3);
  // Exactly eps: the placed point lies eps inside, give or take rounding, and rounding decides:
  // on some backends some rays cross back and are stuck (the scalar backend: an eighth of the
  // frame; lavapipe: none). Whatever the backend does, the suite reports it.
  MarchParams equal = with(Method::sphere);
  equal.offset = equal.eps;
  r = suite.run(kernel(), scene, equal, 48, 27);
  const size_t stuck = r.aov.failures[static_cast<size_t>(Failure::stuck)];
  std::cout << GetParam() << ", offset = eps: " << stuck << " of " << r.aov.decided()
            << " decided pixels stuck\n";
  if (stuck > 0) {
    EXPECT_FALSE(r.passed);
  }
  // The analytic method does not push: offset does not matter to it.
  MarchParams p = with(Method::analytic);
  p.offset = 0.5 * p.eps;
  EXPECT_TRUE(suite.run(kernel(), scene, p, 48, 27).passed);
}

// --- eps below float32's resolution ------------------------------------------------------------

TEST_P(Stability, EpsBelowFloat32ResolutionAtTheScenesScale) {
  const Scene& scene = test::gallery_scene("torus");  // scale 4: float32 steps 2^-21 ~ 4.8e-7
  MarchParams p32 = with(Method::sphere), p64 = with(Method::sphere, Precision::f64);
  p32.eps = p64.eps = 1e-9;
  p32.offset = p64.offset = 2e-9;
  Suite suite;
  const CaseResult r32 = suite.run(kernel(), scene, p32, 48, 27);
  const CaseResult r64 = suite.run(f64_kernel(), scene, p64, 48, 27);
  const auto stuck = [](const CaseResult& r) {
    return static_cast<double>(r.aov.failures[static_cast<size_t>(Failure::stuck)]) /
           static_cast<double>(r.aov.decided());
  };
  std::cout << "eps 1e-9: float32 hit rate " << r32.aov.hit_rate() << ", stuck " << stuck(r32)
            << "; float64 hit rate " << r64.aov.hit_rate() << ", stuck " << stuck(r64) << "\n";
  // float32 positions 4 units from the origin step by 4.8e-7: sphere tracing cannot get within
  // 1e-9 of a wall unless it lands on it exactly, and runs out of steps: a fifth of the frame is
  // stuck, and the suite says so. float64 gets there (a few rays graze walls for longer).
  EXPECT_FALSE(r32.passed);
  EXPECT_GT(stuck(r32), 0.1);
  EXPECT_LT(stuck(r64), 0.02);
  EXPECT_LT(stuck(r64), stuck(r32) / 5.0);
}

INSTANTIATE_TEST_SUITE_P(Backends, Stability, testing::ValuesIn(kernel_backend_names()),
                         [](const testing::TestParamInfo<std::string>& p) { return p.param; });

}  // namespace
}  // namespace flatmarch::conformance
