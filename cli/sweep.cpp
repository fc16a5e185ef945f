// `flatmarch sweep`: each scene over a grid of eps and offsets, measured against the oracle, and
// the stable region, Pareto front and recommendation per surface type.
#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/supervised.hpp"
#include "conformance/suite.hpp"
#include "reports/fingerprint.hpp"
#include "reports/report.hpp"
#include "reports/shard.hpp"
#include "reports/supervise.hpp"
#include "reports/sweep.hpp"

namespace flatmarch::cli {

using nlohmann::json;

void add_sweep(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "sweep",
      "March each scene over a grid of eps (1e-1 ... 1e-7) and offsets (0.5 ... 10 x eps, and\n"
      "fixed values) for each method and precision, measuring time, steps and accuracy against\n"
      "the oracle (conformance verdict, hit mismatch, trace agreement, failures by class). Per\n"
      "surface type it prints the stable region (every scene passes), the speed-accuracy Pareto\n"
      "front and the recommended eps and offset; writes everything as JSON.");
  struct Options {
    std::vector<std::string> scenes, methods, precisions;
    std::vector<std::string> galleries = {data_folder("scenes")};
    std::string size = "64x36", json = "sweep.json", shard;
    reports::SweepOptions sweep;
    SupervisionOptions supervision;
    bool quiet = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("--scene", o->scenes, "Scene file or gallery name (repeat; default: all)");
  cmd->add_option("--gallery", o->galleries, "Folders of scenes")->capture_default_str();
  cmd->add_option("--backend", o->sweep.backend, "Backend to sweep")->capture_default_str();
  cmd->add_option("--method", o->methods, kernel_method_names() + " (repeat; default: all)");
  cmd->add_option("--precision", o->precisions, "f32 or f64 (repeat; default: those it has)");
  cmd->add_option("--eps", o->sweep.eps, "The eps values")->capture_default_str();
  cmd->add_option("--offset-factor", o->sweep.offset_factors, "Offsets as multiples of eps")
      ->capture_default_str();
  cmd->add_option("--offset-fixed", o->sweep.offset_fixed, "Fixed offsets")->capture_default_str();
  cmd->add_option("--size", o->size, "Frame size WxH")->capture_default_str();
  cmd->add_option("--repetitions", o->sweep.repetitions, "Frames timed per point (median)")
      ->capture_default_str();
  add_march_param_options(
      *cmd, o->sweep.params,
      {.eps = false, .offset = false, .max_steps = true, .max_distance = false, .omega = false});
  add_backend_options(*cmd, o->sweep.backend_options);
  cmd->add_option("--json", o->json, "Where to write the results")->capture_default_str();
  cmd->add_option("--shard", o->shard,
                  "I/N: sweep only shard I of N of the groups (surface type x method, each with "
                  "its precisions, grid and re-checks; split by their expected cost, the same in "
                  "every shard); `flatmarch merge` puts the shards' JSON together");
  add_supervision_options(*cmd, o->supervision, "beside --json: JSON.journal");
  cmd->add_flag("-q,--quiet", o->quiet, "No progress");
  cmd->callback([o] {
    std::tie(o->sweep.width, o->sweep.height) = parse_size("--size", o->size);
    check_frame_memory("--size", o->sweep.width, o->sweep.height, kCaseFrames,
                       "a sweep point's conformance case");
    o->sweep.methods = parse_methods(o->methods);
    if (!o->precisions.empty()) {
      o->sweep.precisions.clear();
      for (const std::string& p : o->precisions) o->sweep.precisions.push_back(parse_precision(p));
    }
    for (double e : o->sweep.eps)
      if (!(e > 0.0 && e < 1.0)) throw UsageError("--eps: values must lie in (0, 1)");
    for (double f : o->sweep.offset_factors)
      if (!(f > 0.0 && f <= 1000.0)) throw UsageError("--offset-factor: values in (0, 1000]");
    for (double f : o->sweep.offset_fixed)
      if (!(f > 0.0 && f < 1.0)) throw UsageError("--offset-fixed: values must lie in (0, 1)");
    if (o->sweep.repetitions < 1 || o->sweep.repetitions > 100)
      throw UsageError("--repetitions: expected 1 to 100");
    check_march_params(o->sweep.params);
    check_backend_options(o->sweep.backend_options);
    const std::unique_ptr<Backend> backend =
        make_kernel_backend(o->sweep.backend, o->sweep.backend_options);
    if (const Availability a = backend->availability(); !a.available)
      throw UnavailableError("the " + o->sweep.backend +
                             " backend is unavailable here: " + a.reason);
    const std::vector<Precision> has = backend->precisions();
    if (std::none_of(o->sweep.precisions.begin(), o->sweep.precisions.end(), [&](Precision p) {
          return std::find(has.begin(), has.end(), p) != has.end();
        }))
      throw UsageError("--precision: the " + o->sweep.backend + " backend marches in f32 only");
    const std::vector<Scene> scenes = load_scenes(o->scenes, o->galleries);
    // The groups (a shard's), each run in a worker (or here, --isolate none), journaled.
    const std::vector<std::pair<std::string, double>> groups =
        reports::sweep_cases(scenes, o->sweep);
    std::optional<reports::ShardPlan> plan;
    if (!o->shard.empty())
      plan = reports::plan_shard(parse_shard_option(o->shard), groups, "groups");
    conformance::Suite suite;
    // One group here: its points and re-checks.
    const auto run_group = [&](const std::string& key) -> json {
      reports::SweepOptions one = o->sweep;
      one.holds = [&](const std::string& k) { return k == key; };
      return record_or_error([&] { return reports::run_sweep(scenes, one, suite, nullptr); });
    };
    if (o->supervision.worker) {
      reports::serve_cases(run_group);
      return;
    }
    // Said even when quiet: the first line of a scheduler's log.
    if (plan) std::fprintf(stderr, "sweep: %s\n", plan->summary.c_str());
    json options = {{"size", o->size},
                    {"backend", o->sweep.backend},
                    {"eps", o->sweep.eps},
                    {"offset_factors", o->sweep.offset_factors},
                    {"offset_fixed", o->sweep.offset_fixed},
                    {"repetitions", o->sweep.repetitions},
                    {"max_steps", o->sweep.params.max_steps},
                    {"precisions", json::array()}};
    for (Precision p : o->sweep.precisions)
      options["precisions"].push_back(p == Precision::f32 ? "f32" : "f64");
    if (plan) options["shard"] = plan->record;
    SupervisedRun run{.command = "sweep",
                      .journal = o->json + ".journal",
                      .fingerprint = reports::hardware_fingerprint(),
                      .options = options,
                      .cases = {},
                      .quiet = o->quiet,
                      .resumed = {}};
    for (const auto& [key, cost] : groups)
      if (!plan || plan->holds(key)) run.cases.push_back({key, cost});
    ProgressReporter progress("sweep", o->quiet);
    size_t done = 0;
    json unfinished = json::array();
    const auto show = [&](const std::string& key, const json& record) {
      if (unfinished_record(record)) {
        std::fputs(("sweep: " + unfinished_lines(key, record)).c_str(), stderr);
        unfinished.push_back(reports::unfinished_entry(key, record));
      }
      progress(static_cast<double>(++done) / static_cast<double>(run.cases.size()));
    };
    std::optional<reports::Journal> journal;
    const std::map<std::string, json> records =
        run_supervised(run, o->supervision, run_group, show, journal);
    progress.done();
    // The groups' points and re-checks put together, analysed again.
    json points = json::array(), confirmations = json::array(), sweep_options;
    for (const RunCase& c : run.cases) {
      const json& part = records.at(c.key);
      if (unfinished_record(part)) continue;
      if (sweep_options.is_null()) sweep_options = part["options"];
      for (const json& p : part["points"]) points.push_back(p);
      for (const json& k : part["confirmations"]) confirmations.push_back(k);
    }
    json scene_names = json::array(), methods = json::array();
    for (const Scene& s : scenes) scene_names.push_back(s.name);
    for (Method m : o->sweep.methods) methods.push_back(to_string(m));
    if (sweep_options.is_null()) sweep_options = {{"methods", methods}};
    json result = reports::merged_sweep(sweep_options, std::move(points), std::move(confirmations),
                                        scene_names, methods);
    result["unfinished"] = unfinished;
    json shard = plan ? plan->record : json();
    result["format"] = "flatmarch-sweep/1";
    result["fingerprint"] = reports::hardware_fingerprint();
    result["options"]["scenes"] = json::array();
    for (const Scene& s : scenes) result["options"]["scenes"].push_back(s.name);
    result["options"]["precisions"] = json::array();
    for (Precision p : o->sweep.precisions)
      result["options"]["precisions"].push_back(p == Precision::f32 ? "f32" : "f64");
    if (!shard.is_null()) result["shard"] = shard;
    const std::string no_images = image_module_missing();
    if (!no_images.empty())
      result["left_out"] = {{"what", json::array({"image.perceptual_failpercent"})},
                            {"why", no_images}};
    write_json(o->json, result);
    std::printf("%-12s %-9s %-4s %7s  %-26s %s\n", "surface", "method", "prec", "stable",
                "recommended eps / offset", "pareto front (eps, offset: ms, hit mismatch %)");
    for (const json& g : result["analysis"]) {
      std::string rec = "-";
      if (!g["recommended"].is_null()) {
        char s[64];
        std::snprintf(s, sizeof s, "%g / %g%s", g["recommended"]["eps"].get<double>(),
                      g["recommended"]["offset"].get<double>(),
                      g["recommended"]["fallback"].get<bool>() ? " (fallback)" : "");
        rec = s;
      }
      std::string front;
      for (const json& p : g["pareto"]) {
        char s[96];
        std::snprintf(s, sizeof s, "%s%g,%s: %.2g, %.2g", front.empty() ? "" : "; ",
                      p["eps"].get<double>(), p["offset_label"].get<std::string>().c_str(),
                      p["time_ms"].get<double>(), 100.0 * p["hit_mismatch"].get<double>());
        front += s;
      }
      std::printf("%-12s %-9s %-4s %3zu/%-3zu  %-26s %s\n",
                  g["surface_type"].get<std::string>().c_str(),
                  g["method"].get<std::string>().c_str(), g["precision"].get<std::string>().c_str(),
                  g["stable"].size(), g["grid"].size(), rec.c_str(), front.c_str());
    }
    journal->complete();
    for (const json& u : unfinished)
      std::printf("did not finish: %s  %s\n", u["key"].get<std::string>().c_str(),
                  u["error"].get<std::string>().c_str());
    std::printf("wrote %s\n", o->json.c_str());
    if (!no_images.empty()) say_left_out("sweep", "Yee's perceptual check", kPerceptualLeftOut);
  });
}

}  // namespace flatmarch::cli
