#include "reports/scaling.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "reports/matrix.hpp"
#include "reports/shard.hpp"
#include "scene/surfaces.hpp"

namespace flatmarch::reports {

using nlohmann::json;

double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t k = 0; k < x.size() && k < y.size(); ++k) {
    if (!(x[k] > 0.0) || !(y[k] > 0.0)) continue;
    const double lx = std::log(x[k]), ly = std::log(y[k]);
    n += 1;
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  const double d = n * sxx - sx * sx;
  return n >= 2 && d > 0.0 ? (n * sxy - sx * sy) / d : 0.0;
}

namespace {

struct Point {
  const Scene* scene;
  int width, height;
  double max_distance;
  double x;
};

struct Series {
  std::string axis, family;
  std::vector<Point> points;
};

}  // namespace

std::string scaling_case_key(const std::string& family, const std::string& backend,
                             const std::string& method) {
  return "scaling/" + family + "/" + backend + "/" + method;
}

namespace {

// The series of the options, their scenes kept in `scenes` (they live as long as the benchmarks
// that point at them).
std::vector<Series> make_series(const ScalingOptions& o,
                                std::vector<std::unique_ptr<Scene>>& scenes) {
  const auto keep = [&](Scene s) {
    scenes.push_back(std::make_unique<Scene>(std::move(s)));
    return scenes.back().get();
  };
  std::vector<Series> series;
  {
    const Scene* scene = keep(o.resolution_scene ? *o.resolution_scene : empty_torus_prism());
    Series s{"pixels", scene->name, {}};
    for (const auto& [w, h] : o.resolutions)
      s.points.push_back({scene, w, h, 20.0, static_cast<double>(w) * h});
    series.push_back(s);
  }
  {
    Series s{"edges", "regular 2n-gon", {}};
    for (int n : o.polygon_n)
      s.points.push_back(
          {keep(regular_polygon_surface(n)), o.width, o.height, o.max_distance, 2.0 * n});
    series.push_back(s);
  }
  {
    Series s{"edges", "staircase of squares", {}};
    for (int k : o.staircase_squares)
      s.points.push_back({keep(staircase_surface(k)), o.width, o.height, o.max_distance, 4.0 * k});
    series.push_back(s);
  }
  {
    Series s{"max_distance", "empty torus prism", {}};
    const Scene* prism = keep(empty_torus_prism());
    for (double d : o.max_distances) s.points.push_back({prism, o.width, o.height, d, d});
    series.push_back(s);
  }
  return series;
}

// The backends of the options that can run here; those that cannot, with the reason, into
// `skipped` when given.
std::vector<std::unique_ptr<Backend>> scaling_backends(const ScalingOptions& o, json* skipped) {
  std::vector<std::unique_ptr<Backend>> backends;
  for (const std::string& name : o.backends) {
    std::unique_ptr<Backend> b = make_backend(name, o.backend_options);
    if (!b) throw std::invalid_argument("unknown backend \"" + name + "\"");
    if (const Availability a = b->availability(); !a.available) {
      if (skipped)
        skipped->push_back({{"backend", name}, {"reason", "unavailable here: " + a.reason}});
      continue;
    }
    backends.push_back(std::move(b));
  }
  return backends;
}

}  // namespace

std::vector<std::pair<std::string, double>> scaling_cases(const ScalingOptions& o) {
  std::vector<std::unique_ptr<Scene>> scenes;
  const std::vector<Series> series = make_series(o, scenes);
  std::vector<std::pair<std::string, double>> cases;
  for (const Series& s : series)
    for (const auto& b : scaling_backends(o, nullptr))
      for (Method m : o.methods) {
        double cost = 0.0;
        for (const Point& p : s.points) {
          // Rays run to their path length: about max_distance / 20 of a gallery frame's cost.
          const double frame = frame_cost(b->name(), to_string(m), p.width, p.height) *
                               std::max(1.0, p.max_distance / 20.0);
          cost += timed_case_cost(b->name(), frame, o.repetitions, o.min_time);
        }
        cases.emplace_back(scaling_case_key(s.family, b->name(), to_string(m)), cost);
      }
  return cases;
}

json run_scaling(const ScalingOptions& o,
                 const std::function<void(const std::string&, int, int)>& progress) {
  std::vector<std::unique_ptr<Scene>> scenes;
  const std::vector<Series> series = make_series(o, scenes);
  json out = {{"series", json::array()}, {"skipped", json::array()}};
  const std::vector<std::unique_ptr<Backend>> backends = scaling_backends(o, &out["skipped"]);
  const auto held = [&](const Series& s, const Backend& b, Method m) {
    return !o.holds || o.holds(scaling_case_key(s.family, b.name(), to_string(m)));
  };
  const auto name_of = [](const Series& s, const Backend& b, Method m, const Point& p) {
    return "scaling/" + s.axis + "/" + p.scene->name + "/" + b.name() + "/" + to_string(m) + "/" +
           std::to_string(p.width) + "x" + std::to_string(p.height) + "/d" +
           std::to_string(static_cast<int>(p.max_distance));
  };
  int total = 0;
  for (const Series& s : series)
    for (const auto& b : backends)
      for (Method m : o.methods)
        for (const Point& p : s.points) {
          if (!held(s, *b, m)) continue;
          MarchParams params;
          params.method = m;
          params.max_distance = p.max_distance;
          // Rays end by their path length, not by running out of steps.
          params.max_steps = 1 << 16;
          register_frame_benchmark(*b, *p.scene, p.scene->camera, params, p.width, p.height,
                                   o.repetitions, o.min_time, nullptr, name_of(s, *b, m, p));
          ++total;
        }
  int done = 0;
  // A shard may hold no series: then nothing is timed.
  out["benchmarks"] = total == 0 ? json{{"context", json::object()}, {"benchmarks", json::array()}}
                                 : run_registered_benchmarks([&](const std::string& name) {
                                     if (progress) progress("timed " + name, ++done, total);
                                   });
  const std::map<std::string, Timing> t = timings(out["benchmarks"]);
  for (const Series& s : series)
    for (const auto& b : backends)
      for (Method m : o.methods) {
        if (!held(s, *b, m)) continue;
        json j = {{"axis", s.axis},
                  {"family", s.family},
                  {"backend", b->name()},
                  {"method", to_string(m)}};
        std::vector<double> x, ms, steps, crossings, lanes;
        for (const Point& p : s.points) {
          const auto it = t.find(name_of(s, *b, m, p));
          if (it == t.end() || !it->second.error.empty()) continue;
          x.push_back(p.x);
          ms.push_back(it->second.median_ms);
          steps.push_back(it->second.counters.value("steps_mean", 0.0));
          crossings.push_back(it->second.counters.value("crossings_mean", 0.0));
          if (it->second.counters.contains("lane_utilisation"))
            lanes.push_back(it->second.counters["lane_utilisation"].get<double>());
        }
        j["x"] = x;
        j["time_ms"] = ms;
        j["steps_mean"] = steps;
        j["crossings_mean"] = crossings;
        if (!lanes.empty()) j["lane_utilisation"] = lanes;
        j["slope"] = loglog_slope(x, ms);
        j["steps_slope"] = loglog_slope(x, steps);
        out["series"].push_back(j);
      }
  return out;
}

}  // namespace flatmarch::reports
