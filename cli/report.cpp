// `flatmarch report`, `flatmarch select` and `flatmarch sweep`: the suite's answers for its
// users — which backend is fastest here, which parameters are safe, and did anything get worse.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <thread>

#include "cli/case_progress.hpp"
#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/supervised.hpp"
#include "conformance/expectations.hpp"
#include "conformance/suite.hpp"
#include "output/dynamic_library.hpp"
#include "reports/estimate.hpp"
#include "reports/fingerprint.hpp"
#include "reports/page.hpp"
#include "reports/report.hpp"
#include "reports/supervise.hpp"
#include "scene/load.hpp"
#include "scene/surfaces.hpp"

namespace flatmarch::cli {

namespace fs = std::filesystem;
using nlohmann::json;

void make_report_page(const std::string& python, const std::vector<std::string>& results,
                      const fs::path& out, const std::string& previous) {
  // The tables the page shows, worked out here (reports/page.hpp); the script draws the charts
  // and fills the template with them.
  json tables;
  if (results.size() == 1) {
    const json doc = read_json("RESULTS", results.front());
    const json earlier = previous.empty() ? json() : read_json("--previous", previous);
    tables = reports::page_tables(doc, previous.empty() ? nullptr : &earlier);
  } else {
    std::vector<std::pair<std::string, json>> runs;
    for (const std::string& r : results) runs.emplace_back(r, read_json("RESULTS", r));
    tables = reports::machines_tables(runs);
  }
  const fs::path tables_file = out / "page.json";
  write_json(tables_file, tables);
  std::string command =
      shell_quoted(python) + " " + shell_quoted(data_file("reports/make_report.py")) + " -o " +
      shell_quoted(out.string()) + " --tables " + shell_quoted(tables_file.string());
  if (!previous.empty()) command += " --previous " + shell_quoted(previous);
  for (const std::string& r : results) command += " " + shell_quoted(r);
  if (std::system(command.c_str()) != 0)
    throw std::runtime_error("the charts and the page could not be made (" + command +
                             " failed; it needs python3 with matplotlib and jinja2: "
                             "ci/install-deps.sh installs them); the results "
                             "are in " +
                             results.front());
}

namespace {

// Throws a UsageError unless `file` is a results file of `flatmarch report`.
void check_results_file(const std::string& option, const std::string& file) {
  const json doc = read_json(option, file);
  for (const char* key : {"fingerprint", "matrix", "ranking"})
    if (!doc.is_object() || !doc.contains(key))
      throw UsageError(option + ": " + file + " has no \"" + key +
                       "\": not a results file of `flatmarch report`");
}

}  // namespace

json regression_section(const json& results, const std::string& given) {
  const std::string file = given.empty() ? data_folder("reports/baseline.json") : given;
  if (given.empty() && !fs::exists(file))
    return {{"checked", false}, {"why", file + " is not there"}};
  const json baseline = read_json("--baseline", file);
  if (const std::string why = reports::baseline_mismatch(baseline, results); !why.empty())
    return {{"checked", false},
            {"baseline", file},
            {"given", !given.empty()},
            {"why", given.empty() ? why : why + "; measure alike"}};
  json r = reports::check_baseline(baseline, results);
  r["checked"] = true;
  r["baseline"] = file;
  r["given"] = !given.empty();
  r["baseline_created"] = baseline.value("created", "");
  r["baseline_cases"] = baseline["cases"].size();
  r["tolerances"] = baseline["tolerances"];
  return r;
}

std::string default_python() {
  if (const char* p = std::getenv("FLATMARCH_PYTHON")) return p;
  return "/usr/bin/python3";
}

void gate(const json& results, const std::string& baseline, const fs::path& out) {
  const json& check = results["regression"];
  if (!check["checked"].get<bool>())
    throw UsageError("--baseline: " + baseline + ": " + check["why"].get<std::string>());
  write_json(out / "gate.json", check);
  std::printf("%s",
              reports::describe_gate(check, read_json("--baseline", baseline), baseline).c_str());
  if (!check["regressions"].empty())
    throw ConformanceFailure(std::to_string(check["regressions"].size()) +
                             " figures regressed against " + baseline);
}

reports::Shard parse_shard_option(const std::string& text) {
  const std::optional<reports::Shard> shard = reports::parse_shard(text);
  if (!shard) throw UsageError("--shard: I/N with 1 <= I <= N <= 1000, not " + text);
  return *shard;
}

namespace {

// The matrix's cases of each external renderer with an expectation file, against it
// (conformance/expectations.hpp): results["expectations"][RENDERER], and the changes, printed.
// Its cases are those it ran and those it skipped itself (exit 77), as in `conform`; not those
// never asked of it (a method or scene format it has not, its file's skip lines).
std::vector<std::string> expectation_changes(json& results) {
  std::map<std::string, std::vector<std::pair<std::string, std::string>>> run;
  const json& matrix = results.value("matrix", json::object());
  for (const json& c : matrix.value("cases", json::array()))
    if (c.contains("external"))
      run[c["backend"]].emplace_back(
          conformance::case_key(c["backend"], c["method"], c["scene"]),
          c.contains("accuracy") ? c["accuracy"].value("verdict", "error") : "error");
  for (const json& skip : matrix.value("skipped", json::array()))
    if (skip.value("by_renderer", false))
      run[skip["backend"]].emplace_back(
          conformance::case_key(skip["backend"], skip["method"], skip["scene"]), "skip");
  std::vector<std::string> changes;
  for (const auto& [name, cases] : run) {
    const std::unique_ptr<Backend> backend = make_backend(name, {});
    const ExternalInfo* info = backend ? backend->external() : nullptr;
    if (!info || info->expectations.empty()) continue;
    const json judged = conformance::expectation_outcomes(
        conformance::Expectations::read(info->expectations), cases);
    results["expectations"][name] = judged;
    for (const json& change : judged["changes"]) changes.push_back(change);
  }
  if (!changes.empty()) {
    std::printf("report: %zu changes against the expectation files:\n", changes.size());
    for (const std::string& change : changes) std::printf("    %s\n", change.c_str());
  }
  return changes;
}

}  // namespace

void add_report(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "report",
      "The main job: measure every available backend on the gallery — each scene and method timed\n"
      "(Google Benchmark, median of repetitions) and measured against the oracle (the conformance\n"
      "suite) — sweep eps x offset per surface type, time the scaling series (resolution, edges,\n"
      "path length), and write OUT/results.json (with this machine's fingerprint) and a\n"
      "self-contained OUT/index.html: the verdicts (pass, limit, fail) with every failed check,\n"
      "the ranking of backends and recommended parameters, the recommended method's images with\n"
      "their differences from the oracle, gallery images per backend, speed against accuracy,\n"
      "the ambiguous share, stability and step heatmaps, scaling curves, definitions. The quick\n"
      "default takes minutes on 2 cores; where the webgl backend's browser draws in software\n"
      "(SwiftShader) it is measured on one scene of each surface type (--all-scenes: on all;\n"
      "--skip-backend webgl leaves it out); --full measures more. Given result files (RESULTS...), "
      "measures nothing: one file makes its\n"
      "page again, several compare their machines. --baseline checks the deterministic\n"
      "figures (steps, crossings, conformance rates) against committed ones: exit 1 when one\n"
      "regresses beyond its tolerance; slower timings only warn. Without it the page shows the\n"
      "same check against reports/baseline.json when this run was measured as it was, else why\n"
      "not. --previous adds the change per case since an earlier run.");
  struct Options {
    std::vector<std::string> results, backends, skip_backends, scenes, methods, externals;
    std::vector<std::string> galleries = {data_folder("scenes")};
    std::string out = "reports/out", progress_log, size, conform_size = "160x90", sweep_size,
                sweep_backend;
    std::string baseline, write_baseline, previous, shard, python = default_python();
    int repetitions = 0, compile_jobs = -1;
    // A worker of the compile stage: the matrix's backends it makes (those that compile).
    std::vector<std::string> compile_worker;
    double min_time = 0.02;
    bool full = false, all_scenes = false, no_sweep = false, no_scaling = false, no_html = false,
         quiet = false;
    MarchParams params;
    BackendOptions backend_options;
    SupervisionOptions supervision;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("RESULTS", o->results,
                  "Result files of earlier runs (results.json): page of one, comparison of several")
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--out", o->out, "Output folder")->capture_default_str();
  cmd->add_flag("--full", o->full,
                "The full matrix: frames 640x360, 5 repetitions, the sweep on every scene in f32 "
                "and f64 (the quick one: f32), longer "
                "scaling series on every backend (the quick ones: simd where it is measured, else "
                "scalar)");
  cmd->add_flag("--all-scenes", o->all_scenes,
                "Measure a browser that draws in software (the webgl backend on SwiftShader) on "
                "every scene and method too (default: the simplest scene of each surface type, "
                "one method each; --full implies it)");
  cmd->add_option("--backend", o->backends,
                  "Backend to measure (repeat; default: " + joined(kernel_backend_names()) +
                      " — those unavailable here skipped with the reason)");
  cmd->add_option("--skip-backend", o->skip_backends,
                  "Leave this backend out of the default list (repeat; the regression gate leaves "
                  "out webgl, whose every page a browser compiles for seconds on SwiftShader)");
  cmd->add_option("--scene", o->scenes, "Scene file or gallery name (repeat; default: all)");
  cmd->add_option("--gallery", o->galleries, "Folders of scenes")->capture_default_str();
  cmd->add_option("--method", o->methods, kernel_method_names() + " (repeat; default: all)");
  cmd->add_option("--size", o->size, "Timed frames WxH (default 256x144; --full 640x360)");
  cmd->add_option("--conform-size", o->conform_size, "Frames measured against the oracle")
      ->capture_default_str();
  cmd->add_option("--repetitions", o->repetitions,
                  "Timed repetitions per case (default 3; --full 5)");
  cmd->add_option("--min-time", o->min_time,
                  "Seconds per repetition of a timed case (the matrix's and the scaling series'), "
                  "at least one frame")
      ->capture_default_str();
  cmd->add_option("--sweep-backend", o->sweep_backend,
                  "Backend of the sweep (default: simd where it is measured, else scalar, in f32; "
                  "--full: scalar, the backend with f64 too, in both)");
  cmd->add_option("--sweep-size", o->sweep_size, "Sweep frames WxH (default 64x36; --full 96x54)");
  cmd->add_flag("--no-sweep", o->no_sweep, "Skip the eps x offset sweep");
  cmd->add_flag("--no-scaling", o->no_scaling, "Skip the scaling series");
  cmd->add_flag("--no-html", o->no_html, "Write results.json only");
  cmd->add_option("--baseline", o->baseline,
                  "Check against this baseline (reports/baseline.json): exit 1 on a regression")
      ->check(CLI::ExistingFile);
  cmd->add_option("--previous", o->previous,
                  "An earlier run's results.json: the page shows the change per case (verdicts "
                  "first, then hit mismatch, ambiguous share and speed)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--write-baseline", o->write_baseline,
                  "Write this run's deterministic figures as a baseline file");
  cmd->add_option("--python", o->python,
                  "python3 with matplotlib and jinja2 (env FLATMARCH_PYTHON)")
      ->capture_default_str();
  cmd->add_option(
      "--shard", o->shard,
      "I/N: measure only shard I of N of the report's cases (matrix cases, sweep groups, "
      "scaling series; split by their expected cost, the same in every shard) and "
      "write its results.json and images, for a scheduler to run the shards apart "
      "(ci/slurm/report.sbatch, .github/workflows/bench.yml); `flatmarch merge` puts "
      "them together and makes the ranking, the recommendation, the gallery, the gate "
      "and the page. Prints the shard's estimated time first");
  add_march_param_options(
      *cmd, o->params,
      {.eps = true, .offset = true, .max_steps = true, .max_distance = false, .omega = false});
  add_backend_options(*cmd, o->backend_options);
  add_external_option(*cmd, o->externals);
  add_supervision_options(*cmd, o->supervision, "OUT/results.json.journal");
  cmd->add_flag("-q,--quiet", o->quiet, "No progress");
  cmd->add_option("--compile-jobs", o->compile_jobs,
                  "Compile the GPU backends' kernels (opengl, vulkan: a program per scene and "
                  "method) before the matrix, this many at once, into the driver's disk cache "
                  "(default: one per core, at most 8; 0: none, each case compiles its own)")
      ->check(CLI::Range(0, 64));
  cmd->add_option("--compile-worker", o->compile_worker)->group("");  // hidden
  cmd->add_option("--progress-log", o->progress_log,
                  "Write a JSON line per finished case (its stage, seconds and the stage's "
                  "estimate of the time left then) to this file: bench/eta_check.py judges the "
                  "estimates by it");
  cmd->callback([o] {
    if (o->supervision.resume && !o->results.empty())
      throw UsageError("--resume finishes a measuring run: give no RESULTS with it");
    if (!o->shard.empty() && (!o->results.empty() || !o->baseline.empty() ||
                              !o->write_baseline.empty() || !o->previous.empty()))
      throw UsageError(
          "--shard measures a part: give --baseline, --write-baseline and --previous to `flatmarch "
          "merge`, which puts the shards together, and no RESULTS");
    if (!o->previous.empty()) {
      check_results_file("--previous", o->previous);
      if (o->results.size() > 1)
        throw UsageError("--previous compares one run with an earlier one: give one RESULTS");
      if (o->no_html) throw UsageError("--previous is shown on the page: drop --no-html");
    }
    if (!o->results.empty()) {
      if (!o->baseline.empty() || !o->write_baseline.empty())
        throw UsageError("--baseline and --write-baseline measure: give no RESULTS with them");
      for (const std::string& file : o->results) check_results_file("RESULTS", file);
      make_report_page(o->python, o->results, o->out, o->previous);
      std::printf("report: open %s\n", (fs::path(o->out) / "index.html").c_str());
      return;
    }
    check_march_params(o->params);
    check_backend_options(o->backend_options);
    const std::vector<std::string> externals = register_externals(o->externals);
    reports::ReportOptions r;
    r.matrix.params = o->params;
    r.matrix.backend_options = o->backend_options;
    r.matrix.methods = parse_methods(o->methods);
    if (!o->backends.empty()) r.matrix.backends = o->backends;
    for (const std::string& name : externals)
      if (std::find(r.matrix.backends.begin(), r.matrix.backends.end(), name) ==
          r.matrix.backends.end())
        r.matrix.backends.push_back(name);
    for (const std::string& b : o->skip_backends) {
      const auto at = std::find(r.matrix.backends.begin(), r.matrix.backends.end(), b);
      if (at == r.matrix.backends.end())
        throw UsageError("--skip-backend: " + b + " is not among the backends measured (" +
                         joined(r.matrix.backends) + ")");
      r.matrix.backends.erase(at);
    }
    // A compile worker makes no backend it does not compile on (a browser's start above all).
    if (!o->compile_worker.empty()) r.matrix.backends = o->compile_worker;
    for (const std::string& b : r.matrix.backends) make_kernel_backend(b, o->backend_options);
    std::tie(r.matrix.width, r.matrix.height) =
        parse_size("--size", o->size.empty() ? (o->full ? "640x360" : "256x144") : o->size);
    std::tie(r.matrix.conform_width, r.matrix.conform_height) =
        parse_size("--conform-size", o->conform_size);
    check_frame_memory("--size", r.matrix.width, r.matrix.height, kRenderFrames, "a timed frame");
    check_frame_memory("--conform-size", r.matrix.conform_width, r.matrix.conform_height,
                       kCaseFrames, "a conformance case");
    r.matrix.repetitions = o->repetitions ? o->repetitions : (o->full ? 5 : 3);
    if (r.matrix.repetitions < 2 || r.matrix.repetitions > 100)
      throw UsageError("--repetitions: expected 2 to 100");
    if (!(o->min_time > 0.0 && o->min_time <= 10.0))
      throw UsageError("--min-time: expected seconds in (0, 10]");
    r.matrix.min_time = o->min_time;
    r.matrix.conformance = true;
    // Images are a by-product: without the image module the figures are measured all the same.
    const std::string no_images = image_module_missing();
    r.matrix.images = o->no_html || !no_images.empty() ? fs::path() : fs::path(o->out) / "images";
    const std::vector<Scene> scenes = load_scenes(o->scenes, o->galleries);

    // The CPU backend of the quick sweep and scaling series: the SIMD backend where the report
    // measures it and it runs, else the scalar one.
    const std::string cpu_backend = [&] {
      for (const std::string& name : cpu_backend_names()) {
        const bool measured = std::find(r.matrix.backends.begin(), r.matrix.backends.end(), name) !=
                              r.matrix.backends.end();
        if (measured && make_backend(name, o->backend_options)->availability().available)
          return name;
      }
      return reference_cpu_backend();
    }();
    r.sweep_enabled = !o->no_sweep;
    r.sweep_all_scenes = o->full;
    r.sweep.methods = r.matrix.methods;
    r.sweep.params.max_steps = o->params.max_steps;
    r.sweep.backend_options = o->backend_options;
    // The quick sweep in f32, the precision every backend marches in, on the SIMD backend
    // (cpu_backend: 2.2x the scalar backend's speed over a sweep's small frames, and the backend
    // a CPU's ranking puts first; the two agree on every point's verdict on the l-shape and the
    // cube); --full: the scalar backend in f32 and f64, the precision the CPU backends have
    // beside it. The quick sweep was 72 s of a 2-core machine's report, and is 20 s.
    if (!o->sweep_backend.empty()) {
      r.sweep.backend = o->sweep_backend;
    } else if (!o->full) {
      r.sweep.backend = cpu_backend;
    }
    if (!o->full) r.sweep.precisions = {Precision::f32};
    if (r.sweep_enabled) {
      const std::unique_ptr<Backend> b = make_backend(r.sweep.backend, o->backend_options);
      const std::vector<std::string> kernel = kernel_backend_names();
      if (!b || std::find(kernel.begin(), kernel.end(), r.sweep.backend) == kernel.end())
        throw UsageError("--sweep-backend: expected one of " + joined(kernel) + ", got \"" +
                         r.sweep.backend + "\"");
      if (const Availability a = b->availability(); !a.available)
        throw UnavailableError("--sweep-backend: the " + r.sweep.backend +
                               " backend is unavailable here: " + a.reason);
    }
    r.sweep.repetitions = o->full ? 3 : 2;
    std::tie(r.sweep.width, r.sweep.height) = parse_size(
        "--sweep-size", o->sweep_size.empty() ? (o->full ? "96x54" : "64x36") : o->sweep_size);
    check_frame_memory("--sweep-size", r.sweep.width, r.sweep.height, kCaseFrames,
                       "a sweep point's conformance case");

    r.scaling_enabled = !o->no_scaling;
    r.scaling.methods = r.matrix.methods;
    r.scaling.backend_options = o->backend_options;
    r.scaling.min_time = o->min_time;
    for (const Scene& s : scenes)
      if (s.name == "torus") r.scaling.resolution_scene = s;
    if (o->full) {
      r.scaling.backends = r.matrix.backends;
      r.scaling.polygon_n.clear();
      for (int n = 2; n <= 32; ++n) r.scaling.polygon_n.push_back(n);
      r.scaling.staircase_squares = {2, 4, 8, 16, 32, 64, 128};
      r.scaling.resolutions = {{80, 45}, {160, 90}, {320, 180}, {640, 360}, {1280, 720}};
      r.scaling.max_distances = {10, 20, 40, 80, 160, 320};
    } else {
      // The quick series on one CPU backend (cpu_backend; the scalar backend's beside the SIMD
      // backend's took 18 s of a 2-core machine's report); every backend with --full.
      r.scaling.backends = {cpu_backend};
    }

    if (!o->shard.empty()) r.shard = parse_shard_option(o->shard);

    // The matrix's backends, made once: a worker runs case after case on them; the supervisor
    // lists the cases by them and lets them go.
    std::optional<reports::MatrixBackends> backends;
    try {
      backends = reports::matrix_backends(r.matrix);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());  // an unknown backend, an expectation file that cannot be used
    }
    // A browser drawing in software (webgl on SwiftShader) takes many times the other backends'
    // time a case (4.8 s against 0.3-0.6 s on a 2-core Zen 5, a prism's 20 s): measured on a
    // sample unless asked for all.
    for (const auto& b : backends->available) {
      const BackendEntry* entry = find_backend_entry(b->name());
      if (o->full || o->all_scenes || !entry || entry->software_sample_why.empty()) continue;
      const std::optional<DeviceInfo> device = b->device();
      if (!device || !device->software) continue;
      r.matrix.sampled_backends.push_back(b->name());
      // The simplest scene of each surface type, each with one method, the methods in turn.
      const std::vector<std::string> chosen = reports::simplest_of_each_surface_type(scenes);
      for (size_t k = 0; k < chosen.size(); ++k)
        r.matrix.sample_cases.push_back(chosen[k] + "/" +
                                        to_string(r.matrix.methods[k % r.matrix.methods.size()]));
      r.matrix.sample_why = entry->software_sample_why + " (" + device->name +
                            "): the simplest scene of each surface type, with one method each, "
                            "the methods in turn; --all-scenes or --full measures every case";
    }
    // The run's cases (a shard's), each run in a worker (or here, --isolate none), journaled.
    const std::vector<std::pair<std::string, double>> all =
        reports::report_cases(scenes, r, &*backends);
    const json skipped = backends->skipped;
    std::vector<std::string> compiling;  // the backends whose kernels a case compiles
    std::vector<std::string> together;   // those whose cases run one after another
    for (const auto& b : backends->available) {
      if (b->compiles_per_scene()) compiling.push_back(b->name());
      if (b->runs_back_to_back()) together.push_back(b->name());
    }
    if (!o->supervision.worker && o->supervision.isolate != "none") backends.reset();
    std::optional<reports::ShardPlan> plan;
    if (r.shard) plan = reports::plan_shard(*r.shard, all);
    json results = reports::report_header(scenes, r);
    reports::add_to_benchmark_context(results["fingerprint"]);
    conformance::Suite matrix_suite, sweep_suite;
    // One case here: the part of the results it measures.
    const auto run_case = [&](const std::string& key) -> json {
      if (!backends) backends = reports::matrix_backends(r.matrix);
      if (key.rfind("compile/", 0) == 0)
        return record_or_error(
            [&] { return reports::run_compile_case(key, scenes, r.matrix, backends->available); });
      return record_or_error([&]() -> json {
        // A backend rests after each case (Backend::rest), or, where its cases run back to back,
        // before the first case of another that follows them.
        const reports::CaseGroups g = reports::case_groups(key);
        for (const auto& b : backends->available)
          if (b->runs_back_to_back() && !(g.stage == "matrix" && g.group == b->name())) b->rest();
        json part = reports::run_report_part(
            scenes, r, [&](const std::string& k) { return k == key; }, {matrix_suite, sweep_suite},
            nullptr, &*backends, /*every_stage=*/false);
        for (const auto& b : backends->available)
          if (!b->runs_back_to_back()) b->rest();
        // A case this process cannot run (its backend unavailable here, not where the run was
        // planned) says so, and why, rather than coming back empty.
        const std::vector<std::string> measured = reports::report_part_keys(part);
        if (std::find(measured.begin(), measured.end(), key) != measured.end()) return part;
        // A case its renderer cannot render (an external one's): skipped, in the part.
        if (part.contains("matrix"))
          for (const json& skip : part["matrix"]["skipped"])
            if (skip.contains("scene") &&
                reports::matrix_case_key(skip["backend"], skip["method"], skip["scene"]) == key)
              return part;
        std::string why;
        for (const json& skip : backends->skipped)
          why +=
              "; " + skip["backend"].get<std::string>() + " " + skip["reason"].get<std::string>();
        return {{"error", "no such case here" + why}};
      });
    };
    if (o->supervision.worker) {
      reports::serve_cases(run_case);
      return;
    }
    if (plan) std::fprintf(stderr, "report: %s\n", plan->summary.c_str());
    {
      std::error_code error;
      fs::create_directories(o->out, error);
      if (error) throw UsageError("-o: cannot create " + o->out + ": " + error.message());
    }
    SupervisedRun run{.command = "report",
                      .journal = fs::path(o->out) / "results.json.journal",
                      .fingerprint = results["fingerprint"],
                      .options = results["options"],
                      .cases = {},
                      .quiet = o->quiet,
                      .resumed = {}};
    run.options["min_time"] = r.matrix.min_time;
    run.options["images"] = !r.matrix.images.empty();
    run.options["sweep"] = {
        {"backend", r.sweep.backend},
        {"size", std::to_string(r.sweep.width) + "x" + std::to_string(r.sweep.height)},
        {"repetitions", r.sweep.repetitions}};
    if (plan) run.options["shard"] = plan->record;
    // Run so that every backend's cases are timed early (the estimates are calibrated on them),
    // those of a backend that runs them back to back one after another from where its second
    // falls, the oracle's share priced on the first case of a scene and method; put together in
    // the run's order all the same.
    std::vector<std::pair<std::string, double>> held;
    for (const auto& c : all)
      if (!plan || plan->holds(c.first)) held.push_back(c);
    const std::vector<std::pair<std::string, double>> order = reports::oracle_once(
        reports::back_to_back(reports::calibrating_order(held), together), scenes, r.matrix);
    for (const auto& [key, cost] : order) run.cases.push_back({key, cost});
    for (const json& skip : skipped)
      if (!o->quiet)
        std::fprintf(stderr, "report: %s skipped: %s\n", skip["backend"].get<std::string>().c_str(),
                     skip["reason"].get<std::string>().c_str());
    if (!o->quiet)
      for (const std::string& b : r.matrix.sampled_backends)
        std::fprintf(stderr, "report: %s on a sample: %s\n", b.c_str(),
                     r.matrix.sample_why.c_str());
    // The GPU kernels of the matrix compiled first, a case a core (reports::compile_cases): not
    // where the cases run here, nor for a run resumed (its kernels are warm from the run it
    // finishes), nor where the driver's cache is off.
    const int jobs =
        o->compile_jobs >= 0
            ? o->compile_jobs
            : static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
    std::vector<std::pair<std::string, double>> compiled, shown;
    const char* no_cache = std::getenv("MESA_SHADER_CACHE_DISABLE");
    if (jobs > 0 && o->supervision.isolate == "worker" && !o->supervision.resume &&
        !(no_cache && (std::string(no_cache) == "true" || std::string(no_cache) == "1")))
      compiled = reports::compile_cases(order, scenes, compiling, r.matrix.methods);
    // The dearest first: the last to finish are the cheap ones, and the cores finish together.
    std::stable_sort(compiled.begin(), compiled.end(),
                     [](const auto& a, const auto& b) { return a.second > b.second; });
    for (const auto& [key, cost] : compiled) shown.emplace_back(key, cost / jobs);
    shown.insert(shown.end(), order.begin(), order.end());
    CaseProgress progress("report", shown, o->quiet, o->progress_log);
    run.resumed = [&](const std::string& key) { progress.resumed(key); };
    const auto show = [&](const std::string& key, const json& record) {
      if (unfinished_record(record)) progress.say("report: " + unfinished_lines(key, record));
      progress.finished(key);
    };
    if (!compiled.empty()) {
      std::vector<RunCase> ahead;
      for (const auto& [key, cost] : compiled) ahead.push_back({key, cost});
      // A kernel that does not compile is the matrix case's error to report, not this one's.
      std::vector<std::string> only;
      for (const std::string& b : compiling) only.insert(only.end(), {"--compile-worker", b});
      run_alongside(ahead, o->supervision, jobs, only,
                    [&](const std::string& key, const json&) { progress.finished(key); });
    }
    std::optional<reports::Journal> journal;
    const std::map<std::string, json> records =
        run_supervised(run, o->supervision, run_case, show, journal);
    progress.close();
    // The parts put together in the run's order; a case that did not finish in its place.
    std::vector<std::string> keys;
    std::vector<json> made;  // the unfinished matrix cases' parts
    made.reserve(run.cases.size());
    std::vector<std::pair<std::string, const json*>> parts;
    results["unfinished"] = json::array();
    for (const auto& [key, cost] : held) {
      keys.push_back(key);
      const json& record = records.at(key);
      if (!unfinished_record(record)) {
        parts.emplace_back(key, &record);
        continue;
      }
      results["unfinished"].push_back(reports::unfinished_entry(key, record));
      if (json part = reports::unfinished_part(key, record, scenes, r); !part.is_null()) {
        made.push_back(std::move(part));
        parts.emplace_back(key, &made.back());
      }
    }
    results.update(reports::assemble_report(results, parts, keys));
    if (r.shard) {
      results["shard"] = plan->record;
      if (!r.matrix.images.empty())
        reports::draw_oracle_images(scenes, r.matrix, results["matrix"]);
    } else {
      reports::finish_report(results, scenes, r);
    }
    if (!no_images.empty())
      results["left_out"] = {
          {"what", o->no_html ? json::array({"image.perceptual_failpercent"})
                              : json::array({"image.perceptual_failpercent", "images"})},
          {"why", no_images}};
    const auto say = [&](const fs::path& file) {
      if (no_images.empty()) return;
      say_left_out("report",
                   o->no_html ? "Yee's perceptual check"
                              : "Yee's perceptual check, each backend's frames and the "
                                "recommended gallery",
                   std::string(kPerceptualLeftOut) +
                       (o->no_html ? ""
                                   : "; on a machine with OpenImageIO (ci/install-deps.sh), "
                                     "`flatmarch merge " +
                                         file.string() +
                                         " -o DIR/results.json` draws the recommended gallery "
                                         "and the page from these results"));
    };
    // The cases that did not finish, again at the end, where a person reads.
    const auto say_unfinished = [&] {
      if (results["unfinished"].empty()) return;
      std::printf("report: %zu cases did not finish (the page's failure list has them):\n",
                  results["unfinished"].size());
      for (const json& u : results["unfinished"])
        std::printf("  %s  %s\n", u["key"].get<std::string>().c_str(),
                    u["error"].get<std::string>().c_str());
    };
    if (r.shard) {
      const fs::path file = fs::path(o->out) / "results.json";
      write_json(file, results);
      journal->complete();
      say(file);
      say_unfinished();
      std::printf(
          "report: shard %s: wrote %s; put the shards together with `flatmarch merge "
          "SHARD.../results.json -o OUT/results.json`\n",
          r.shard->text().c_str(), file.c_str());
      return;
    }
    results["regression"] = regression_section(results, o->baseline);
    const std::vector<std::string> changes = expectation_changes(results);
    const fs::path file = fs::path(o->out) / "results.json";
    write_json(file, results);
    journal->complete();
    std::printf("%s", reports::describe_selection(results, "").c_str());
    say_unfinished();
    std::printf("report: wrote %s\n", file.c_str());
    say(file);
    if (!o->write_baseline.empty()) {
      write_json(o->write_baseline, reports::make_baseline(results));
      std::printf("report: wrote the baseline %s\n", o->write_baseline.c_str());
    }
    if (!o->no_html) {
      make_report_page(o->python, {file.string()}, o->out, o->previous);
      std::printf("report: open %s\n", (fs::path(o->out) / "index.html").c_str());
    }
    if (!o->baseline.empty()) gate(results, o->baseline, o->out);
    if (!changes.empty())
      throw ConformanceFailure(std::to_string(changes.size()) +
                               " cases changed against their expectation files");
  });
}

}  // namespace flatmarch::cli
