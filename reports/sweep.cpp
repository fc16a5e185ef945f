#include "reports/sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>

#include "conformance/vocabulary.hpp"
#include "reports/matrix.hpp"
#include "reports/shard.hpp"
#include "scene/surfaces.hpp"

namespace flatmarch::reports {

using nlohmann::json;

namespace {

std::string number(double v) {
  char s[32];
  std::snprintf(s, sizeof s, "%g", v);
  return s;
}

const char* precision_name(Precision p) {
  return p == Precision::f32 ? "f32" : "f64";
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// A point is stable on a scene when the conformance verdict there is `pass` (issue 22): a
// `limit` of the method is no pass, and no check is left out.
bool stable_point(const json& accuracy) {
  return accuracy["verdict"] == conformance::kVerdictPass;
}

const std::string kFailurePrefix = "failures.";

// A re-check's group, as the analysis orders them.
auto confirmation_group(const json& k) {
  return std::tie(k["surface_type"].get_ref<const std::string&>(),
                  k["method"].get_ref<const std::string&>(),
                  k["precision"].get_ref<const std::string&>());
}

void sort_confirmations(json& confirmations) {
  std::stable_sort(confirmations.begin(), confirmations.end(), [](const json& a, const json& b) {
    return confirmation_group(a) < confirmation_group(b);
  });
}

}  // namespace

std::vector<std::string> offset_labels(const SweepOptions& o) {
  std::vector<std::string> labels;
  for (double f : o.offset_factors) labels.push_back(number(f) + "xeps");
  for (double v : o.offset_fixed) labels.push_back(number(v));
  return labels;
}

std::string sweep_case_key(const std::string& surface_type, const std::string& method) {
  return "sweep/" + surface_type + "/" + method;
}

namespace {

// The precisions of `options` that its backend marches in (none for an unknown backend).
std::vector<Precision> sweep_precisions(const Backend& backend, const SweepOptions& o) {
  std::vector<Precision> precisions;
  const std::vector<Precision> has = backend.precisions();
  for (Precision p : o.precisions)
    if (std::find(has.begin(), has.end(), p) != has.end()) precisions.push_back(p);
  return precisions;
}

}  // namespace

std::vector<std::pair<std::string, double>> sweep_cases(const std::vector<Scene>& scenes,
                                                        const SweepOptions& o) {
  const std::unique_ptr<Backend> backend = make_backend(o.backend, o.backend_options);
  const size_t precisions = backend ? sweep_precisions(*backend, o).size() : 0;
  const size_t grid = o.eps.size() * (o.offset_factors.size() + o.offset_fixed.size());
  std::vector<std::string> types;
  for (const Scene& s : scenes)
    if (std::find(types.begin(), types.end(), surface_type(s)) == types.end())
      types.push_back(surface_type(s));
  std::vector<std::pair<std::string, double>> cases;
  for (const std::string& type : types)
    for (Method m : o.methods) {
      const std::string method = to_string(m);
      double cost = 0.0;
      for (const Scene& s : scenes) {
        if (surface_type(s) != type) continue;
        const int edges = edge_count(s);
        const double point = conformance_case_cost(o.backend, method, edges, o.width, o.height) +
                             (o.repetitions - 1) * frame_cost(o.backend, method, o.width, o.height);
        // Two rounds of re-checks at the larger size, as a rule.
        const double recheck = conformance_case_cost(
            o.backend, method, edges, o.width * o.confirm_scale, o.height * o.confirm_scale);
        cost += scene_cost_factor(s) * static_cast<double>(precisions) *
                (static_cast<double>(grid) * point + (o.confirm_scale > 1 ? 2.0 * recheck : 0.0));
      }
      cases.emplace_back(sweep_case_key(type, to_string(m)), cost);
    }
  return cases;
}

json run_sweep(const std::vector<Scene>& scenes, const SweepOptions& o, conformance::Suite& suite,
               const SweepProgress& progress) {
  const std::unique_ptr<Backend> backend = make_backend(o.backend, o.backend_options);
  if (!backend) throw std::invalid_argument("unknown backend \"" + o.backend + "\"");
  if (const Availability a = backend->availability(); !a.available)
    throw std::invalid_argument("the " + o.backend + " backend is unavailable here: " + a.reason);
  const std::vector<Precision> precisions = sweep_precisions(*backend, o);
  if (precisions.empty())
    throw std::invalid_argument("the " + o.backend +
                                " backend marches in none of the precisions asked for");
  // Every point is judged against one truth, masked as for the default parameters.
  suite.fix_mask(MarchParams{});
  const std::vector<std::string> labels = offset_labels(o);
  const auto held = [&](const Scene& scene, Method m) {
    return !o.holds || o.holds(sweep_case_key(surface_type(scene), to_string(m)));
  };
  int groups = 0;
  for (const Scene& scene : scenes)
    for (Method m : o.methods) groups += held(scene, m);
  const int total = static_cast<int>(groups * precisions.size() * o.eps.size() * labels.size());
  json points = json::array();
  int done = 0;
  for (const Scene& scene : scenes)
    for (Method m : o.methods) {
      if (!held(scene, m)) continue;
      // The grid's points (precision, eps, offset, in that order), their steps references
      // drawn first on every core (nothing is timed meanwhile), then each measured and timed.
      std::vector<MarchParams> grid;
      for (Precision p : precisions)
        for (double eps : o.eps)
          for (size_t k = 0; k < labels.size(); ++k) {
            MarchParams params = o.params;
            params.method = m;
            params.precision = p;
            params.eps = eps;
            params.offset = k < o.offset_factors.size()
                                ? o.offset_factors[k] * eps
                                : o.offset_fixed[k - o.offset_factors.size()];
            grid.push_back(params);
          }
      suite.prepare_references(scene, grid, o.width, o.height);
      for (size_t i = 0; i < grid.size(); ++i) {
        const MarchParams& params = grid[i];
        const Precision p = params.precision;
        const double eps = params.eps;
        const size_t k = i % labels.size();
        json point = {{"scene", scene.name},
                      {"surface_type", surface_type(scene)},
                      {"method", to_string(m)},
                      {"precision", precision_name(p)},
                      {"eps", eps},
                      {"offset", params.offset},
                      {"offset_label", labels[k]}};
        try {
          const conformance::CaseResult r = suite.run(*backend, scene, params, o.width, o.height);
          std::vector<double> ms = {1e3 * r.seconds};
          for (int rep = 1; rep < o.repetitions; ++rep) {
            const auto start = std::chrono::steady_clock::now();
            backend->render(scene, scene.camera, o.width, o.height, params, {});
            ms.push_back(
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count());
          }
          point["time_ms"] = median(ms);
          point["steps_mean"] = r.steps.mean;
          point["steps_p99"] = r.steps.p99;
          point["accuracy"] = accuracy_summary(r);
        } catch (const std::exception& e) {
          point["error"] = e.what();
        }
        points.push_back(std::move(point));
        if (progress)
          progress(scene.name + " " + to_string(m) + " " + precision_name(p) +
                       " eps=" + number(eps) + " offset=" + labels[k],
                   ++done, total);
      }
    }
  // Each recommended point again at confirm_scale times the frame size, on every scene of its
  // type: a point that passed only because the small frames missed a few failing rays drops
  // out, and the analysis picks again (a few rounds: each re-check removes one point).
  const int cw = o.width * o.confirm_scale, ch = o.height * o.confirm_scale;
  json confirmations = json::array();
  json analysis = analyse_sweep(points, confirmations);
  for (int round = 0; o.confirm_scale > 1 && round < 4; ++round) {
    bool again = false;
    for (const json& g : analysis) {
      const json& rec = g["recommended"];
      if (rec.is_null() || !rec["confirmed"].is_null()) continue;
      again = true;
      MarchParams params = o.params;
      params.method = *parse_method(g["method"]);
      params.precision = g["precision"] == "f32" ? Precision::f32 : Precision::f64;
      params.eps = rec["eps"];
      params.offset = rec["offset"];
      json k = {{"surface_type", g["surface_type"]},
                {"method", g["method"]},
                {"precision", g["precision"]},
                {"eps", rec["eps"]},
                {"offset_label", rec["offset_label"]},
                {"size", std::to_string(cw) + "x" + std::to_string(ch)},
                {"scenes", json::object()},
                {"passed", true}};
      for (const Scene& scene : scenes) {
        if (surface_type(scene) != g["surface_type"]) continue;
        json verdict;
        try {
          const json a = accuracy_summary(suite.run(*backend, scene, params, cw, ch));
          verdict = {{"verdict", a["verdict"]}, {"failed", a["failed"]}};
        } catch (const std::exception& e) {
          verdict = {{"verdict", conformance::kVerdictError}, {"error", e.what()}};
        }
        k["passed"] = k["passed"].get<bool>() && verdict["verdict"] == conformance::kVerdictPass;
        k["scenes"][scene.name] = verdict;
      }
      if (progress)
        progress("re-checked " + g["surface_type"].get<std::string>() + " " +
                     g["method"].get<std::string>() + " " + g["precision"].get<std::string>() +
                     " at " + k["size"].get<std::string>() +
                     (k["passed"].get<bool>() ? ": passes" : ": fails"),
                 done, total);
      confirmations.push_back(std::move(k));
    }
    if (!again) break;
    analysis = analyse_sweep(points, confirmations);
  }
  // By group, as the analysis: the order a shard's groups merge into (issue 24).
  sort_confirmations(confirmations);
  json options = {
      {"backend", o.backend},
      {"eps", o.eps},
      {"offset_labels", labels},
      {"size", std::to_string(o.width) + "x" + std::to_string(o.height)},
      {"confirm_size",
       o.confirm_scale > 1 ? json(std::to_string(cw) + "x" + std::to_string(ch)) : json(nullptr)},
      {"repetitions", o.repetitions},
      {"methods", json::array()},
      {"max_steps", o.params.max_steps},
      {"max_distance", o.params.max_distance}};
  for (Method m : o.methods) options["methods"].push_back(to_string(m));
  return {{"options", options},
          {"points", points},
          {"confirmations", confirmations},
          {"analysis", analysis}};
}

json merged_sweep(const json& options, json points, json confirmations, const json& scenes,
                  const json& methods) {
  const auto index_in = [](const json& names, const json& name) {
    return static_cast<size_t>(std::find(names.begin(), names.end(), name) - names.begin());
  };
  // A scene's points of a method are one group's, so one shard's, in the order made.
  std::stable_sort(points.begin(), points.end(), [&](const json& a, const json& b) {
    return std::pair(index_in(scenes, a["scene"]), index_in(methods, a["method"])) <
           std::pair(index_in(scenes, b["scene"]), index_in(methods, b["method"]));
  });
  sort_confirmations(confirmations);
  json analysis = analyse_sweep(points, confirmations);
  return {{"options", options},
          {"points", std::move(points)},
          {"confirmations", std::move(confirmations)},
          {"analysis", std::move(analysis)}};
}

json merge_sweep(const std::vector<std::pair<std::string, json>>& files) {
  const auto shards = check_shards(files, "flatmarch-sweep/1", "flatmarch sweep");
  json points = json::array(), confirmations = json::array(), unfinished = json::array();
  for (const auto* entry : shards) {
    const auto& [file, doc] = *entry;
    ShardContents contents(file, doc["shard"]);
    for (const json& p : doc.at("points")) {
      contents.add(sweep_case_key(p["surface_type"], p["method"]));
      points.push_back(p);
    }
    for (const json& k : doc.at("confirmations")) confirmations.push_back(k);
    // A group its shard's worker did not finish is accounted for by its record.
    for (const json& u : doc.value("unfinished", json::array())) {
      contents.add(u.at("key").get<std::string>());
      unfinished.push_back(u);
    }
    contents.complete();
  }
  const json& first = files.front().second;
  json out = merged_header(files);
  out.update(merged_sweep(first["options"], std::move(points), std::move(confirmations),
                          first["options"].value("scenes", json::array()),
                          first["options"].value("methods", json::array())));
  out["unfinished"] = unfinished;
  return out;
}

json analyse_sweep(const json& points, const json& confirmations) {
  // Grid points by group (surface type, method, precision) and position (eps, offset label).
  struct Cell {
    double eps = 0.0, offset = 0.0;
    std::string label;
    int scenes = 0, passed = 0, limits = 0, errors = 0;
    double time_ms = 0.0, steps_mean = 0.0, hit_mismatch = 0.0;
    int traces = 0, diverged = 0;
    long failures = 0;
    std::map<std::string, int> failed_checks;  // check -> scenes that fail it
    std::map<std::string, long> failure_rays;  // failure class -> rays, over the scenes
    const json* confirmation = nullptr;        // the re-check at a larger size, if any
    bool stable() const {
      return errors == 0 && passed == scenes &&
             (!confirmation || (*confirmation)["passed"].get<bool>());
    }
    // What made the cell unstable, in one word: the failure class whose threshold the most
    // scenes fail (ties: the most rays of it); else, when the hit, crossings or trace
    // agreement fails (which the classes' rays make up), the class with the most rays; else
    // the check the most scenes fail; else an error or a failed re-check; "" when stable.
    std::string cause() const {
      std::string best;
      std::tuple<bool, int, long> best_key{false, 0, 0};
      for (const auto& [check, n] : failed_checks) {
        const bool is_class = check.rfind(kFailurePrefix, 0) == 0;
        const auto rays =
            is_class ? failure_rays.find(check.substr(kFailurePrefix.size())) : failure_rays.end();
        const std::tuple<bool, int, long> key{is_class, n,
                                              rays == failure_rays.end() ? 0 : rays->second};
        if (best.empty() || key > best_key) {
          best = is_class ? check.substr(kFailurePrefix.size()) : check;
          best_key = key;
        }
      }
      if (!std::get<0>(best_key) &&
          (failed_checks.count("hit_rate") || failed_checks.count("crossings_rate") ||
           failed_checks.count("traces.diverged"))) {
        const auto most =
            std::max_element(failure_rays.begin(), failure_rays.end(),
                             [](const auto& x, const auto& y) { return x.second < y.second; });
        if (most != failure_rays.end() && most->second > 0) return most->first;
      }
      if (!best.empty()) return best;
      if (errors > 0) return "error";
      return stable() ? "" : "confirmation";
    }
  };
  struct Group {
    std::vector<double> eps;
    std::vector<std::string> labels;
    std::map<std::pair<double, std::string>, Cell> cells;
  };
  std::map<std::string, Group> groups;
  std::map<std::string, json> group_keys;
  for (const json& p : points) {
    const std::string key = p["surface_type"].get<std::string>() + "/" +
                            p["method"].get<std::string>() + "/" +
                            p["precision"].get<std::string>();
    group_keys[key] = {{"surface_type", p["surface_type"]},
                       {"method", p["method"]},
                       {"precision", p["precision"]}};
    Group& g = groups[key];
    const double eps = p["eps"];
    const std::string label = p["offset_label"];
    if (std::find(g.eps.begin(), g.eps.end(), eps) == g.eps.end()) g.eps.push_back(eps);
    if (std::find(g.labels.begin(), g.labels.end(), label) == g.labels.end())
      g.labels.push_back(label);
    Cell& c = g.cells[{eps, label}];
    c.eps = eps;
    c.offset = p["offset"];
    c.label = label;
    ++c.scenes;
    if (p.contains("error")) {
      ++c.errors;
      continue;
    }
    const json& a = p["accuracy"];
    c.passed += stable_point(a);
    c.limits += a["verdict"] == conformance::kVerdictLimit;
    for (const json& check : a["failed"]) ++c.failed_checks[check.get<std::string>()];
    for (const auto& [failure, n] : a["failures"].items()) c.failure_rays[failure] += n.get<long>();
    c.time_ms += p["time_ms"].get<double>();
    c.steps_mean += p["steps_mean"].get<double>();
    c.hit_mismatch += a["hit_mismatch"].get<double>();
    c.traces += a["traces"].get<int>();
    c.diverged += a["traces_diverged"].get<int>();
    c.failures += a["failures_total"].get<long>();
  }
  for (const json& k : confirmations) {
    const auto g =
        groups.find(k["surface_type"].get<std::string>() + "/" + k["method"].get<std::string>() +
                    "/" + k["precision"].get<std::string>());
    if (g == groups.end()) continue;
    const auto c = g->second.cells.find({k["eps"].get<double>(), k["offset_label"]});
    if (c != g->second.cells.end()) c->second.confirmation = &k;
  }
  json analysis = json::array();
  for (auto& [key, g] : groups) {
    json grid = json::array(), stable = json::array(), pareto = json::array();
    std::vector<const Cell*> ran;
    for (auto& [pos, c] : g.cells) {
      const int n = c.scenes - c.errors;
      if (n > 0) {
        c.time_ms /= n;
        c.steps_mean /= n;
        c.hit_mismatch /= n;
      }
      const bool is_stable = c.stable();
      grid.push_back({{"eps", c.eps},
                      {"offset", c.offset},
                      {"offset_label", c.label},
                      {"scenes", c.scenes},
                      {"passed", c.passed},
                      {"limits", c.limits},
                      {"errors", c.errors},
                      {"stable", is_stable},
                      {"cause", c.cause()},
                      {"failed_checks", c.failed_checks},
                      {"failures_by_class", c.failure_rays},
                      {"confirmation", c.confirmation ? *c.confirmation : json(nullptr)},
                      {"time_ms", c.time_ms},
                      {"steps_mean", c.steps_mean},
                      {"hit_mismatch", c.hit_mismatch},
                      {"traces", c.traces},
                      {"traces_diverged", c.diverged},
                      {"failures", c.failures}});
      if (is_stable) stable.push_back({{"eps", c.eps}, {"offset_label", c.label}});
      if (c.errors == 0) ran.push_back(&c);
    }
    // Pareto front: by time, each point more accurate than every faster one.
    std::sort(ran.begin(), ran.end(),
              [](const Cell* a, const Cell* b) { return a->time_ms < b->time_ms; });
    double best = 2.0;
    for (const Cell* c : ran)
      if (c->hit_mismatch < best) {
        best = c->hit_mismatch;
        pareto.push_back({{"eps", c->eps},
                          {"offset", c->offset},
                          {"offset_label", c->label},
                          {"time_ms", c->time_ms},
                          {"hit_mismatch", c->hit_mismatch}});
      }
    // Recommended: of the stable points whose eps neighbours (a decade either side, same
    // offset rule) are stable too, so that neither rounding nor a neighbouring choice tips
    // them (failing that, of all stable points), those within 10% of the fewest mean steps,
    // and of these the one with the most stable neighbours on the grid, then the one nearest
    // the defaults.
    std::sort(g.eps.begin(), g.eps.end());
    // g named in the capture: Clang 14 cannot capture a structured binding.
    const auto stable_at = [&g = g](long e, long k) {
      if (e < 0 || k < 0 || e >= static_cast<long>(g.eps.size()) ||
          k >= static_cast<long>(g.labels.size()))
        return false;
      const auto it =
          g.cells.find({g.eps[static_cast<size_t>(e)], g.labels[static_cast<size_t>(k)]});
      return it != g.cells.end() && it->second.stable();
    };
    struct Candidate {
      const Cell* cell;
      bool interior;
      int margin;  // stable neighbours of the 8 around it
      // |log10(eps / 1e-4)| + |log10(offset / 2e-4)|: among equals, the defaults'
      // neighbourhood (the analytic method, which pushes no point across an edge, ignores the
      // offset).
      double from_default;
    };
    std::vector<Candidate> candidates;
    for (long e = 0; e < static_cast<long>(g.eps.size()); ++e)
      for (long k = 0; k < static_cast<long>(g.labels.size()); ++k) {
        if (!stable_at(e, k)) continue;
        int margin = 0;
        for (long de = -1; de <= 1; ++de)
          for (long dk = -1; dk <= 1; ++dk) margin += (de || dk) && stable_at(e + de, k + dk);
        const Cell* c =
            &g.cells.at({g.eps[static_cast<size_t>(e)], g.labels[static_cast<size_t>(k)]});
        candidates.push_back({c, stable_at(e - 1, k) && stable_at(e + 1, k), margin,
                              std::abs(std::log10(c->eps / MarchParams{}.eps)) +
                                  std::abs(std::log10(c->offset / MarchParams{}.offset))});
      }
    const bool any_interior = std::any_of(candidates.begin(), candidates.end(),
                                          [](const Candidate& c) { return c.interior; });
    std::erase_if(candidates, [&](const Candidate& c) { return any_interior && !c.interior; });
    // Speed by the mean steps, which a frame's time follows on one backend and method, and
    // which, unlike the time, every run measures alike: the pick is the same on every run and
    // in every shard (issue 24).
    double fewest = std::numeric_limits<double>::infinity();
    for (const Candidate& c : candidates) fewest = std::min(fewest, c.cell->steps_mean);
    std::erase_if(candidates,
                  [&](const Candidate& c) { return c.cell->steps_mean > 1.1 * fewest; });
    const auto chosen = std::min_element(candidates.begin(), candidates.end(),
                                         [](const Candidate& a, const Candidate& b) {
                                           if (a.margin != b.margin) return a.margin > b.margin;
                                           return a.from_default < b.from_default;
                                         });
    const Cell* pick = chosen == candidates.end() ? nullptr : chosen->cell;
    const bool interior = any_interior;
    json group = group_keys[key];
    group["grid"] = grid;
    group["stable"] = stable;
    group["pareto"] = pareto;
    group["recommended"] =
        pick ? json{{"eps", pick->eps},
                    {"offset", pick->offset},
                    {"offset_label", pick->label},
                    {"time_ms", pick->time_ms},
                    {"hit_mismatch", pick->hit_mismatch},
                    // No stable point has stable eps neighbours: the pick may sit on an edge
                    // of the stable region.
                    {"fallback", !interior},
                    {"confirmed", pick->confirmation ? *pick->confirmation : json(nullptr)},
                    {"why", std::string(interior ? "of the stable points whose neighbours a "
                                                   "decade of eps either side are stable too"
                                                 : "of the stable points (none has stable "
                                                   "neighbours a decade of eps either side)") +
                                ", within 10% of the fewest mean steps, the one with the "
                                "most stable neighbours on the grid"}}
             : json(nullptr);
    analysis.push_back(group);
  }
  return analysis;
}

}  // namespace flatmarch::reports
