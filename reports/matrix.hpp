// The report's matrix: every backend x gallery scene x method, timed by Google Benchmark (its
// JSON, with the hardware fingerprint in its context, is the exchange format) and measured
// against the oracle by the conformance suite.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <benchmark/benchmark.h>

#include "backends/backend.hpp"
#include "conformance/external.hpp"
#include "conformance/suite.hpp"

namespace flatmarch::reports {

struct MatrixOptions {
  std::vector<std::string> backends = kernel_backend_names();
  BackendOptions backend_options;
  std::vector<Method> methods{kKernelMethods.begin(), kKernelMethods.end()};
  MarchParams params;             // eps, offset, ...; the method is each case's
  int width = 256, height = 144;  // timed frames
  int conform_width = 160, conform_height = 90;
  int repetitions = 3;      // Google Benchmark repetitions of each timed case
  double min_time = 0.02;   // seconds per repetition, at least one frame
  bool conformance = true;  // measure against the oracle too
  bool timing = true;
  // Where to write each backend's frame of each scene (the first method's) as BACKEND/SCENE.png;
  // empty: nowhere.
  std::filesystem::path images;
  // The cases to run, by matrix_case_key (a shard's, issue 24); empty: every case.
  std::function<bool(const std::string& key)> holds;
  // Backends measured on a sample of the matrix, not all of it: one whose cases take many times
  // the others' (a browser drawing in software). `sample_cases` names the cases as
  // "SCENE/METHOD", `sample_why` says why, as the results, the ranking and the page repeat it.
  std::vector<std::string> sampled_backends, sample_cases;
  std::string sample_why;
};

// Whether the matrix measures `backend` on `scene` with `method` (every case but for a sampled
// backend).
bool matrix_measures(const MatrixOptions& o, const std::string& backend, const std::string& scene,
                     const std::string& method);

// A matrix case's key in a sharded run's case list: "matrix/BACKEND/METHOD/SCENE".
std::string matrix_case_key(const std::string& backend, const std::string& method,
                            const std::string& scene);
// A matrix or compile case's key taken apart: "STAGE/BACKEND/METHOD/SCENE" (STAGE "matrix" or
// "compile"); std::nullopt for a key of another shape or stage.
struct CaseKey {
  std::string stage, backend, method, scene;
};
std::optional<CaseKey> parse_case_key(const std::string& key);

// The kernels of the matrix's GPU cases, compiled ahead (a report's "compile" stage). A GPU
// backend's case compiles three programs (its whole frame, its frame of the colour alone, the
// trace of a probe ray) on one thread while the other cores wait: 147 s of a 2-core machine's
// first report on llvmpipe and lavapipe. Compiled first, several cases at once, each in a frame
// of 8x8 pixels and one trace, they are in the driver's disk cache when the case runs.
// The compile cases of `cases` (matrix cases among others, by key) whose backend is one of
// `backends`: "compile/BACKEND/METHOD/SCENE", each with its expected seconds on one thread (more
// rooms, more code), in the order of `cases`.
// A backend's trace program that scenes share (kernel::shared_trace) is compiled by one case, the
// first scene's that shares it with the first of `methods`, the dearer by its compile.
std::vector<std::pair<std::string, double>> compile_cases(
    const std::vector<std::pair<std::string, double>>& cases, const std::vector<Scene>& scenes,
    const std::vector<std::string>& backends, const std::vector<Method>& methods);
// Compiles a compile case's programs on its backend, one of `backends` (a worker's matrix
// backends). Returns {"seconds"}; throws std::invalid_argument for a key that names no scene,
// method or backend here.
nlohmann::json run_compile_case(const std::string& key, const std::vector<Scene>& scenes,
                                const MatrixOptions& o,
                                const std::vector<std::unique_ptr<Backend>>& backends);

// Called with a line of progress: what was done, how many of how many.
using MatrixProgress = std::function<void(const std::string& line, int done, int total)>;

// The summary of a conformance case the report shows: passed, hit_mismatch and
// crossings_mismatch (shares of decided pixels), ambiguous (share of pixels), image_fail (share),
// image_mean_error, traces and traces_diverged, failures by class and failures_total, steps_ks,
// failed_checks (a line each) and failed (the names of the failed checks).
nlohmann::json accuracy_summary(const conformance::CaseResult& r);

// A GPU backend's device as results carry it: name, type, api, driver, platform, software,
// kernel_shape.
nlohmann::json device_json(const DeviceInfo& device);
// The same in one line, as benchmark runs are labelled: "device NAME; driver DRIVER; software".
std::string device_label(const DeviceInfo& device);

// The matrix's backends that can run here, made once (a worker of a supervised report runs case
// after case on them), and "skipped": the others, each {"backend", "reason"}.
// `external` says which cases a renderer we did not write does not render (its methods, the
// scenes it reads, its expectation file's skip lines); those are skipped, saying why.
struct MatrixBackends {
  std::vector<std::unique_ptr<Backend>> available;
  nlohmann::json skipped = nlohmann::json::array();
  conformance::ExternalSkips external;
};
// Throws std::invalid_argument for an external renderer's expectation file that cannot be used.
MatrixBackends matrix_backends(const MatrixOptions& options);

// The matrix's cases (backends available here x scenes x methods, in run_matrix's order) by key,
// each with its expected seconds on this machine (conformance and timing). The backends are
// `built`'s, or made (matrix_backends) where null: making them starts a browser, GL and Vulkan
// contexts, seconds on a machine without a GPU, which a worker's every case must not pay.
std::vector<std::pair<std::string, double>> matrix_cases(const std::vector<Scene>& scenes,
                                                         const MatrixOptions& options,
                                                         const MatrixBackends* built = nullptr);

// `order` (cases of a run, in the order they run) with the part of each matrix case's oracle
// share (oracle_case_cost) that a worker's suite keeps for the next backend's case of the scene and
// method (its truth and steps reference) priced on the first case of them alone. Priced on every
// case, a first report's first cases took about a fifth of their time in it and the later ones
// almost none, and the estimate stayed 15-25% over through the matrix. A case priced below that
// part (one only said to be skipped) neither pays it nor is the first.
std::vector<std::pair<std::string, double>> oracle_once(
    const std::vector<std::pair<std::string, double>>& order, const std::vector<Scene>& scenes,
    const MatrixOptions& o);

// Runs the matrix (on `backends`, or on matrix_backends(options) where null). Returns
// {"benchmarks": Google Benchmark's JSON document (each GPU case's run labelled with its device),
// "cases": one per backend x scene x method with its timing (median and samples, ms), counters,
// accuracy and, for a GPU backend, the device it ran on (device_json), "skipped": backends
// unavailable here with the reason}.
nlohmann::json run_matrix(const std::vector<Scene>& scenes, const MatrixOptions& options,
                          conformance::Suite& suite, const MatrixProgress& progress,
                          const MatrixBackends* backends = nullptr);

// The oracle's frame of each scene the `matrix` (run_matrix's) has a case of, beside the
// backends' frames: options.images/oracle/SCENE.png. Nothing where options.images is empty.
void draw_oracle_images(const std::vector<Scene>& scenes, const MatrixOptions& options,
                        const nlohmann::json& matrix);

// Runs Google Benchmark on what is registered now, collecting its JSON (with the context, where
// the fingerprint is added) and calling `on_run` with each run's name as it ends; clears the
// registrations after.
nlohmann::json run_registered_benchmarks(const std::function<void(const std::string&)>& on_run);

// Registers one timed case, BACKEND/METHOD/SCENE/WxH: frames of the scene's camera, after an
// untimed whole frame and an untimed frame of its colour (a GPU backend compiles a program for
// each then; the deterministic counters are the whole frame's), each timed frame one of its colour
// alone (Backend::render_colour: what a user waits for; the GPU backends read back nothing else)
// timed by the backend's own measure where it has one (Backend::last_frame_seconds: webgl's page),
// else by the clock around it (Google Benchmark's manual time); counters rays_per_s, steps_mean,
// steps_p99, crossings_mean, out_of_steps, a GPU backend's device times (DeviceTimes) and, for the
// SIMD backend, lane_utilisation, steps_per_s, peak_steps_per_s and of_peak (lane_counters), lanes,
// and one_thread_rays_per_s (the median of three frames on one thread of its instruction set,
// where it runs more: the numerator of its lane efficiency, report.hpp); a GPU backend's runs are
// labelled with its device (device_label). `last`, when given, receives the
// whole frame. Repetitions and min_time of 0 leave them to Google Benchmark's flags
// (--benchmark_repetitions, --benchmark_min_time).
void register_frame_benchmark(const Backend& backend, const Scene& scene, const Camera& camera,
                              const MarchParams& params, int width, int height, int repetitions,
                              double min_time, Frame* last = nullptr, const std::string& name = "");

// A GPU backend's time on its device over a timed case's frames (Backend::last_device_timing):
// add() after each frame, with the wall time it took; counters() then sets device_ms (the march
// and the read-back on the device's clock, a frame), march_ms, readback_ms and rest_ms (a frame's
// wall time less its device time: the submission, the waits and the host's unpacking), each the
// mean over the frames. Nothing for a backend that runs on no device of its own; where the
// device has no clock, `why()` says so and no counter is set.
class DeviceTimes {
 public:
  void add(const Backend& backend, double wall_seconds);
  void counters(benchmark::State& state) const;
  const std::string& why() const { return why_; }

 private:
  int frames_ = 0;
  double march_ = 0.0, readback_ = 0.0, wall_ = 0.0;
  std::string why_;
};

// The counters of a timed frame: rays_per_s (a rate over the iterations), and the deterministic
// figures of the frame: steps_mean, steps_p99, crossings_mean, out_of_steps (share of rays that
// reached max_steps).
void frame_counters(benchmark::State& state, const Frame& frame);

// A lane backend's counters of a timed frame (LaneFigures, the SIMD backend's): lane_utilisation
// (active lanes over lanes), steps_per_s (the frame's steps, summed over its rays, a second: a
// rate over the iterations), peak_steps_per_s (the case's peak: one room's step on full packets
// on all its threads; none where it is 0, no step to time) and of_peak, the share of that peak
// the frame's steps reach: how close to what this CPU can do the backend runs (idle lanes,
// shading, pixel writes and scheduling make the rest).
void lane_counters(benchmark::State& state, const Frame& frame, const LaneFigures& lanes);

// The name register_frame_benchmark gives.
std::string case_name(const std::string& backend, Method method, const std::string& scene,
                      int width, int height);

// The median and the per-repetition times (ms) of each run name in a Google Benchmark document.
struct Timing {
  double median_ms = 0.0;
  std::vector<double> samples_ms;
  nlohmann::json counters;  // of the median aggregate (or the only run)
  std::string error;        // the backend's error, when the case could not run
};
std::map<std::string, Timing> timings(const nlohmann::json& benchmark_document);

}  // namespace flatmarch::reports
