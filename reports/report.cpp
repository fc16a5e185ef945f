#include "reports/report.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <optional>
#include <set>

#include "conformance/vocabulary.hpp"
#include "reports/fingerprint.hpp"
#include "reports/gallery.hpp"
#include "reports/shard.hpp"
#include "reports/supervise.hpp"
#include "scene/surfaces.hpp"

namespace flatmarch::reports {

using nlohmann::json;

namespace {

std::string now_utc() {
  const std::time_t t = std::time(nullptr);
  char s[32];
  std::strftime(s, sizeof s, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return s;
}

std::string number(double v) {
  char s[32];
  std::snprintf(s, sizeof s, "%g", v);
  return s;
}

}  // namespace

std::vector<std::string> first_of_each_surface_type(const std::vector<Scene>& scenes) {
  std::vector<std::string> chosen;
  std::set<std::string> types;
  for (const Scene& s : scenes)
    if (types.insert(surface_type(s)).second) chosen.push_back(s.name);
  return chosen;
}

std::vector<std::string> simplest_of_each_surface_type(const std::vector<Scene>& scenes) {
  std::vector<std::string> types;
  std::map<std::string, const Scene*> simplest;
  for (const Scene& s : scenes) {
    const std::string type = surface_type(s);
    auto [it, fresh] = simplest.emplace(type, &s);
    if (fresh) types.push_back(type);
    if (!fresh && edge_count(s) < edge_count(*it->second)) it->second = &s;
  }
  std::vector<std::string> chosen;
  for (const std::string& type : types) chosen.push_back(simplest[type]->name);
  return chosen;
}

namespace {

// The scenes the sweep runs on: every scene, or the first of each surface type.
std::vector<Scene> sweep_scenes(const std::vector<Scene>& scenes, const ReportOptions& o) {
  if (o.sweep_all_scenes) return scenes;
  const std::vector<std::string> first = first_of_each_surface_type(scenes);
  std::vector<Scene> chosen;
  for (const Scene& s : scenes)
    if (std::find(first.begin(), first.end(), s.name) != first.end()) chosen.push_back(s);
  return chosen;
}

}  // namespace

std::vector<std::pair<std::string, double>> report_cases(const std::vector<Scene>& scenes,
                                                         const ReportOptions& o,
                                                         const MatrixBackends* backends) {
  std::vector<std::pair<std::string, double>> cases = matrix_cases(scenes, o.matrix, backends);
  if (o.sweep_enabled)
    for (auto& c : sweep_cases(sweep_scenes(scenes, o), o.sweep)) cases.push_back(std::move(c));
  if (o.scaling_enabled)
    for (auto& c : scaling_cases(o.scaling)) cases.push_back(std::move(c));
  return cases;
}

json report_header(const std::vector<Scene>& scenes, const ReportOptions& o) {
  json results = {{"format", "flatmarch-report/1"}, {"created", now_utc()}};
  results["fingerprint"] = hardware_fingerprint();
  // The lists the page draws by (it restates none).
  json methods = json::array();
  for (Method m : kKernelMethods) methods.push_back(to_string(m));
  json machine = json::array();  // the page's machine table, as the backends describe it
  for (const auto& [label, text] : fingerprint_rows(results["fingerprint"]))
    machine.push_back({label, text});
  results["registry"] = {{"backends", kernel_backend_names()},
                         {"methods", methods},
                         {"surface_types", surface_types()},
                         {"fingerprint_rows", machine}};
  results["vocabulary"] = conformance::vocabulary_json();
  results["options"] = {
      {"size", std::to_string(o.matrix.width) + "x" + std::to_string(o.matrix.height)},
      {"conform_size",
       std::to_string(o.matrix.conform_width) + "x" + std::to_string(o.matrix.conform_height)},
      {"repetitions", o.matrix.repetitions},
      {"eps", o.matrix.params.eps},
      {"offset", o.matrix.params.offset},
      {"max_steps", o.matrix.params.max_steps},
      {"max_distance", o.matrix.params.max_distance},
      {"scenes", json::array()},
      {"methods", json::array()}};
  for (const Scene& s : scenes) results["options"]["scenes"].push_back(s.name);
  for (Method m : o.matrix.methods) results["options"]["methods"].push_back(to_string(m));
  return results;
}

json run_report_part(const std::vector<Scene>& scenes, const ReportOptions& o,
                     const std::function<bool(const std::string& key)>& holds,
                     const ReportSuites& suites, const ReportProgress& progress,
                     const MatrixBackends* backends, bool every_stage) {
  // Whether the part holds a case of a stage: a stage it holds none of is left out of it, but
  // for a shard's results (every_stage), whose every enabled stage is there, if empty.
  const auto holds_any = [&](const std::vector<std::pair<std::string, double>>& cases) {
    return every_stage || std::any_of(cases.begin(), cases.end(),
                                      [&](const auto& c) { return !holds || holds(c.first); });
  };
  auto started = std::chrono::steady_clock::now();
  // Seconds since the last call: the time each stage took.
  const auto lap = [&started] {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - started).count();
    started = now;
    return s;
  };
  json part = {{"seconds", json::object()}};
  MatrixOptions matrix = o.matrix;
  matrix.holds = holds;
  if (holds_any(matrix_cases(scenes, o.matrix, backends))) {
    part["matrix"] = run_matrix(
        scenes, matrix, suites.matrix,
        [&](const std::string& line, int done, int total) {
          if (progress) progress("matrix", line, done, total);
        },
        backends);
    part["seconds"]["matrix"] = lap();
  }
  const std::vector<Scene> swept = sweep_scenes(scenes, o);
  if (o.sweep_enabled && holds_any(sweep_cases(swept, o.sweep))) {
    SweepOptions sweep = o.sweep;
    sweep.holds = holds;
    part["sweep"] =
        run_sweep(swept, sweep, suites.sweep, [&](const std::string& line, int done, int total) {
          if (progress) progress("sweep", line, done, total);
        });
    part["seconds"]["sweep"] = lap();
  }
  if (o.scaling_enabled && holds_any(scaling_cases(o.scaling))) {
    ScalingOptions scaling = o.scaling;
    scaling.holds = holds;
    part["scaling"] = run_scaling(scaling, [&](const std::string& line, int done, int total) {
      if (progress) progress("scaling", line, done, total);
    });
    part["seconds"]["scaling"] = lap();
  }
  return part;
}

json unfinished_entry(const std::string& key, const json& record) {
  json entry = {{"key", key},
                {"stage", key.substr(0, key.find('/'))},
                {"verdict", record.value("verdict", conformance::kVerdictError)},
                {"error", unfinished_summary(record)}};
  for (const char* field :
       {"seconds", "signal_name", "exit_code", "deadline_seconds", "stderr_tail", "signal"})
    if (record.contains(field)) entry[field] = record[field];
  return entry;
}

json unfinished_part(const std::string& key, const json& record, const std::vector<Scene>& scenes,
                     const ReportOptions& o) {
  // matrix/BACKEND/METHOD/SCENE
  const size_t a = key.find('/'), b = key.find('/', a + 1), c = key.find('/', b + 1);
  if (key.compare(0, a, "matrix") != 0 || b == std::string::npos || c == std::string::npos)
    return nullptr;
  const std::string backend = key.substr(a + 1, b - a - 1), method = key.substr(b + 1, c - b - 1),
                    scene_name = key.substr(c + 1);
  const auto scene = std::find_if(scenes.begin(), scenes.end(),
                                  [&](const Scene& s) { return s.name == scene_name; });
  const std::optional<Method> m = parse_method(method);
  if (scene == scenes.end() || !m) return nullptr;
  json entry = {{"name", case_name(backend, *m, scene_name, o.matrix.width, o.matrix.height)},
                {"backend", backend},
                {"scene", scene_name},
                {"surface_type", surface_type(*scene)},
                {"method", method},
                {"width", o.matrix.width},
                {"height", o.matrix.height},
                {"verdict", record.value("verdict", conformance::kVerdictError)},
                {"error", unfinished_summary(record)}};
  return {{"matrix", {{"cases", json::array({entry})}}}};
}

void finish_report(json& results, const std::vector<Scene>& scenes, const ReportOptions& o) {
  const auto started = std::chrono::steady_clock::now();
  results["ranking"] = rank_backends(results["matrix"]);
  results["recommendation"] = recommend(results["ranking"], results.value("sweep", json::object()));
  if (!o.matrix.images.empty()) {
    draw_oracle_images(scenes, o.matrix, results["matrix"]);
    results["gallery"] = recommended_gallery(scenes, results["recommendation"],
                                             {.width = o.matrix.width,
                                              .height = o.matrix.height,
                                              .params = o.matrix.params,
                                              .backend_options = o.matrix.backend_options,
                                              .images = o.matrix.images});
  }
  results["seconds"]["gallery"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

json run_report(const std::vector<Scene>& scenes, const ReportOptions& options,
                const ReportProgress& progress) {
  ReportOptions o = options;
  json shard;
  std::function<bool(const std::string&)> holds;
  if (o.shard) {
    ShardPlan plan = plan_shard(*o.shard, report_cases(scenes, o));
    shard = std::move(plan.record);
    holds = plan.holds;
    if (progress) progress("shard", plan.summary, 0, 0);
  }
  json results = report_header(scenes, o);
  add_to_benchmark_context(results["fingerprint"]);
  conformance::Suite suite;
  results.update(
      run_report_part(scenes, o, holds, {suite, suite}, progress, nullptr, /*every_stage=*/true));
  if (o.shard) {
    if (!o.matrix.images.empty()) draw_oracle_images(scenes, o.matrix, results["matrix"]);
    results["shard"] = shard;
    return results;
  }
  finish_report(results, scenes, o);
  return results;
}

double lane_efficiency(const json& counters, double scalar_rays_per_s) {
  const double lanes = counters.value("lanes", 0.0);
  const double one = counters.value("one_thread_rays_per_s", counters.value("rays_per_s", 0.0));
  if (lanes <= 0.0 || scalar_rays_per_s <= 0.0 || one <= 0.0) return 0.0;
  return one / scalar_rays_per_s / lanes;
}

json rank_backends(const json& matrix) {
  struct Tally {
    int cases = 0, passed = 0, limits = 0, errors = 0;
    std::map<std::string, int> unfinished;  // errors that were crash, timeout or out_of_memory
    double log_rays = 0.0;
    int timed = 0;
    std::map<std::string, std::array<double, 4>> methods;  // cases, passed, log rays, timed
    // The SIMD backend's share of its peak (counter of_peak), per method: sum of logs, cases.
    std::map<std::string, std::array<double, 2>> of_peak;
    // And its lane efficiency (lane_efficiency()), per method: sum of logs, cases.
    std::map<std::string, std::array<double, 2>> efficiency;
    // A GPU backend's frames on its device's clock (counters device_ms, march_ms, readback_ms):
    // the cases timed so, the logs of their wall and device ms, and their shares of the wall
    // time summed (march, read-back, the rest).
    int device_timed = 0;
    double log_wall = 0.0, log_device = 0.0;
    std::array<double, 3> shares{};
  };
  std::map<std::string, Tally> tallies;
  std::map<std::string, json> devices;  // of the GPU backends
  // The scalar backend's rays a second by scene, method and size: what a lane efficiency is of.
  std::map<std::string, double> scalar;
  const auto key = [](const json& c) {
    return c.value("scene", "") + "/" + c.value("method", "") + "/" +
           std::to_string(c.value("width", 0)) + "x" + std::to_string(c.value("height", 0));
  };
  for (const json& c : matrix.value("cases", json::array()))
    if (c.value("backend", "") == "scalar" && !c.contains("error") && c.contains("counters"))
      scalar[key(c)] = c["counters"].value("rays_per_s", 0.0);
  std::vector<std::string> order;
  for (const json& c : matrix.value("cases", json::array())) {
    const std::string b = c["backend"];
    if (!tallies.count(b)) order.push_back(b);
    if (c.contains("device")) devices[b] = c["device"];
    Tally& t = tallies[b];
    auto& m = t.methods[c["method"].get<std::string>()];
    ++t.cases;
    m[0] += 1;
    if (c.contains("error")) {
      ++t.errors;
      // A supervised run's case that did not finish: counted by its verdict too.
      if (const std::string v = c.value("verdict", ""); is_supervision_verdict(v))
        ++t.unfinished[v];
      continue;
    }
    // A case at its method's limit (issue 22) is no pass: counted apart.
    const std::string verdict =
        c.contains("accuracy") ? c["accuracy"].value("verdict", c["accuracy"]["passed"].get<bool>()
                                                                    ? conformance::kVerdictPass
                                                                    : conformance::kVerdictFail)
                               : conformance::kVerdictPass;
    const bool passed = verdict == conformance::kVerdictPass;
    t.passed += passed;
    t.limits += verdict == conformance::kVerdictLimit;
    m[1] += passed;
    if (c.contains("counters") && c["counters"].value("rays_per_s", 0.0) > 0.0) {
      const double l = std::log(c["counters"]["rays_per_s"].get<double>());
      t.log_rays += l;
      ++t.timed;
      m[2] += l;
      m[3] += 1;
      const double wall = c.value("time_ms", 0.0), device = c["counters"].value("device_ms", 0.0);
      if (wall > 0.0 && device > 0.0) {
        ++t.device_timed;
        t.log_wall += std::log(wall);
        t.log_device += std::log(device);
        t.shares[0] += c["counters"].value("march_ms", 0.0) / wall;
        t.shares[1] += c["counters"].value("readback_ms", 0.0) / wall;
        t.shares[2] += std::max(0.0, wall - device) / wall;
      }
      if (const double p = c["counters"].value("of_peak", 0.0); p > 0.0) {
        auto& share = t.of_peak[c["method"].get<std::string>()];
        share[0] += std::log(p);
        share[1] += 1;
      }
      const auto s = scalar.find(key(c));
      if (const double e = lane_efficiency(c["counters"], s == scalar.end() ? 0.0 : s->second);
          e > 0.0) {
        auto& share = t.efficiency[c["method"].get<std::string>()];
        share[0] += std::log(e);
        share[1] += 1;
      }
    }
  }
  json ranking = json::array();
  for (const std::string& b : order) {
    const Tally& t = tallies[b];
    json methods = json::object();
    std::string best;
    double best_rays = 0.0;
    for (const auto& [name, m] : t.methods) {
      const double rays = m[3] > 0 ? std::exp(m[2] / m[3]) : 0.0;
      const bool conforms = m[1] == m[0];
      methods[name] = {
          {"cases", m[0]}, {"passed", m[1]}, {"rays_per_s", rays}, {"conforms", conforms}};
      if (const auto share = t.of_peak.find(name); share != t.of_peak.end())
        methods[name]["of_peak"] = std::exp(share->second[0] / share->second[1]);
      if (const auto share = t.efficiency.find(name); share != t.efficiency.end()) {
        methods[name]["lane_efficiency"] = std::exp(share->second[0] / share->second[1]);
        methods[name]["lane_efficiency_cases"] = share->second[1];
      }
      if (conforms && rays > best_rays) {
        best = name;
        best_rays = rays;
      }
    }
    ranking.push_back({{"backend", b},
                       {"cases", t.cases},
                       {"passed", t.passed},
                       {"limits", t.limits},
                       {"errors", t.errors},
                       {"unfinished", t.unfinished},
                       {"pass_rate", t.cases ? static_cast<double>(t.passed) / t.cases : 0.0},
                       {"rays_per_s", t.timed ? std::exp(t.log_rays / t.timed) : 0.0},
                       {"methods", methods},
                       {"best_method", best.empty() ? json(nullptr) : json(best)}});
    if (devices.count(b)) {
      ranking.back()["device"] = devices[b];
      ranking.back()["software"] = devices[b].value("software", false);
    }
    // Beside the wall time it is ranked by, what the device itself took (GPU backends).
    if (t.device_timed > 0) {
      const double n = t.device_timed;
      ranking.back()["device_time"] = {{"cases", t.device_timed},
                                       {"wall_ms", std::exp(t.log_wall / n)},
                                       {"device_ms", std::exp(t.log_device / n)},
                                       {"march_share", t.shares[0] / n},
                                       {"readback_share", t.shares[1] / n},
                                       {"rest_share", t.shares[2] / n}};
    }
  }
  // A backend measured on a sample of the scenes: its figures are of those scenes alone.
  for (const json& sample : matrix.value("sampled", json::array()))
    for (json& b : ranking)
      if (b["backend"] == sample["backend"])
        b["sampled"] = {{"cases", sample["cases"].size()},
                        {"of_cases", sample["of_cases"]},
                        {"why", sample["why"]}};
  std::stable_sort(ranking.begin(), ranking.end(), [](const json& a, const json& b) {
    const bool ca = a["passed"] == a["cases"], cb = b["passed"] == b["cases"];
    if (ca != cb) return ca;
    return a["rays_per_s"].get<double>() > b["rays_per_s"].get<double>();
  });
  for (size_t k = 0; k < ranking.size(); ++k) ranking[k]["rank"] = k + 1;
  return ranking;
}

json recommend(const json& ranking, const json& sweep) {
  json r = json::object();
  const json* top = nullptr;
  for (const json& b : ranking)
    if (!b["best_method"].is_null()) {
      top = &b;
      break;
    }
  if (!top) {
    r["backend"] = nullptr;
    r["why"] = "no backend passed every conformance case of any method here";
    return r;
  }
  r["backend"] = (*top)["backend"];
  r["method"] = (*top)["best_method"];
  r["rays_per_s"] = (*top)["methods"][(*top)["best_method"].get<std::string>()]["rays_per_s"];
  // Said as it is: when no backend passed every case (a case at its method's limit is no pass),
  // the choice is the fastest backend with a method that passed on every scene.
  r["why"] = (*top)["passed"] == (*top)["cases"]
                 ? "the fastest backend of those that passed every conformance case, with its "
                   "fastest method of those that passed on every scene"
                 : "no backend passed every conformance case (" +
                       (*top)["backend"].get<std::string>() + ": " +
                       std::to_string((*top)["passed"].get<int>()) + " of " +
                       std::to_string((*top)["cases"].get<int>()) + " pass, " +
                       std::to_string((*top).value("limits", 0)) +
                       " at their method's limit): the fastest backend with a method that passed "
                       "on every scene, and its fastest such method";
  const MarchParams defaults;
  json parameters = json::object();
  const json analysis = sweep.value("analysis", json::array());
  // The surface types the sweep measured; `select` gives the defaults for the others.
  for (const std::string& type : surface_types()) {
    if (std::none_of(analysis.begin(), analysis.end(),
                     [&](const json& g) { return g["surface_type"] == type; }))
      continue;
    // A fallback is marked as one: the defaults where the method has no stable point, or a
    // stable point none of whose eps neighbours is stable. With the defaults come the methods
    // that are stable on this surface type (f32, as the kernel backends march).
    json choice = {{"eps", defaults.eps},
                   {"offset", defaults.offset},
                   {"source", "defaults"},
                   {"fallback", true},
                   {"stable_methods", json::array()}};
    json stable_methods = json::array();
    for (const json& g : analysis) {
      if (g["surface_type"] != type || g["precision"] != "f32" || g["recommended"].is_null())
        continue;
      const json& rec = g["recommended"];
      if (g["method"] == r["method"])
        choice = {{"eps", rec["eps"]},
                  {"offset", rec["offset"]},
                  {"offset_label", rec["offset_label"]},
                  {"source", "sweep"},
                  {"fallback", rec.value("fallback", false)},
                  {"confirmed", rec.value("confirmed", json(nullptr))}};
      else
        stable_methods.push_back(
            {{"method", g["method"]}, {"eps", rec["eps"]}, {"offset", rec["offset"]}});
    }
    if (choice["source"] == "defaults") choice["stable_methods"] = stable_methods;
    parameters[type] = choice;
  }
  r["parameters"] = parameters;
  return r;
}

std::string describe_selection(const json& results, const std::string& type) {
  const json& rec = results.at("recommendation");
  std::string s = "measured " + results.value("created", std::string("?")) + " on " +
                  describe_machine(results.at("fingerprint")) + "\n";
  if (rec["backend"].is_null()) return s + "no choice: " + rec["why"].get<std::string>() + "\n";
  char line[256];
  std::snprintf(line, sizeof line, "backend %s, method %s: %.3g Mrays/s (%s)\n",
                rec["backend"].get<std::string>().c_str(), rec["method"].get<std::string>().c_str(),
                rec["rays_per_s"].get<double>() / 1e6, rec["why"].get<std::string>().c_str());
  s += line;
  const auto line_for = [&](const std::string& t, const json& p, const std::string& note) {
    return "  " + t + std::string(12 - std::min<size_t>(t.size(), 11), ' ') + "--backend " +
           rec["backend"].get<std::string>() + " --method " + rec["method"].get<std::string>() +
           " --eps " + number(p["eps"]) + " --offset " + number(p["offset"]) + note + "\n";
  };
  for (const auto& [t, p] : rec["parameters"].items()) {
    if (!type.empty() && t != type) continue;
    std::string note;
    if (p["source"] != "sweep") {
      note = "   (a fallback, the defaults: no point of the sweep passes on every " + t +
             " scene with this method";
      for (const json& m : p.value("stable_methods", json::array()))
        note += "; stable there: --method " + m["method"].get<std::string>() + " --eps " +
                number(m["eps"]) + " --offset " + number(m["offset"]);
      note += ")";
    } else if (p.value("fallback", false)) {
      note = "   (a fallback: no stable point of the sweep has stable eps neighbours)";
    }
    s += line_for(t, p, note);
  }
  if (!type.empty() && !rec["parameters"].contains(type)) {
    const MarchParams defaults;
    s += line_for(type, {{"eps", defaults.eps}, {"offset", defaults.offset}},
                  "   (defaults: no scene of this type was swept)");
  }
  s += "ranking:\n";
  for (const json& b : results.at("ranking")) {
    std::snprintf(line, sizeof line,
                  "  %zu. %-7s %8.3g Mrays/s  %d/%d cases pass, %d at their method's limit%s",
                  b["rank"].get<size_t>(), b["backend"].get<std::string>().c_str(),
                  b["rays_per_s"].get<double>() / 1e6, b["passed"].get<int>(),
                  b["cases"].get<int>(), b.value("limits", 0),
                  b["errors"].get<int>()
                      ? (", " + std::to_string(b["errors"].get<int>()) + " errors").c_str()
                      : "");
    s += line;
    // Of those errors, the cases that did not finish: "(1 crash, 1 timeout)".
    std::string ended;
    const json unfinished = b.value("unfinished", json::object());
    for (const auto& [verdict, n] : unfinished.items())
      ended += (ended.empty() ? "" : ", ") + std::to_string(n.get<int>()) + " " + verdict;
    if (!ended.empty()) s += " (" + ended + ")";
    if (b.contains("sampled"))
      s += " on a sample of " + std::to_string(b["sampled"]["cases"].get<int>()) + " of " +
           std::to_string(b["sampled"]["of_cases"].get<int>()) + " cases";
    if (b.contains("device"))
      s += "  on " + b["device"]["name"].get<std::string>() +
           (b["device"]["software"].get<bool>() ? " (software: a rasteriser on the CPU)" : "") +
           ", " + b["device"].value("driver", std::string("?"));
    if (b.contains("device_time")) {
      const json& d = b["device_time"];
      std::snprintf(line, sizeof line,
                    "; a frame %.3g ms, %.3g ms of it on the device (march %.0f%%, read-back "
                    "%.0f%%, the rest %.0f%%)",
                    d["wall_ms"].get<double>(), d["device_ms"].get<double>(),
                    100.0 * d["march_share"].get<double>(),
                    100.0 * d["readback_share"].get<double>(),
                    100.0 * d["rest_share"].get<double>());
      s += line;
    }
    s += "\n";
  }
  return s;
}

// --- The regression gate.

namespace {

// Figures of a case the gate holds, with their tolerance: worse is higher; a change beyond
// abs + rel * baseline counts.
struct Figure {
  const char* name;
  const char* source;  // "counters" or "accuracy"
  double abs, rel;
};
constexpr Figure kFigures[] = {
    {"steps_mean", "counters", 0.05, 0.02},     {"steps_p99", "counters", 1.0, 0.05},
    {"crossings_mean", "counters", 0.01, 0.02}, {"out_of_steps", "counters", 0.001, 0.0},
    {"hit_mismatch", "accuracy", 0.002, 0.0},   {"crossings_mismatch", "accuracy", 0.002, 0.0},
    {"image_fail", "accuracy", 0.005, 0.0},     {"traces_diverged", "accuracy", 0.0, 0.0}};

}  // namespace

json make_baseline(const json& results) {
  json tolerances = json::object();
  for (const Figure& f : kFigures) tolerances[f.name] = {{"abs", f.abs}, {"rel", f.rel}};
  json cases = json::object(), timings = json::object();
  for (const json& c : results.at("matrix").at("cases")) {
    if (c.contains("error")) continue;
    json figures = json::object();
    for (const Figure& f : kFigures)
      if (c.contains(f.source) && c[f.source].contains(f.name))
        figures[f.name] = c[f.source][f.name];
    if (c.contains("accuracy")) {
      figures["passed"] = c["accuracy"]["passed"];
      if (c["accuracy"].contains("verdict")) figures["verdict"] = c["accuracy"]["verdict"];
    }
    cases[c["name"].get<std::string>()] = figures;
    if (c.contains("time_samples_ms")) timings[c["name"].get<std::string>()] = c["time_samples_ms"];
  }
  return {{"format", "flatmarch-baseline/1"},
          {"created", results.value("created", "")},
          {"fingerprint", results.at("fingerprint")},
          {"options", results.at("options")},
          {"tolerances", tolerances},
          {"cases", cases},
          {"timings_ms", timings}};
}

std::string baseline_mismatch(const json& baseline, const json& results) {
  if (baseline.value("format", "") != "flatmarch-baseline/1") return "it is not a baseline file";
  for (const char* key : {"size", "conform_size", "eps", "offset", "max_steps"})
    if (baseline["options"][key] != results["options"][key])
      return "it was measured with " + std::string(key) + " " + baseline["options"][key].dump() +
             ", this run with " + results["options"][key].dump();
  return "";
}

double mann_whitney_p(const std::vector<double>& a, const std::vector<double>& b) {
  const size_t n1 = a.size(), n2 = b.size(), n = n1 + n2;
  if (n1 < 2 || n2 < 2) return 1.0;
  std::vector<std::pair<double, int>> all;
  for (double v : a) all.push_back({v, 0});
  for (double v : b) all.push_back({v, 1});
  std::sort(all.begin(), all.end());
  double rank_sum_a = 0.0, ties = 0.0;
  for (size_t i = 0; i < n;) {
    size_t j = i;
    while (j < n && all[j].first == all[i].first) ++j;
    const double rank = 0.5 * static_cast<double>(i + 1 + j);  // mean of ranks i+1 .. j
    for (size_t k = i; k < j; ++k)
      if (all[k].second == 0) rank_sum_a += rank;
    const double t = static_cast<double>(j - i);
    ties += t * t * t - t;
    i = j;
  }
  const double u1 = rank_sum_a - static_cast<double>(n1 * (n1 + 1)) / 2.0;
  const double u = std::max(u1, static_cast<double>(n1 * n2) - u1);
  const double mu = static_cast<double>(n1 * n2) / 2.0;
  const double nn = static_cast<double>(n);
  const double sigma =
      std::sqrt(static_cast<double>(n1 * n2) / 12.0 * ((nn + 1.0) - ties / (nn * (nn - 1.0))));
  if (sigma == 0.0) return 1.0;
  const double z = (u - mu - 0.5) / sigma;
  return std::min(1.0, std::erfc(z / std::sqrt(2.0)));
}

json check_baseline(const json& baseline, const json& results) {
  json out = {{"regressions", json::array()},
              {"improvements", json::array()},
              {"missing", json::array()},
              {"timing_warnings", json::array()},
              {"compared", 0}};
  std::map<std::string, const json*> now;
  for (const json& c : results.at("matrix").at("cases")) now[c["name"].get<std::string>()] = &c;
  const json& tolerances = baseline.at("tolerances");
  int compared = 0;
  for (const auto& [name, figures] : baseline.at("cases").items()) {
    const auto it = now.find(name);
    if (it == now.end()) {
      out["missing"].push_back(name);
      continue;
    }
    const json& c = *it->second;
    if (c.contains("error")) {
      // A case that crashed, overran its deadline or ran out of memory (a supervised run's
      // verdicts), or that could not run: a regression of a case that ran before.
      const std::string was =
          figures.value("verdict", figures.value("passed", false) ? conformance::kVerdictPass
                                                                  : conformance::kVerdictFail);
      if (c.contains("verdict"))
        out["regressions"].push_back({{"case", name},
                                      {"figure", "verdict"},
                                      {"was", was},
                                      {"now", c["verdict"]},
                                      {"error", c["error"]}});
      else
        out["regressions"].push_back(
            {{"case", name}, {"figure", "error"}, {"now", c["error"]}, {"was", "ran"}});
      continue;
    }
    ++compared;
    if (figures.value("passed", false) && c.contains("accuracy") &&
        !c["accuracy"]["passed"].get<bool>())
      out["regressions"].push_back({{"case", name},
                                    {"figure", "passed"},
                                    {"was", true},
                                    {"now", false},
                                    {"failed_checks", c["accuracy"]["failed_checks"]}});
    // A case at its method's limit that now fails outright is a regression too.
    if (figures.value("verdict", "") == conformance::kVerdictLimit && c.contains("accuracy") &&
        c["accuracy"].value("verdict", "") == conformance::kVerdictFail)
      out["regressions"].push_back({{"case", name},
                                    {"figure", "verdict"},
                                    {"was", conformance::kVerdictLimit},
                                    {"now", conformance::kVerdictFail},
                                    {"failed_checks", c["accuracy"]["failed_checks"]}});
    for (const Figure& f : kFigures) {
      if (!figures.contains(f.name) || !c.contains(f.source) || !c[f.source].contains(f.name))
        continue;
      const double was = figures[f.name], is = c[f.source][f.name];
      const json& tol = tolerances.at(f.name);
      const double allowed = tol["abs"].get<double>() + tol["rel"].get<double>() * std::abs(was);
      const json entry = {
          {"case", name}, {"figure", f.name}, {"was", was}, {"now", is}, {"tolerance", allowed}};
      if (is > was + allowed)
        out["regressions"].push_back(entry);
      else if (is < was - allowed)
        out["improvements"].push_back(entry);
    }
    const json& samples = baseline.value("timings_ms", json::object());
    if (samples.contains(name) && c.contains("time_samples_ms")) {
      const std::vector<double> a = samples[name], b = c["time_samples_ms"];
      std::vector<double> sa = a, sb = b;
      std::sort(sa.begin(), sa.end());
      std::sort(sb.begin(), sb.end());
      const double ratio = sb[sb.size() / 2] / sa[sa.size() / 2];
      const double p = mann_whitney_p(a, b);
      if (p < 0.05 && ratio > 1.1)
        out["timing_warnings"].push_back({{"case", name},
                                          {"ratio", ratio},
                                          {"p_value", p},
                                          {"was_ms", sa[sa.size() / 2]},
                                          {"now_ms", sb[sb.size() / 2]}});
    }
  }
  out["compared"] = compared;
  out["same_machine"] = baseline.at("fingerprint").value("cpu", json::object()) ==
                        results.at("fingerprint").value("cpu", json::object());
  return out;
}

namespace {
// printf into a string.
template <typename... Args>
std::string format(const char* pattern, Args... args) {
  const int n = std::snprintf(nullptr, 0, pattern, args...);
  std::string s(static_cast<size_t>(std::max(n, 0)) + 1, '\0');
  std::snprintf(s.data(), s.size(), pattern, args...);
  s.resize(static_cast<size_t>(std::max(n, 0)));
  return s;
}
}  // namespace

std::string describe_gate(const json& check, const json& baseline,
                          const std::string& baseline_file) {
  std::string out;
  for (const json& w : check["timing_warnings"])
    out += format("warning: %s is slower: %.3g ms against %.3g ms (x%.2f, Mann-Whitney p=%.3g)\n",
                  w["case"].get<std::string>().c_str(), w["now_ms"].get<double>(),
                  w["was_ms"].get<double>(), w["ratio"].get<double>(), w["p_value"].get<double>());
  if (!check["same_machine"].get<bool>() && !check["timing_warnings"].empty())
    out += format(
        "warning: the baseline's timings come from another CPU (%s): compare with "
        "care\n",
        reports::describe_machine(baseline["fingerprint"]).c_str());
  for (const json& m : check["missing"])
    out += format("warning: %s is in the baseline but was not measured\n",
                  m.get<std::string>().c_str());
  for (const json& i : check["improvements"])
    out += format("improved: %s %s %s -> %s (update the baseline: --write-baseline)\n",
                  i["case"].get<std::string>().c_str(), i["figure"].get<std::string>().c_str(),
                  i["was"].dump().c_str(), i["now"].dump().c_str());
  for (const json& g : check["regressions"])
    out +=
        format("REGRESSION: %s %s %s -> %s (tolerance %s)\n", g["case"].get<std::string>().c_str(),
               g["figure"].get<std::string>().c_str(), g["was"].dump().c_str(),
               g["now"].dump().c_str(), g.value("tolerance", json(0)).dump().c_str());
  out += format(
      "gate: %d cases compared with %s: %zu regressions, %zu improvements, %zu timing "
      "warnings, %zu missing\n",
      check["compared"].get<int>(), baseline_file.c_str(), check["regressions"].size(),
      check["improvements"].size(), check["timing_warnings"].size(), check["missing"].size());
  return out;
}

std::vector<std::string> report_part_keys(const json& part) {
  std::vector<std::string> keys;
  if (part.contains("matrix"))
    for (const json& c : part["matrix"].at("cases"))
      keys.push_back(matrix_case_key(c["backend"], c["method"], c["scene"]));
  if (part.contains("sweep"))
    for (const json& p : part["sweep"].at("points")) {
      std::string key = sweep_case_key(p["surface_type"], p["method"]);
      if (keys.empty() || keys.back() != key) keys.push_back(std::move(key));
    }
  if (part.contains("scaling"))
    for (const json& s : part["scaling"].at("series"))
      keys.push_back(scaling_case_key(s["family"], s["backend"], s["method"]));
  return keys;
}

json assemble_report(const json& header,
                     const std::vector<std::pair<std::string, const json*>>& parts,
                     const std::vector<std::string>& keys) {
  std::map<std::string, size_t> position;  // of each case in the run's list
  for (size_t k = 0; k < keys.size(); ++k) position[keys[k]] = k;
  std::map<std::string, json> matrix;  // case key -> case
  json benchmarks = json::array(), context = json::object(), scaling_benchmarks = json::array();
  json points = json::array(), confirmations = json::array(), series = json::array();
  json sweep_options, seconds = json::object();
  json matrix_skipped = json::array(), matrix_sampled, matrix_work_counter, scaling_skipped;
  bool matrix_seen = false;
  std::string sweep_from;
  for (const auto& [label, doc] : parts) {
    if (doc->contains("matrix")) {
      if (!matrix_seen) matrix_sampled = (*doc)["matrix"].value("sampled", json());
      // Each part's skips: whole backends unavailable (the same in every part), and the cases
      // an external renderer could not render (in their own part).
      for (const json& skip : (*doc)["matrix"].value("skipped", json::array()))
        if (std::find(matrix_skipped.begin(), matrix_skipped.end(), skip) == matrix_skipped.end())
          matrix_skipped.push_back(skip);
      if (matrix_work_counter.is_null())
        matrix_work_counter = (*doc)["matrix"].value("work_counter", json());
      matrix_seen = true;
      for (const json& c : (*doc)["matrix"].at("cases"))
        matrix[matrix_case_key(c["backend"], c["method"], c["scene"])] = c;
      const json& timed = (*doc)["matrix"].value("benchmarks", json::object());
      for (const json& run : timed.value("benchmarks", json::array())) benchmarks.push_back(run);
      if (context.empty()) context = timed.value("context", json::object());
    }
    if (doc->contains("sweep")) {
      const json& sweep = (*doc)["sweep"];
      if (sweep_options.is_null()) {
        sweep_options = sweep["options"];
        sweep_from = label;
      }
      if (sweep["options"] != sweep_options)
        throw std::invalid_argument(label + ": its sweep's options differ from " + sweep_from +
                                    "'s: not a part of the same run");
      for (const json& p : sweep["points"]) points.push_back(p);
      for (const json& k : sweep["confirmations"]) confirmations.push_back(k);
    }
    if (doc->contains("scaling")) {
      if (scaling_skipped.is_null()) scaling_skipped = (*doc)["scaling"]["skipped"];
      for (const json& s : (*doc)["scaling"]["series"]) series.push_back(s);
      const json& runs = (*doc)["scaling"].value("benchmarks", json::object());
      for (const json& run : runs.value("benchmarks", json::array()))
        scaling_benchmarks.push_back(run);
      if (context.empty()) context = runs.value("context", json::object());
    }
    const json stages = doc->value("seconds", json::object());
    for (const auto& [stage, s] : stages.items())
      seconds[stage] = seconds.value(stage, 0.0) + s.get<double>();
  }
  json out = {{"seconds", seconds}};
  out["matrix"] = {{"cases", json::array()},
                   {"skipped", matrix_skipped},
                   {"benchmarks", {{"context", context}, {"benchmarks", benchmarks}}}};
  if (!matrix_sampled.is_null()) out["matrix"]["sampled"] = matrix_sampled;
  if (!matrix_work_counter.is_null()) out["matrix"]["work_counter"] = matrix_work_counter;
  for (const std::string& key : keys)
    if (matrix.count(key)) out["matrix"]["cases"].push_back(matrix[key]);
  if (!sweep_options.is_null())
    out["sweep"] = merged_sweep(sweep_options, std::move(points), std::move(confirmations),
                                header["options"]["scenes"],
                                sweep_options.value("methods", header["registry"]["methods"]));
  if (!scaling_skipped.is_null()) {
    const auto at = [&](const json& s) {
      const auto it = position.find(scaling_case_key(s["family"], s["backend"], s["method"]));
      return it == position.end() ? keys.size() : it->second;
    };
    std::stable_sort(series.begin(), series.end(),
                     [&](const json& a, const json& b) { return at(a) < at(b); });
    out["scaling"] = {{"series", series},
                      {"skipped", scaling_skipped},
                      {"benchmarks", {{"context", context}, {"benchmarks", scaling_benchmarks}}}};
  }
  return out;
}

json merge_report(const std::vector<std::pair<std::string, json>>& files) {
  const std::vector<const std::pair<std::string, json>*> shards =
      check_shards(files, "flatmarch-report/1", "flatmarch report");
  const json& first = files.front().second;
  std::vector<std::string> keys;
  for (const json& key : first["shard"]["cases"]) keys.push_back(key.get<std::string>());
  std::vector<std::pair<std::string, const json*>> parts;
  json per_shard = json::array(), unfinished = json::array();
  for (const auto* entry : shards) {
    const auto& [file, doc] = *entry;
    ShardContents contents(file, doc["shard"]);
    for (const std::string& key : report_part_keys(doc)) contents.add(key);
    // A case its shard's worker did not finish is accounted for by its record.
    for (const json& u : doc.value("unfinished", json::array())) {
      contents.add(u.at("key").get<std::string>());
      unfinished.push_back(u);
    }
    contents.complete();
    parts.emplace_back(file, &doc);
    per_shard.push_back(
        {{"file", file},
         {"host", doc["fingerprint"].value("host", json(""))},
         {"seconds", doc.value("seconds", json::object())},
         {"expected_seconds", doc["shard"]["costs"][doc["shard"]["index"].get<size_t>() - 1]}});
  }
  json out = merged_header(files);
  out["created"] = now_utc();
  out["registry"] = first["registry"];
  out["vocabulary"] = first.value("vocabulary", conformance::vocabulary_json());
  out.update(assemble_report(first, parts, keys));
  out["shards"] = per_shard;
  out["unfinished"] = unfinished;
  out["ranking"] = rank_backends(out["matrix"]);
  out["recommendation"] = recommend(out["ranking"], out.value("sweep", json::object()));
  return out;
}

}  // namespace flatmarch::reports
