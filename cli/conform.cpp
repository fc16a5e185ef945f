// `flatmarch conform`: the conformance suite from the command line.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "cli/supervised.hpp"
#include "conformance/expectations.hpp"
#include "conformance/suite.hpp"
#include "conformance/vocabulary.hpp"
#include "output/image_io.hpp"
#include "reports/fingerprint.hpp"
#include "reports/shard.hpp"
#include "reports/supervise.hpp"
#include "scene/load.hpp"

namespace flatmarch::cli {

namespace fs = std::filesystem;

namespace {

std::string percent(double share) {
  char s[32];
  std::snprintf(s, sizeof s, "%.3f", 100.0 * share);
  return s;
}

std::string failures_summary(const conformance::CaseResult& r) {
  std::string s;
  for (int c = 0; c < conformance::kFailureClasses; ++c) {
    const size_t n =
        r.aov.failures[static_cast<size_t>(c)] + r.trace_failures[static_cast<size_t>(c)];
    if (n)
      s += (s.empty() ? "" : " ") + std::string(to_string(static_cast<conformance::Failure>(c))) +
           ":" + std::to_string(n);
  }
  return s.empty() ? "-" : s;
}

// The table's lines for a case: its row, then its limit or the checks it failed.
std::string table_lines(const conformance::CaseResult& r) {
  int diverged = 0;
  for (const auto& t : r.traces) diverged += t.failure.has_value();
  // What a renderer we did not write does not give: "-".
  const auto shown = [&](const char* check, const std::string& value) {
    return std::find(r.unmeasured.begin(), r.unmeasured.end(), check) == r.unmeasured.end()
               ? value
               : std::string("-");
  };
  char ks[32], traces[32];
  std::snprintf(ks, sizeof ks, "%.3f", r.steps_ks);
  std::snprintf(traces, sizeof traces, "%d/%zu", diverged, r.traces.size());
  char row[512];
  std::snprintf(
      row, sizeof row, "%-8s %-30s %-9s %7s %8s %8s %7s %7s %6s  %-24s %s\n", r.backend.c_str(),
      r.scene.c_str(), to_string(r.params.method),
      percent(static_cast<double>(r.aov.ambiguous) / static_cast<double>(r.aov.pixels)).c_str(),
      shown("hit_rate", percent(r.aov.hit_rate())).c_str(),
      shown("crossings_rate", percent(r.aov.crossings_rate())).c_str(),
      shown("image",
            percent(static_cast<double>(r.image.fail) / static_cast<double>(r.image.pixels)))
          .c_str(),
      shown("steps", ks).c_str(), shown("traces", traces).c_str(), failures_summary(r).c_str(),
      r.verdict == conformance::Verdict::pass    ? "pass"
      : r.verdict == conformance::Verdict::limit ? "limit"
                                                 : "FAIL");
  std::string lines = row;
  if (r.verdict == conformance::Verdict::limit) lines += "    " + r.limit + "\n";
  for (const std::string& line : r.failed_checks()) lines += "    " + line + "\n";
  return lines;
}

}  // namespace

void add_conform(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "conform",
      "Measure backends against the oracle: for each backend, scene and method, a frame's hit and\n"
      "crossings AOVs on the pixels the oracle can decide at this precision (the others are\n"
      "reported apart as ambiguous), its colour (idiff-style thresholds and Yee's perceptual\n"
      "metric over the frame; CIE Delta E over each object, the walls, the floor and the sky),\n"
      "its step counts against the scalar backend in float64, and the traces of generic\n"
      "probe rays; failures are classed (stuck, wrong_edge, missed_object, phantom_hit,\n"
      "early_escape, late_escape, leak). Each case is judged by conformance/thresholds.json:\n"
      "pass; limit, when it fails them only through a documented failure mode of its method\n"
      "(rays out of max_steps, offset <= eps, the re-entry push's drift), named with its size;\n"
      "or FAIL.\n"
      "Prints a table, writes JSON; exits 1 when a case fails (or, with --strict, is at its\n"
      "method's limit). Columns: ambig% pixels the mask\n"
      "leaves undecided; hit% and cross% decided pixels whose hit and crossings are the oracle's;\n"
      "img% pixels over idiff's fail threshold; stepKS the steps' distance from float64's;\n"
      "traces probe rays diverged / traced; failures the rays of each class.");
  struct Options {
    std::vector<std::string> backends, scenes, methods;
    std::vector<std::string> galleries = {data_folder("scenes"), data_folder("conformance/scenes")};
    std::string size = "160x90", json = "conform.json", thresholds, error_images;
    std::string precision = "f32";
    MarchParams params;
    BackendOptions backend_options;
    std::string shard;
    std::vector<std::string> externals;
    bool quiet = false;
    bool strict = false;
    SupervisionOptions supervision;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("--backend", o->backends,
                  "Backend to measure (repeat for more; default: every kernel backend, those "
                  "unavailable here skipped with the reason)");
  cmd->add_option("--scene", o->scenes,
                  "Scene file, or a scene's name in a --gallery folder (repeat; default: every "
                  "scene of the --gallery folders)");
  cmd->add_option("--method", o->methods, kernel_method_names() + " (repeat; default: all)");
  cmd->add_option("--gallery", o->galleries,
                  "Folders of scenes, run whole when no --scene is given and searched for "
                  "--scene names (repeat; default: scenes and conformance/scenes, the suite's own)")
      ->capture_default_str();
  cmd->add_option("--size", o->size, "Frame size WxH")->capture_default_str();
  cmd->add_option("--json", o->json, "Where to write the results")->capture_default_str();
  cmd->add_option("--thresholds", o->thresholds,
                  "Thresholds file (default: conformance/thresholds.json as built in)");
  cmd->add_option("--error-images", o->error_images,
                  "Write each case's error image into this folder, BACKEND-SCENE-METHOD.png: " +
                      conformance::error_legend());
  add_march_param_options(*cmd, o->params);
  cmd->add_option("--precision", o->precision, "f32 or f64 (backends without f64 are skipped)")
      ->capture_default_str();
  add_backend_options(*cmd, o->backend_options);
  add_external_option(*cmd, o->externals);
  cmd->add_option("--shard", o->shard,
                  "I/N: run only shard I of N of the cases (split by their expected cost, the same "
                  "in every shard), for a scheduler to run the shards apart; `flatmarch merge` "
                  "puts their JSON back together");
  add_supervision_options(*cmd, o->supervision, "beside --json: JSON.journal");
  cmd->add_flag("-q,--quiet", o->quiet, "Only the summary line");
  cmd->add_flag("--strict", o->strict,
                "Exit 1 when a case is at its method's limit too, not only when one fails");
  cmd->callback([o] {
    const std::vector<std::string> externals = register_externals(o->externals);
    const std::pair<int, int> size = parse_size("--size", o->size);
    const int w = size.first, h = size.second;
    check_frame_memory("--size", w, h, kCaseFrames, "a conformance case");
    check_march_params(o->params);
    check_backend_options(o->backend_options);
    o->params.precision = parse_precision(o->precision);
    const std::vector<Method> methods = parse_methods(o->methods);
    const std::vector<Scene> scenes = load_scenes(o->scenes, o->galleries);
    for (const Scene& scene : scenes) check_reach(scene, scene.camera, o->params);
    if (std::any_of(methods.begin(), methods.end(), [](Method m) { return m != Method::analytic; }))
      for (const Scene& scene : scenes) {
        MarchParams sphere = o->params;
        sphere.method = Method::sphere;
        warn_about_resolution(scene, sphere);
      }
    if (o->backends.empty()) o->backends = kernel_backend_names();
    for (const std::string& name : externals)
      if (std::find(o->backends.begin(), o->backends.end(), name) == o->backends.end())
        o->backends.push_back(name);
    nlohmann::json thresholds = conformance::builtin_thresholds();
    if (!o->thresholds.empty()) {
      try {
        thresholds = conformance::load_thresholds(o->thresholds);
      } catch (const std::runtime_error& e) {
        throw UsageError(std::string("--thresholds: ") + e.what());
      }
    }

    conformance::Suite suite(thresholds);
    const std::string no_images = image_module_missing();
    const bool error_images = !o->error_images.empty() && no_images.empty();
    if (error_images) {
      std::error_code error;
      fs::create_directories(o->error_images, error);
      if (error)
        throw UsageError("--error-images: cannot create " + o->error_images + ": " +
                         error.message());
      suite.keep_pixel_classes(true);
    }
    std::optional<reports::Shard> shard;
    if (!o->shard.empty()) shard = parse_shard_option(o->shard);
    nlohmann::json out = {{"format", "flatmarch-conform/1"},
                          {"fingerprint", reports::hardware_fingerprint()},
                          {"options",
                           {{"size", o->size},
                            {"eps", o->params.eps},
                            {"offset", o->params.offset},
                            {"max_steps", o->params.max_steps},
                            {"max_distance", o->params.max_distance},
                            {"omega", o->params.omega},
                            {"precision", o->precision},
                            {"thresholds", thresholds}}},
                          {"cases", nlohmann::json::array()},
                          {"skipped", nlohmann::json::array()}};
    int cases = 0, failed = 0, limits = 0;
    // The run's cases, over the backends available here, and the shard of each.
    std::vector<std::unique_ptr<Backend>> backends;
    for (const std::string& name : o->backends) {
      std::unique_ptr<Backend> backend = make_kernel_backend(name, o->backend_options);
      const Availability a = backend->availability();
      const std::vector<Precision> precisions = backend->precisions();
      std::string skip = a.available ? "" : "unavailable here: " + a.reason;
      if (skip.empty() &&
          std::find(precisions.begin(), precisions.end(), o->params.precision) == precisions.end())
        skip = "does not march in " + o->precision;
      if (!skip.empty()) {
        if (!o->supervision.worker) std::printf("%-8s skipped: %s\n", name.c_str(), skip.c_str());
        out["skipped"].push_back({{"backend", name}, {"reason", skip}});
        continue;
      }
      backends.push_back(std::move(backend));
    }
    // A renderer we did not write runs the cases it can: its methods, the scenes it reads, and
    // not those its expectation file skips; the others are skipped, saying why.
    const conformance::ExternalSkips skips = [&] {
      try {
        return conformance::ExternalSkips(backends);
      } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
      }
    }();
    const std::map<std::string, conformance::Expectations>& expectations = skips.files();
    std::vector<std::pair<std::string, double>> run;
    for (const auto& backend : backends)
      for (const Scene& scene : scenes)
        for (const Method m : methods) {
          const std::string key = conformance::case_key(backend->name(), to_string(m), scene.name);
          if (const std::string why = skips.why(*backend, m, scene); !why.empty()) {
            out["skipped"].push_back({{"backend", backend->name()},
                                      {"scene", scene.name},
                                      {"method", to_string(m)},
                                      {"reason", why}});
            continue;
          }
          run.emplace_back(key, reports::conformance_case_cost(backend->name(), to_string(m),
                                                               reports::edge_count(scene), w, h));
        }
    const reports::ShardPlan plan = reports::plan_shard(shard.value_or(reports::Shard{}), run);
    if (shard) {
      out["shard"] = plan.record;
      std::fprintf(stderr, "conform: %s\n", plan.summary.c_str());
    }
    // The cases this shard holds, in order.
    struct Case {
      std::string key;
      const Backend* backend;
      const Scene* scene;
      Method method;
      double cost;
    };
    std::vector<Case> held;
    {
      size_t k = 0;
      for (const auto& backend : backends)
        for (const Scene& scene : scenes)
          for (const Method m : methods) {
            if (!skips.why(*backend, m, scene).empty()) continue;
            const auto& [key, cost] = run[k++];
            if (plan.holds(key)) held.push_back({key, backend.get(), &scene, m, cost});
          }
    }
    // One case, run here: its record (conformance::to_json's, with its table lines apart).
    const auto run_case = [&](const Case& c) {
      MarchParams params = o->params;
      params.method = c.method;
      return record_or_error([&] {
        const conformance::CaseResult r = suite.run(*c.backend, *c.scene, params, w, h);
        nlohmann::json record = conformance::to_json(r);
        record["table"] = table_lines(r);
        if (error_images) {
          const fs::path file =
              fs::path(o->error_images) /
              (c.backend->name() + "-" + c.scene->name + "-" + to_string(c.method) + ".png");
          write_png(
              conformance::error_image(r.pixel_classes, suite.truth_frame(*c.scene, params, w, h)),
              file);
          record["error_image"] = file.string();
        }
        return record;
      });
    };
    if (o->supervision.worker) {
      reports::serve_cases([&](const std::string& key) {
        for (const Case& c : held)
          if (c.key == key) return run_case(c);
        // Its backend available where the run was planned but not in this process.
        return nlohmann::json{
            {"error", "no such case here: its backend is unavailable in this worker"}};
      });
      return;
    }
    if (!o->quiet)
      std::printf("%-8s %-30s %-9s %7s %8s %8s %7s %7s %6s  %-24s %s\n", "backend", "scene",
                  "method", "ambig%", "hit%", "cross%", "img%", "stepKS", "traces", "failures",
                  "verdict");
    SupervisedRun supervised{.command = "conform",
                             .journal = o->json + ".journal",
                             .fingerprint = out["fingerprint"],
                             .options = out["options"],
                             .cases = {},
                             .quiet = o->quiet,
                             .resumed = {}};
    if (shard) supervised.options["shard"] = plan.record;
    std::map<std::string, const Case*> by_key;
    for (const Case& c : held) {
      supervised.cases.push_back({c.key, c.cost});
      by_key[c.key] = &c;
    }
    int unfinished = 0, skipped = 0;
    const auto show = [&](const std::string& key, const nlohmann::json& record) {
      if (shard && !o->quiet)
        std::fprintf(stderr, "conform: shard %s: case %d of %zu\n", shard->text().c_str(),
                     cases + skipped + 1, out["shard"]["holds"].size());
      const std::string verdict = record_verdict(record);
      if (verdict == "skip") {
        ++skipped;
        if (!o->quiet)
          std::printf("%s  skipped: %s\n", key.c_str(), record.value("skipped", "").c_str());
        return;
      }
      ++cases;
      failed += verdict == conformance::kVerdictFail;
      limits += verdict == conformance::kVerdictLimit;
      const bool finished = verdict == conformance::kVerdictPass ||
                            verdict == conformance::kVerdictLimit ||
                            verdict == conformance::kVerdictFail;
      unfinished += !finished;
      if (o->quiet) return;
      std::fputs(
          finished ? record.value("table", "").c_str() : unfinished_lines(key, record).c_str(),
          stdout);
      std::fflush(stdout);
    };
    std::optional<reports::Journal> journal;
    const std::map<std::string, nlohmann::json> records = run_supervised(
        supervised, o->supervision,
        [&](const std::string& key) { return run_case(*by_key.at(key)); }, show, journal);
    // A renderer with an expectation file counts against the run by its changes alone, as
    // deqp-runner's do: a case that does not do what its file says (an unexpected pass too).
    std::map<std::string, std::vector<std::pair<std::string, std::string>>> judged_runs;
    for (const Case& c : held)
      if (expectations.count(c.backend->name()))
        judged_runs[c.backend->name()].emplace_back(c.key, record_verdict(records.at(c.key)));
    std::map<std::string, nlohmann::json> judged;
    std::vector<std::string> changes;
    for (const auto& [name, run_of] : judged_runs) {
      judged[name] = conformance::expectation_outcomes(expectations.at(name), run_of);
      for (const nlohmann::json& change : judged[name]["changes"]) changes.push_back(change);
      for (const nlohmann::json& stale : judged[name]["unseen"])
        std::fprintf(stderr, "conform: %s lists %s, which this run did not have\n",
                     expectations.at(name).file().c_str(), stale.get<std::string>().c_str());
    }
    int expected_failures = 0;
    for (const Case& c : held) {
      nlohmann::json record = records.at(c.key);
      record.erase("table");
      const std::string verdict = record_verdict(record);
      if (judged.count(c.backend->name())) {
        record["expectation"] = judged[c.backend->name()]["cases"][c.key];
        expected_failures += !conformance::Expectations::change(record["expectation"]["outcome"]) &&
                             verdict != conformance::kVerdictPass && verdict != "skip" &&
                             verdict != conformance::kVerdictLimit;
      }
      if (verdict == "skip") {
        out["skipped"].push_back({{"backend", c.backend->name()},
                                  {"scene", c.scene->name},
                                  {"method", to_string(c.method)},
                                  {"reason", record["skipped"]},
                                  {"by_renderer", true}});
        if (record.contains("expectation"))
          out["skipped"].back()["expectation"] = record["expectation"];
        continue;
      }
      // A case its worker failed: the supervisor's record, named.
      if (!record.contains("backend")) {
        record["backend"] = c.backend->name();
        record["scene"] = c.scene->name;
        record["method"] = to_string(c.method);
      }
      out["cases"].push_back(std::move(record));
    }
    if (!expectations.empty()) out["changes"] = changes;
    if (!no_images.empty())
      out["unmeasured"] =
          nlohmann::json::array({{{"check", "image.perceptual_failpercent"}, {"why", no_images}}});
    write_json(o->json, out);
    journal->complete();
    std::printf("%d cases: %d pass, %d at their method's limit, %d failed%s; wrote %s\n", cases,
                cases - failed - limits - unfinished, limits, failed,
                unfinished ? (", " + std::to_string(unfinished) +
                              " did not finish (crash, timeout, out of memory or error)")
                                 .c_str()
                           : "",
                o->json.c_str());
    const auto case_skips =
        std::count_if(out["skipped"].begin(), out["skipped"].end(),
                      [](const nlohmann::json& s) { return s.contains("scene"); });
    if (case_skips > 0)
      std::printf("%d cases skipped (their renderer cannot render them; see \"skipped\" in %s)\n",
                  static_cast<int>(case_skips), o->json.c_str());
    if (!expectations.empty()) {
      std::printf("%zu changes against the expectation files%s\n", changes.size(),
                  changes.empty() ? "" : ":");
      for (const std::string& change : changes) std::printf("    %s\n", change.c_str());
    }
    if (!no_images.empty())
      say_left_out("conform",
                   o->error_images.empty() ? "Yee's perceptual check"
                                           : "Yee's perceptual check and the error images",
                   std::string(kPerceptualLeftOut) +
                       (o->error_images.empty()
                            ? ""
                            : "; `flatmarch conform --error-images DIR` on a machine with "
                              "OpenImageIO (ci/install-deps.sh installs it) draws the images"));
    if (!changes.empty())
      throw ConformanceFailure(std::to_string(changes.size()) +
                               " cases changed against their expectation files");
    if (failed + unfinished > expected_failures)
      throw ConformanceFailure(std::to_string(failed + unfinished - expected_failures) + " of " +
                               std::to_string(cases) + " cases failed or did not finish");
    if (limits && o->strict)
      throw ConformanceFailure(std::to_string(limits) + " of " + std::to_string(cases) +
                               " cases are at their method's limit (--strict)");
  });
}

}  // namespace flatmarch::cli
