// The scalar backend against the oracle on every gallery scene, for every method at default
// parameters: generic rays follow the oracle's edge sequence for their first 20 events, and the
// hit AOV agrees on at least 99% of the pixels of a 160x90 frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <random>
#include <set>

#include "backends/oracle/oracle.hpp"
#include "backends/scalar/scalar.hpp"
#include "kernels/camera.hpp"
#include "scene/load.hpp"
#include "tests/gallery.hpp"
#include "tests/process.hpp"

namespace flatmarch {
namespace {

namespace fs = std::filesystem;

constexpr int kEvents = 20;
constexpr int kRaysPerScene = 8;

// Whether the oracle's path, up to its kEvents-th event, keeps `margin` away from every vertex
// and crosses every edge at a sine of at least `min_sine`: a generic ray, whose fate rounding
// and eps cannot decide.
bool generic(const Scene& scene, const OracleResult& r, double margin, double min_sine) {
  const double horizon = r.trace.events.back().t;
  double t = 0.0;
  for (const PathSegment& seg : r.path) {
    if (t > horizon) break;
    const Vec3 step = seg.to - seg.from;
    t += glm::length(step);
    const Polygon& polygon = scene.polygons[static_cast<size_t>(seg.polygon)];
    for (int v = 0; v < polygon.size(); ++v) {
      if (distance_to_segment(polygon.vertex(v), Vec2(seg.from), Vec2(seg.to)) < margin)
        return false;
      const Edge& edge = polygon.edges[static_cast<size_t>(v)];
      const bool ends_on_edge =
          distance_to_segment(Vec2(seg.to), polygon.vertex(v), polygon.vertex(v + 1)) < 1e-9;
      if (ends_on_edge && glm::length(step) > 0.0 &&
          std::abs(glm::dot(Vec2(step), edge.normal)) < min_sine * glm::length(step))
        return false;
    }
  }
  return true;
}

// Nearly horizontal rays from random points of random rooms, kept when generic.
std::vector<Ray> generic_rays(const Scene& scene) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double top = scene.period ? *scene.period : scene.height;
  std::vector<Ray> rays;
  for (int attempt = 0; attempt < 500 && static_cast<int>(rays.size()) < kRaysPerScene; ++attempt) {
    const int p = static_cast<int>(unit(rng) * static_cast<double>(scene.polygons.size()));
    const Polygon& polygon = scene.polygons[static_cast<size_t>(p)];
    Vec2 lo = polygon.vertices[0], hi = lo;
    for (const Vec2& v : polygon.vertices) lo = glm::min(lo, v), hi = glm::max(hi, v);
    const Vec2 xy = lo + Vec2(unit(rng), unit(rng)) * (hi - lo);
    if (!polygon.contains(xy, 0.05 * scene.scale)) continue;
    const double angle = 2.0 * kPi * unit(rng);
    const Ray ray{p, Vec3(xy, top * (0.3 + 0.4 * unit(rng))),
                  Vec3(std::cos(angle), std::sin(angle), 0.05 * (unit(rng) - 0.5))};
    bool inside_object = false;
    for (const Object& o : scene.objects)
      inside_object |= o.polygon == p && glm::length(Vec2(ray.from) - Vec2(o.center)) <
                                             o.footprint_radius() + 0.05 * scene.scale;
    if (inside_object) continue;
    const OracleResult r =
        oracle_trace(scene, ray, {}, {.max_events = kEvents, .record_path = true});
    if (generic(scene, r, 0.01 * scene.scale, 0.05)) rays.push_back(ray);
  }
  return rays;
}

std::string describe(const Event& e) {
  std::string s = std::string(to_string(e.kind)) + " p" + std::to_string(e.polygon);
  if (e.edge >= 0) s += " e" + std::to_string(e.edge);
  if (e.object >= 0) s += " o" + std::to_string(e.object);
  return s;
}

// Scenes where sphere tracing at the default max_steps (1024) cannot follow every ray to the
// default max_distance (100): rays near the horizon cross a room every unit or two and spend
// 10-20 steps closing in on each wall, and in translation prisms nothing escapes, so every ray
// runs the whole distance. The analytic method takes one step per room and has no exceptions.
bool out_of_steps_exception(const std::string& scene, Method method) {
  static const std::set<std::pair<std::string, Method>> exceptions = {
      {"cube", Method::sphere},
      {"cube", Method::relaxed},
      {"double_pentagon", Method::sphere},
      {"l_shape", Method::sphere},
      {"pillowcase", Method::sphere},
      {"pillowcase", Method::relaxed},
      {"torus_prism", Method::sphere},
      {"l_shape_prism", Method::sphere},
      {"l_shape_prism", Method::relaxed},
      {"double_pentagon_prism", Method::sphere},
      {"double_pentagon_prism", Method::relaxed}};
  return exceptions.count({scene, method}) > 0;
}

struct Case {
  std::string scene;
  Method method;
};

class ScalarConformance : public testing::TestWithParam<Case> {};

TEST_P(ScalarConformance, GenericRaysFollowTheOraclesEdgeSequence) {
  const Scene& scene = test::gallery_scene(GetParam().scene);
  const std::vector<Ray> rays = generic_rays(scene);
  ASSERT_EQ(static_cast<int>(rays.size()), kRaysPerScene) << "too few generic rays found";
  MarchParams params;
  params.method = GetParam().method;
  for (size_t k = 0; k < rays.size(); ++k) {
    const Trace truth = OracleBackend().trace(scene, rays[k], {}, kEvents);
    const Trace got = ScalarBackend().trace(scene, rays[k], params, kEvents);
    for (size_t i = 0; i < std::min(truth.events.size(), got.events.size()); ++i) {
      const Event &a = truth.events[i], &b = got.events[i];
      ASSERT_EQ(describe(b), describe(a))
          << "event " << i << " of the ray from " << test::vec3_arg(rays[k].from) << " along "
          << test::vec3_arg(rays[k].dir) << " in polygon " << rays[k].polygon;
      EXPECT_EQ(b.to_polygon, a.to_polygon);
      EXPECT_EQ(b.to_edge, a.to_edge);
      EXPECT_NEAR(b.t, a.t, 1e-2 * scene.scale) << "ray " << k << " event " << i;
    }
    EXPECT_EQ(got.events.size(), truth.events.size()) << "ray " << k;
  }
}

// The oracle's answers for each pixel of a frame: at its centre, and 1/100 pixel away in four
// directions. A pixel with more than one answer is ambiguous: rounding may decide it, and either
// answer is fine (as VK-GL-CTS's COVERAGE_PARTIAL).
std::vector<std::set<int>> oracle_answers(const Scene& scene, int width, int height) {
  const Camera& camera = scene.camera;
  const CameraBasis<double> basis =
      camera_basis(camera.yaw_deg, camera.pitch_deg, camera.fov_deg, width, height);
  constexpr double kJitter = 0.01;
  const double offsets[5][2] = {{0, 0}, {kJitter, 0}, {-kJitter, 0}, {0, kJitter}, {0, -kJitter}};
  std::vector<std::set<int>> answers(static_cast<size_t>(width) * static_cast<size_t>(height));
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i)
      for (const auto& o : offsets) {
        const Vec3 dir = camera_ray_at(basis, i + 0.5 + o[0], j + 0.5 + o[1], width, height);
        answers[static_cast<size_t>(j * width + i)].insert(
            oracle_trace(scene, {camera.polygon, camera.position, dir}, {}).end.hit);
      }
  return answers;
}

TEST_P(ScalarConformance, HitAovAgreesWithTheOracle) {
  const Scene& scene = test::gallery_scene(GetParam().scene);
  MarchParams params;
  params.method = GetParam().method;
  const Frame truth = OracleBackend().render(scene, scene.camera, 160, 90, {}, {});
  const std::vector<std::set<int>> answers = oracle_answers(scene, 160, 90);
  const Frame got = ScalarBackend().render(scene, scene.camera, 160, 90, params, {});
  const double pixels = static_cast<double>(truth.hit.size());
  size_t agree = 0, acceptable = 0, ambiguous = 0;
  size_t gave_up = 0;  // max_steps where the oracle decided otherwise
  float most_steps = 0.0f;
  std::map<std::pair<int, int>, int> confusion;  // (oracle's hit, scalar's hit) -> pixels
  for (size_t px = 0; px < truth.hit.size(); ++px) {
    const int want = static_cast<int>(truth.hit[px]), hit = static_cast<int>(got.hit[px]);
    agree += hit == want;
    ambiguous += answers[px].size() > 1;
    const bool fine = answers[px].count(hit) > 0;
    acceptable += fine;
    gave_up += !fine && hit == kHitMaxSteps;
    if (hit != want) ++confusion[{want, hit}];
    most_steps = std::max(most_steps, got.steps[px]);
  }
  const double fraction = static_cast<double>(acceptable) / pixels;
  std::cout << "hit agreement " << scene.name << " " << to_string(params.method) << ": "
            << 100.0 * static_cast<double>(agree) / pixels << "% exact, " << 100.0 * fraction
            << "% allowing the " << ambiguous << " ambiguous pixels; "
            << 100.0 * static_cast<double>(gave_up) / pixels << "% out of steps;";
  for (const auto& [hits, count] : confusion)
    std::cout << "  " << hits.first << "->" << hits.second << ": " << count;
  std::cout << "\n";
  EXPECT_LE(most_steps, static_cast<float>(params.max_steps));  // bounded work
  if (!out_of_steps_exception(scene.name, params.method)) {
    EXPECT_GE(fraction, 0.99);
    return;
  }
  // A named exception: below 99% only because rays ran out of steps where the oracle went on.
  EXPECT_LT(fraction, 0.99) << "no longer an exception: take it off the list";
  EXPECT_GE(fraction + static_cast<double>(gave_up) / pixels, 0.99);
}

double mean_steps(const Scene& scene, Method method) {
  MarchParams params;
  params.method = method;
  const Frame f = ScalarBackend().render(scene, scene.camera, 320, 180, params, {});
  double sum = 0.0;
  for (float s : f.steps) sum += s;
  return sum / static_cast<double>(f.steps.size());
}

TEST(ScalarSteps, AnalyticTakesTenTimesFewerStepsThanSphereOnTranslationSurfaces) {
  // Steps are deterministic, so this holds on any machine (bench/kernel_bench reports them too).
  for (const std::string name : {"l_shape", "double_pentagon"}) {
    const Scene& scene = test::gallery_scene(name);
    const double sphere = mean_steps(scene, Method::sphere);
    const double analytic = mean_steps(scene, Method::analytic);
    std::cout << name << ": mean steps per ray at 320x180, sphere " << sphere << ", analytic "
              << analytic << ", ratio " << sphere / analytic << "\n";
    EXPECT_GE(sphere / analytic, 10.0) << name;
  }
}

std::vector<Case> cases() {
  std::vector<Case> all;
  for (const std::string& name : test::gallery_names())
    for (Method m : {Method::sphere, Method::relaxed, Method::analytic}) all.push_back({name, m});
  return all;
}

INSTANTIATE_TEST_SUITE_P(Gallery, ScalarConformance, testing::ValuesIn(cases()),
                         [](const testing::TestParamInfo<Case>& param) {
                           return param.param.scene + "_" + to_string(param.param.method);
                         });

}  // namespace
}  // namespace flatmarch
