// What the backend tests share when they hold a kernel backend against the oracle: generic probe
// rays, the oracle's answers per pixel (with ambiguous pixels), and the scenes where sphere
// tracing runs out of steps at default parameters.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "backends/backend.hpp"
#include "backends/oracle/oracle.hpp"
#include "kernels/camera.hpp"
#include "scene/scene.hpp"

namespace flatmarch::test {

constexpr int kEvents = 20;
constexpr int kRaysPerScene = 8;

// Whether the oracle's path, up to its kEvents-th event, keeps `margin` away from every vertex
// and crosses every edge at a sine of at least `min_sine`: a generic ray, whose fate rounding
// and eps cannot decide.
inline bool generic(const Scene& scene, const OracleResult& r, double margin, double min_sine) {
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
inline std::vector<Ray> generic_rays(const Scene& scene) {
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

inline std::string describe(const Event& e) {
  std::string s = std::string(to_string(e.kind)) + " p" + std::to_string(e.polygon);
  if (e.edge >= 0) s += " e" + std::to_string(e.edge);
  if (e.object >= 0) s += " o" + std::to_string(e.object);
  return s;
}

// Scenes where sphere tracing at the default max_steps (1024) cannot follow every ray to the
// default max_distance (100): rays near the horizon cross a room every unit or two and spend
// 10-20 steps closing in on each wall, and in translation prisms nothing escapes, so every ray
// runs the whole distance. The analytic method takes one step per room and has no exceptions.
inline bool out_of_steps_exception(const std::string& scene, Method method) {
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

// The oracle's answers for each pixel of a frame: at its centre, and 1/100 pixel away in four
// directions. A pixel with more than one answer is ambiguous: rounding may decide it, and either
// answer is fine (as VK-GL-CTS's COVERAGE_PARTIAL).
inline std::vector<std::set<int>> oracle_answers(const Scene& scene, int width, int height) {
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

}  // namespace flatmarch::test
