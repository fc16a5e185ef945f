#include "reports/matrix.hpp"

#include "conformance/expectations.hpp"
#include "conformance/external.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <regex>
#include <set>
#include <sstream>

#include "kernels/compile.hpp"
#include "kernels/scene_shader.hpp"
#include "output/image_io.hpp"
#include "reports/estimate.hpp"
#include "reports/shard.hpp"
#include "reports/work_count.hpp"
#include "scene/surfaces.hpp"

namespace flatmarch::reports {

using nlohmann::json;

json accuracy_summary(const conformance::CaseResult& r) {
  json failures = json::object();
  size_t total = 0;
  for (int c = 0; c < conformance::kFailureClasses; ++c) {
    const size_t n =
        r.aov.failures[static_cast<size_t>(c)] + r.trace_failures[static_cast<size_t>(c)];
    failures[conformance::to_string(static_cast<conformance::Failure>(c))] = n;
    total += n;
  }
  int diverged = 0;
  for (const auto& t : r.traces) diverged += t.failure.has_value();
  json failed = json::array();
  for (const conformance::Check& c : r.checks)
    if (!c.passed) failed.push_back(c.name);
  const double pixels = static_cast<double>(std::max<size_t>(r.aov.pixels, 1));
  json summary = {{"passed", r.passed},
                  {"verdict", conformance::to_string(r.verdict)},
                  {"limit", r.limit},
                  {"hit_mismatch", 1.0 - r.aov.hit_rate()},
                  {"crossings_mismatch", 1.0 - r.aov.crossings_rate()},
                  {"ambiguous", static_cast<double>(r.aov.ambiguous) / pixels},
                  {"image_fail", static_cast<double>(r.image.fail) /
                                     static_cast<double>(std::max<size_t>(r.image.pixels, 1))},
                  {"image_mean_error", r.image.mean_error},
                  {"traces", r.traces.size()},
                  {"traces_diverged", diverged},
                  {"failures", failures},
                  {"failures_total", total},
                  {"steps_ks", r.steps_ks},
                  {"failed_checks", r.failed_checks()},
                  {"failed", failed}};
  // Only where a check was left out: a run with every check has the same summary as before.
  if (!r.unmeasured.empty()) summary["unmeasured"] = conformance::unmeasured_json(r);
  return summary;
}

json device_json(const DeviceInfo& d) {
  return {{"name", d.name},
          {"type", d.type},
          {"api", d.api},
          {"driver", d.driver},
          {"platform", d.platform},
          {"software", d.software},
          {"kernel_shape", d.kernel_shape}};
}

std::string device_label(const DeviceInfo& d) {
  return "device " + d.name + "; driver " + d.driver + "; " + d.platform +
         (d.software ? "; software" : "") +
         (d.kernel_shape.empty() ? "" : "; " + d.kernel_shape + " shape");
}

void DeviceTimes::add(const Backend& backend, double wall_seconds) {
  const std::optional<DeviceTiming> t = backend.last_device_timing();
  if (!t) return;
  if (!t->measured) {
    why_ = t->why;
    return;
  }
  ++frames_;
  march_ += t->march_s;
  readback_ += t->readback_s;
  wall_ += wall_seconds;
}

void DeviceTimes::counters(benchmark::State& state) const {
  if (frames_ == 0) return;
  const double ms = 1e3 / frames_;
  state.counters["device_ms"] = (march_ + readback_) * ms;
  state.counters["march_ms"] = march_ * ms;
  state.counters["readback_ms"] = readback_ * ms;
  state.counters["rest_ms"] = std::max(0.0, wall_ - march_ - readback_) * ms;
}

std::string case_name(const std::string& backend, Method method, const std::string& scene,
                      int width, int height) {
  return backend + "/" + to_string(method) + "/" + scene + "/" + std::to_string(width) + "x" +
         std::to_string(height);
}

namespace {

// Collects Google Benchmark's JSON and says when each run ends.
class CollectingReporter : public benchmark::JSONReporter {
 public:
  CollectingReporter(std::ostream& out, std::function<void(const std::string&)> on_run)
      : on_run_(std::move(on_run)) {
    SetOutputStream(&out);
    SetErrorStream(&errors_);
  }
  void ReportRuns(const std::vector<Run>& runs) override {
    JSONReporter::ReportRuns(runs);
    for (const Run& run : runs)
      if (run.run_type == Run::RT_Aggregate && run.aggregate_name == "median" && on_run_)
        on_run_(run.run_name.str());
  }

 private:
  std::ostringstream errors_;
  std::function<void(const std::string&)> on_run_;
};

}  // namespace

void register_frame_benchmark(const Backend& backend, const Scene& scene, const Camera& camera,
                              const MarchParams& params, int width, int height, int repetitions,
                              double min_time, Frame* last, const std::string& name) {
  const std::optional<DeviceInfo> device = backend.device();
  const std::string label = device ? device_label(*device) : "";
  // The case's whole frame, drawn once before the first repetition's timed frames.
  auto whole = std::make_shared<std::optional<Frame>>();
  // A backend's lane figures (the SIMD backend's lane counts and peak), the same in every
  // repetition of a case (its frames are deterministic): measured in the first, the peak over
  // 0.05 s, and over 0.1 s where min_time is 0 (Google Benchmark's own, 0.5 s unless its flag
  // says otherwise: backend_bench). Each repetition's took a counted frame and 0.05 s of
  // stepping: the regression gate 133 s -> 118 s measured once instead. The report's peak was
  // 0.1 s (with four frames on one thread, three timed): 0.05 s and three frames took the SIMD
  // cases' lane figures from 15.7 s to 10.2 s of a first report (2-vCPU Intel Xeon, Emerald
  // Rapids); the untimed one-thread frame is back (SimdBackend::lane_figures).
  const double peak_seconds = min_time > 0.0 ? 0.05 : 0.1;
  struct Lanes {
    bool known = false;
    std::optional<LaneFigures> figures;
  };
  auto lanes = std::make_shared<Lanes>();
  // A CPU backend's instructions a ray (every thread, user space), counted over one frame of
  // the colour once a case where the machine lets a process count them (work_count.hpp): 0
  // where it does not, or for a backend on a device.
  auto instructions_per_ray = std::make_shared<std::optional<double>>();
  benchmark::internal::Benchmark* b =
      benchmark::RegisterBenchmark(
          (name.empty() ? case_name(backend.name(), params.method, scene.name, width, height)
                        : name)
              .c_str(),
          [&backend, &scene, camera, params, width, height, last, whole, lanes, peak_seconds, label,
           instructions_per_ray, on_device = device.has_value()](benchmark::State& state) {
            // A backend's error (a failed compile, a lost device) ends the case, not the run.
            DeviceTimes device_times;
            try {
              // A GPU backend's first frames are untimed: a whole frame, and where a frame of
              // the colour alone is a program of its own (OpenGL's fragment shaders,
              // kernel::Readback) one of those, which compiles it. Vulkan's one program draws
              // both, so its second frame would only cost time (0.13 s a case on lavapipe).
              // Where a frame of the colour is a whole frame (the CPU backends, webgl), the
              // first timed one is kept as the whole frame instead of drawing one more (a
              // quarter of the scalar backend's frames in a report); the conformance case
              // before it warmed the backend. A frame whose instructions are counted below
              // counts the threads (oneTBB's) there are: a whole frame first.
              const bool counting =
                  !*instructions_per_ray && !on_device && instructions_unavailable().empty();
              const bool whole_in_loop = backend.colour_frames_whole() && !counting;
              if (!*whole && !whole_in_loop) {
                *whole = backend.render(scene, camera, width, height, params, {});
                if (backend.colour_program_apart())
                  backend.render_colour(scene, camera, width, height, params, {});
              }
              if (!*instructions_per_ray) {
                *instructions_per_ray = 0.0;
                std::optional<WorkCounter> counter =
                    counting ? WorkCounter::open(WorkCounter::Event::kInstructions, nullptr)
                             : std::nullopt;
                if (counter) {
                  counter->start();
                  backend.render_colour(scene, camera, width, height, params, {});
                  *instructions_per_ray = static_cast<double>(counter->stop()) / (width * height);
                }
              }
              if (**instructions_per_ray > 0.0)
                state.counters["instructions_per_ray"] = **instructions_per_ray;
              for (auto _ : state) {
                const auto start = std::chrono::steady_clock::now();
                const Frame f = backend.render_colour(scene, camera, width, height, params, {});
                benchmark::DoNotOptimize(f.srgb.data());
                benchmark::DoNotOptimize(f.rgb.data());
                // The backend's own time where it has one (webgl: the page's, without the
                // browser's round trip), else the clock's around render_colour().
                const double seconds = backend.last_frame_seconds().value_or(
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
                        .count());
                state.SetIterationTime(seconds);
                device_times.add(backend, seconds);
                if (!*whole && whole_in_loop) *whole = f;  // after the clock
              }
              if (!*whole) *whole = backend.render(scene, camera, width, height, params, {});
              if (!lanes->known) {
                lanes->figures =
                    backend.lane_figures(scene, camera, width, height, params, peak_seconds);
                lanes->known = true;
              }
              if (lanes->figures) {
                lane_counters(state, **whole, *lanes->figures);
                state.counters["lanes"] = lanes->figures->lanes;
                if (lanes->figures->one_thread_rays_per_s > 0.0)
                  state.counters["one_thread_rays_per_s"] = lanes->figures->one_thread_rays_per_s;
              }
            } catch (const std::exception& e) {
              state.SkipWithError(e.what());
              return;
            }
            const std::string clock =
                device_times.why().empty() ? "" : "no device clock: " + device_times.why();
            state.SetLabel(label.empty() || clock.empty() ? label + clock : label + "; " + clock);
            frame_counters(state, **whole);
            device_times.counters(state);
            if (last) *last = **whole;
          })
          ->Unit(benchmark::kMillisecond)
          ->UseManualTime();
  if (min_time > 0.0) b->MinTime(min_time);
  if (repetitions > 0) b->Repetitions(repetitions);
}

void frame_counters(benchmark::State& state, const Frame& frame) {
  std::vector<float> steps(frame.steps.begin(), frame.steps.end());
  std::sort(steps.begin(), steps.end());
  const double pixels = static_cast<double>(steps.size());
  state.counters["rays_per_s"] =
      benchmark::Counter(pixels, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["steps_mean"] = std::accumulate(steps.begin(), steps.end(), 0.0) / pixels;
  state.counters["steps_p99"] = steps[static_cast<size_t>(0.99 * (pixels - 1))];
  state.counters["crossings_mean"] =
      std::accumulate(frame.crossings.begin(), frame.crossings.end(), 0.0) / pixels;
  state.counters["out_of_steps"] =
      static_cast<double>(std::count(frame.hit.begin(), frame.hit.end(), float(kHitMaxSteps))) /
      pixels;
}

void lane_counters(benchmark::State& state, const Frame& frame, const LaneFigures& lanes) {
  state.counters["lane_utilisation"] =
      static_cast<double>(lanes.active) / static_cast<double>(lanes.slots);
  const double steps = std::accumulate(frame.steps.begin(), frame.steps.end(), 0.0);
  state.counters["steps_per_s"] =
      benchmark::Counter(steps, benchmark::Counter::kIsIterationInvariantRate);
  const double peak = lanes.peak_steps_per_s;
  if (peak <= 0.0) return;  // no step to time (SimdBackend::peak_lane_steps)
  state.counters["peak_steps_per_s"] = peak;
  state.counters["of_peak"] =
      benchmark::Counter(steps / peak, benchmark::Counter::kIsIterationInvariantRate);
}

json run_registered_benchmarks(const std::function<void(const std::string&)>& on_run) {
  std::ostringstream out;
  CollectingReporter reporter(out, on_run);
  benchmark::RunSpecifiedBenchmarks(&reporter, ".*");
  benchmark::ClearRegisteredBenchmarks();
  // Nothing registered (a shard that holds no timed case): Google Benchmark reports nothing.
  if (out.str().empty()) return {{"context", json::object()}, {"benchmarks", json::array()}};
  // Google Benchmark writes NaN for a coefficient of variation of zeros (a counter that is 0 in
  // every repetition); JSON has no NaN, so it is read as null.
  static const std::regex not_a_number(R"((:\s*)-?(NaN|nan|inf)\b)");
  return json::parse(std::regex_replace(out.str(), not_a_number, "$1null"));
}

std::map<std::string, Timing> timings(const json& document) {
  std::map<std::string, Timing> result;
  const auto ms = [](const json& run) {
    const std::string unit = run.value("time_unit", "ns");
    const double scale = unit == "ms" ? 1.0 : unit == "us" ? 1e-3 : unit == "s" ? 1e3 : 1e-6;
    return run.at("real_time").get<double>() * scale;
  };
  for (const json& run : document.value("benchmarks", json::array())) {
    // Google Benchmark appends the case's settings to the name it was registered with.
    static const std::regex settings(
        R"(/(min_time|repeats|iterations|threads):[^/]*|/real_time|/manual_time)");
    const std::string name =
        std::regex_replace(run.value("run_name", run.value("name", "")), settings, "");
    Timing& t = result[name];
    if (run.value("error_occurred", false)) {
      t.error = run.value("error_message", "error");
      continue;
    }
    const bool aggregate = run.value("run_type", "iteration") == "aggregate";
    if (!aggregate) t.samples_ms.push_back(ms(run));
    if (aggregate && run.value("aggregate_name", "") != "median") continue;
    if (aggregate) t.median_ms = ms(run);
    json counters = json::object();
    for (const auto& [key, value] : run.items())
      if (value.is_number() && key != "real_time" && key != "cpu_time" && key != "iterations" &&
          key != "repetitions" && key != "repetition_index" && key != "threads" &&
          key != "family_index" && key != "per_family_instance_index")
        counters[key] = value;
    if (aggregate || t.counters.is_null()) t.counters = counters;
  }
  for (auto& [name, t] : result)
    if (t.median_ms == 0.0 && !t.samples_ms.empty()) {
      std::vector<double> s = t.samples_ms;
      std::nth_element(s.begin(), s.begin() + static_cast<long>(s.size() / 2), s.end());
      t.median_ms = s[s.size() / 2];
    }
  return result;
}

std::string matrix_case_key(const std::string& backend, const std::string& method,
                            const std::string& scene) {
  return "matrix/" + conformance::case_key(backend, method, scene);
}

std::optional<CaseKey> parse_case_key(const std::string& key) {
  const size_t b = key.find('/'), m = b == std::string::npos ? b : key.find('/', b + 1),
               n = m == std::string::npos ? m : key.find('/', m + 1);
  if (n == std::string::npos) return std::nullopt;
  CaseKey k{key.substr(0, b), key.substr(b + 1, m - b - 1), key.substr(m + 1, n - m - 1),
            key.substr(n + 1)};
  if ((k.stage != "matrix" && k.stage != "compile") || k.backend.empty() || k.method.empty() ||
      k.scene.empty())
    return std::nullopt;
  return k;
}

namespace {

// Whether a scene's probe rays are traced by the program every scene shares (kernel::shared_trace).
bool trace_shared(const Scene& scene) {
  return kernel::shared_trace(kernel::compile_scene<float>(scene, {}));
}

// The compile case that compiles its backend's shared trace program, "SCENE/METHOD": the first
// scene whose trace is shared, with the first method; "" where none is. The other compile cases
// trace only a scene whose trace is a program of its own, so that the program is compiled once
// (not once a worker, a second or two each from an empty cache) in a case that costs what it
// does, and the stage's estimate is not thrown by the first cases of each worker.
std::string shared_trace_case(const std::vector<Scene>& scenes,
                              const std::vector<Method>& methods) {
  if (methods.empty()) return "";
  for (const Scene& scene : scenes)
    if (trace_shared(scene)) return scene.name + "/" + to_string(methods.front());
  return "";
}

// The shared trace program's compile on one thread from an empty cache: a `flatmarch trace` took
// 1.0 s on Vulkan (lavapipe) and 0.7 s on OpenGL (llvmpipe), the process's start included
// (2-vCPU Intel Xeon, Emerald Rapids).
constexpr double kSharedTraceSeconds = 0.8;

}  // namespace

std::vector<std::pair<std::string, double>> compile_cases(
    const std::vector<std::pair<std::string, double>>& cases, const std::vector<Scene>& scenes,
    const std::vector<std::string>& backends, const std::vector<Method>& methods) {
  const std::string shared = shared_trace_case(scenes, methods);
  std::map<std::string, const Scene*> by_name;
  for (const Scene& s : scenes) by_name[s.name] = &s;
  std::vector<std::pair<std::string, double>> out;
  for (const auto& c : cases) {
    const std::optional<CaseKey> k = parse_case_key(c.first);
    if (!k || k->stage != "matrix" ||
        std::find(backends.begin(), backends.end(), k->backend) == backends.end())
      continue;
    const auto scene = by_name.find(k->scene);
    if (scene == by_name.end()) continue;
    // A case's programs on llvmpipe and lavapipe when they were three on OpenGL and two on
    // Vulkan, a trace program among them, two cases at once, cache empty (a 2-vCPU Intel Xeon,
    // AVX-512, LLVM 15 at 256 bits): a median 0.40 s in a scene of one room, 0.49 s in one of
    // several, whose tables the kernel reads from a buffer (kernels/scene_shader.hpp's
    // tables_in_buffer; baked in, the cube's took 38 s). Its trace now shared, a case compiles
    // one program fewer; the run's calibration (estimate.hpp) takes the difference.
    const bool rooms = scene->second->polygons.size() > 1;
    const bool traces = k->scene + "/" + k->method == shared;
    out.emplace_back("compile/" + conformance::case_key(k->backend, k->method, k->scene),
                     (rooms ? 0.5 : 0.4) + (traces ? kSharedTraceSeconds : 0.0));
  }
  return out;
}

json run_compile_case(const std::string& key, const std::vector<Scene>& scenes,
                      const MatrixOptions& o,
                      const std::vector<std::unique_ptr<Backend>>& backends) {
  const std::optional<CaseKey> k = parse_case_key(key);
  if (!k || k->stage != "compile") throw std::invalid_argument("not a compile case: " + key);
  const auto scene = std::find_if(scenes.begin(), scenes.end(),
                                  [&](const Scene& s) { return s.name == k->scene; });
  const std::optional<Method> parsed = parse_method(k->method);
  if (scene == scenes.end() || !parsed)
    throw std::invalid_argument("no such scene or method here: " + key);
  const auto it =
      std::find_if(backends.begin(), backends.end(),
                   [&](const std::unique_ptr<Backend>& x) { return x->name() == k->backend; });
  if (it == backends.end()) throw std::invalid_argument("no such backend here: " + key);
  const Backend& on = **it;
  MarchParams params = o.params;
  params.method = *parsed;
  const auto start = std::chrono::steady_clock::now();
  // The programs the case runs: its whole frames (the conformance frame, the timed case's
  // first), its frames of the colour alone where they are a program of their own, a probe ray's
  // trace where it is the scene's own or this is the case that compiles the shared one
  // (shared_trace_case); all from its camera.
  constexpr int kPixels = 8;
  on.render(*scene, scene->camera, kPixels, kPixels, params, {});
  if (on.colour_program_apart())
    on.render_colour(*scene, scene->camera, kPixels, kPixels, params, {});
  if (!trace_shared(*scene) || k->scene + "/" + k->method == shared_trace_case(scenes, o.methods)) {
    const double yaw = scene->camera.yaw_deg * 3.14159265358979323846 / 180.0;
    on.trace(
        *scene,
        {scene->camera.polygon, scene->camera.position, Vec3(std::cos(yaw), std::sin(yaw), 0.0)},
        params, 4);
  }
  return {
      {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()}};
}

MatrixBackends matrix_backends(const MatrixOptions& o) {
  MatrixBackends out;
  for (const std::string& name : o.backends) {
    std::unique_ptr<Backend> b = make_backend(name, o.backend_options);
    if (!b) throw std::invalid_argument("unknown backend \"" + name + "\"");
    const Availability a = b->availability();
    const std::vector<Precision> p = b->precisions();
    std::string skip = a.available ? "" : "unavailable here: " + a.reason;
    if (skip.empty() && std::find(p.begin(), p.end(), o.params.precision) == p.end())
      skip = "does not march in this precision";
    if (!skip.empty()) {
      out.skipped.push_back({{"backend", name}, {"reason", skip}});
      continue;
    }
    out.available.push_back(std::move(b));
  }
  out.external = conformance::ExternalSkips(out.available);
  return out;
}

bool matrix_measures(const MatrixOptions& o, const std::string& backend, const std::string& scene,
                     const std::string& method) {
  const auto has = [](const std::vector<std::string>& v, const std::string& x) {
    return std::find(v.begin(), v.end(), x) != v.end();
  };
  return !has(o.sampled_backends, backend) || has(o.sample_cases, scene + "/" + method);
}

std::vector<std::pair<std::string, double>> matrix_cases(const std::vector<Scene>& scenes,
                                                         const MatrixOptions& o,
                                                         const MatrixBackends* built) {
  std::optional<MatrixBackends> own;
  if (!built) own = matrix_backends(o);
  std::vector<std::pair<std::string, double>> cases;
  const MatrixBackends& made = built ? *built : *own;
  for (const auto& backend : made.available)
    for (const Scene& scene : scenes)
      for (const Method m : o.methods) {
        if (!matrix_measures(o, backend->name(), scene.name, to_string(m))) continue;
        const std::string method = to_string(m);
        if (!made.external.why(*backend, m, scene).empty()) {  // only said to be skipped
          cases.emplace_back(matrix_case_key(backend->name(), method, scene.name), 0.01);
          continue;
        }
        double cost = 0.0;
        if (o.conformance)
          cost += conformance_case_cost(backend->name(), method, edge_count(scene), o.conform_width,
                                        o.conform_height);
        if (o.timing)
          cost += timed_case_cost(backend->name(),
                                  frame_cost(backend->name(), method, o.width, o.height),
                                  o.repetitions, o.min_time);
        cases.emplace_back(matrix_case_key(backend->name(), to_string(m), scene.name),
                           cost * scene_cost_factor(scene));
      }
  return cases;
}

// The share of oracle_case_cost that a suite keeps for the next case of the scene and method.
// Fitted on four first reports' progress logs of a 2-vCPU Intel Xeon (Emerald Rapids) in today's
// order, replayed through StageEstimate: the matrix's worst error after its first tenth 22.5,
// 20.1, 11.8 and 7.7% with half, against 36.4, 13.7, 18.3 and 16.1% with none kept and 8.5, 27.2,
// 19.0 and 16.9% with all of it.
constexpr double kOracleKept = 0.5;

std::vector<std::pair<std::string, double>> oracle_once(
    const std::vector<std::pair<std::string, double>>& order, const std::vector<Scene>& scenes,
    const MatrixOptions& o) {
  std::vector<std::pair<std::string, double>> out = order;
  if (!o.conformance) return out;
  std::map<std::string, const Scene*> by_name;
  for (const Scene& s : scenes) by_name.emplace(s.name, &s);
  std::set<std::string> seen;  // method and scene
  for (auto& [key, cost] : out) {
    const CaseGroups g = case_groups(key);
    const auto scene = by_name.find(g.item);
    if (g.stage != "matrix" || scene == by_name.end()) continue;
    const double share =
        kOracleKept *
        oracle_case_cost(edge_count(*scene->second), o.conform_width, o.conform_height) *
        scene_cost_factor(*scene->second);
    if (cost < share || seen.insert(g.method + "/" + g.item).second) continue;
    cost -= share;
  }
  return out;
}

json run_matrix(const std::vector<Scene>& scenes, const MatrixOptions& o, conformance::Suite& suite,
                const MatrixProgress& progress, const MatrixBackends* built) {
  std::optional<MatrixBackends> own;
  if (!built) own = matrix_backends(o);
  const MatrixBackends& made = built ? *built : *own;
  const std::vector<std::unique_ptr<Backend>>& backends = made.available;
  json out = {{"cases", json::array()}, {"skipped", made.skipped}};
  // Whether the CPU backends' cases count their instructions a ray, and why not.
  if (o.timing)
    out["work_counter"] = {{"event", "instructions"},
                           {"available", instructions_unavailable().empty()},
                           {"why", instructions_unavailable()}};
  for (const json& skip : out["skipped"])
    if (progress)
      progress(
          skip["backend"].get<std::string>() + " skipped: " + skip["reason"].get<std::string>(), 0,
          0);
  const auto held = [&](const Backend& backend, Method m, const Scene& scene) {
    return matrix_measures(o, backend.name(), scene.name, to_string(m)) &&
           (!o.holds || o.holds(matrix_case_key(backend.name(), to_string(m), scene.name))) &&
           made.external.why(backend, m, scene).empty();
  };
  for (const auto& backend : backends)
    for (const Scene& scene : scenes)
      for (const Method m : o.methods)
        if (const std::string why = made.external.why(*backend, m, scene);
            !why.empty() && matrix_measures(o, backend->name(), scene.name, to_string(m)) &&
            (!o.holds || o.holds(matrix_case_key(backend->name(), to_string(m), scene.name))))
          out["skipped"].push_back({{"backend", backend->name()},
                                    {"scene", scene.name},
                                    {"method", to_string(m)},
                                    {"reason", why}});
  for (const std::string& b : o.sampled_backends) {
    if (!out.contains("sampled")) out["sampled"] = json::array();
    out["sampled"].push_back({{"backend", b},
                              {"cases", o.sample_cases},
                              {"of_cases", scenes.size() * o.methods.size()},
                              {"why", o.sample_why}});
  }
  int total = 0;
  for (const auto& backend : backends)
    for (const Scene& scene : scenes)
      for (const Method m : o.methods) total += held(*backend, m, scene);
  std::map<std::string, json> cases;
  std::vector<std::string> order;
  // Frames kept for the gallery images, by case name (the first method's).
  std::map<std::string, Frame> frames;
  const int steps = (o.conformance ? total : 0) + (o.timing ? total : 0);
  int done = 0;
  // Each case is measured against the oracle now and registered for timing, which runs after.
  for (const auto& backend : backends)
    for (const Scene& scene : scenes)
      for (const Method m : o.methods) {
        if (!held(*backend, m, scene)) continue;
        MarchParams params = o.params;
        params.method = m;
        const std::string name = case_name(backend->name(), m, scene.name, o.width, o.height);
        order.push_back(name);
        json& c = cases[name];
        c = {{"name", name},           {"backend", backend->name()},
             {"scene", scene.name},    {"surface_type", surface_type(scene)},
             {"method", to_string(m)}, {"width", o.width},
             {"height", o.height}};
        if (const std::optional<DeviceInfo> device = backend->device())
          c["device"] = device_json(*device);
        if (const ExternalInfo* info = backend->external())
          c["external"] = conformance::external_json(*info);
        if (o.timing) {
          Frame* keep = nullptr;
          if (!o.images.empty() && m == o.methods.front()) keep = &frames[name];
          register_frame_benchmark(*backend, scene, scene.camera, params, o.width, o.height,
                                   o.repetitions, o.min_time, keep);
        }
        if (!o.conformance) continue;
        try {
          // Where a renderer we did not write goes wrong, drawn: its error image (as `conform
          // --error-images`), for the page.
          const bool where = backend->external() && !o.images.empty();
          suite.keep_pixel_classes(where);
          const conformance::CaseResult r =
              suite.run(*backend, scene, params, o.conform_width, o.conform_height);
          suite.keep_pixel_classes(false);
          c["accuracy"] = accuracy_summary(r);
          c["accuracy"]["size"] =
              std::to_string(o.conform_width) + "x" + std::to_string(o.conform_height);
          if (where) {
            const std::string diff =
                backend->name() + "/" + scene.name + "." + to_string(m) + ".diff.png";
            std::filesystem::create_directories((o.images / diff).parent_path());
            write_png(conformance::error_image(
                          r.pixel_classes,
                          suite.truth_frame(scene, r.params, o.conform_width, o.conform_height)),
                      o.images / diff);
            c["diff"] = diff;
          }
        } catch (const CaseSkipped& e) {
          c["skipped"] = e.what();
        } catch (const std::exception& e) {
          c["error"] = e.what();
        }
        if (progress)
          progress("conformance " + name + (c.contains("error") ? ": error" : ""), ++done, steps);
      }
  if (o.timing && total > 0) {  // a shard may hold no matrix case
    out["benchmarks"] = run_registered_benchmarks([&](const std::string& name) {
      if (progress) progress("timed " + name, ++done, steps);
    });
    for (const auto& [name, t] : timings(out["benchmarks"])) {
      if (!cases.count(name)) continue;
      json& c = cases[name];
      if (c.contains("skipped")) continue;
      if (!t.error.empty()) {
        c["error"] = t.error;
        continue;
      }
      c["time_ms"] = t.median_ms;
      c["time_samples_ms"] = t.samples_ms;
      c["counters"] = t.counters;
    }
  }
  for (const std::string& name : order) {
    const json& c = cases[name];
    if (c.contains("skipped"))  // its renderer could not render it (CaseSkipped)
      out["skipped"].push_back({{"backend", c["backend"]},
                                {"scene", c["scene"]},
                                {"method", c["method"]},
                                {"reason", c["skipped"]},
                                {"by_renderer", true}});
    else
      out["cases"].push_back(c);
  }
  for (const auto& [name, frame] : frames) {
    if (frame.width == 0) continue;
    const json& c = cases[name];
    const std::filesystem::path png =
        o.images / c["backend"].get<std::string>() / (c["scene"].get<std::string>() + ".png");
    std::filesystem::create_directories(png.parent_path());
    write_png(frame, png);
  }
  return out;
}

void draw_oracle_images(const std::vector<Scene>& scenes, const MatrixOptions& o,
                        const json& matrix) {
  const Backend* oracle = find_backend("oracle");
  if (o.images.empty() || !oracle) return;
  for (const Scene& scene : scenes) {
    // A shard draws the truth of its own scenes.
    const json& cases = matrix.at("cases");
    if (std::none_of(cases.begin(), cases.end(),
                     [&](const json& c) { return c.value("scene", "") == scene.name; }))
      continue;
    MarchParams params = o.params;
    params.method = Method::oracle;
    const std::filesystem::path png = o.images / "oracle" / (scene.name + ".png");
    std::filesystem::create_directories(png.parent_path());
    write_png(oracle->render(scene, scene.camera, o.width, o.height, params, {}), png);
  }
}

}  // namespace flatmarch::reports
