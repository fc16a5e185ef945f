#include "reports/shard.hpp"
#include "backends/backend.hpp"
#include "scene/surfaces.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <numeric>
#include <set>
#include <stdexcept>

namespace flatmarch::reports {

using nlohmann::json;

std::optional<Shard> parse_shard(const std::string& text) {
  Shard s;
  char rest = 0;
  if (std::sscanf(text.c_str(), "%d/%d%c", &s.index, &s.count, &rest) != 2) return std::nullopt;
  if (s.count < 1 || s.count > 1000 || s.index < 1 || s.index > s.count) return std::nullopt;
  return s;
}

std::vector<int> assign_shards(const std::vector<double>& costs, int count) {
  if (count < 1) throw std::invalid_argument("assign_shards: no shards");
  std::vector<size_t> order(costs.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return costs[a] > costs[b]; });
  std::vector<double> load(static_cast<size_t>(count), 0.0);
  std::vector<int> shard(costs.size(), 1);
  for (const size_t k : order) {
    if (!std::isfinite(costs[k]) || costs[k] < 0.0)
      throw std::invalid_argument("assign_shards: a cost that is not finite and >= 0");
    const size_t least =
        static_cast<size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    load[least] += costs[k];
    shard[k] = static_cast<int>(least) + 1;
  }
  return shard;
}

namespace {

// The registry's cost of a backend (BackendEntry::cost); the default one for a backend it does
// not know (a test's, by the cost of the cheapest).
BackendCost cost_of(const std::string& backend) {
  const BackendEntry* entry = find_backend_entry(backend);
  return entry ? entry->cost : BackendCost{};
}

}  // namespace

double frame_cost(const std::string& backend, const std::string& method, int width, int height) {
  // Seconds a case took on this 2-core machine at 160x90 (conform's per-case seconds over the
  // gallery, 2026-11-26): the backend's BackendCost::frame_seconds, a tenth of it analytic.
  const double frame = static_cast<double>(width) * static_cast<double>(height) / 14400.0;
  const double marching = method == "analytic" ? 0.1 : 1.0;
  return cost_of(backend).frame_seconds * marching * frame;
}

double timed_case_cost(const std::string& backend, double frame_seconds, int repetitions,
                       double min_time) {
  double seconds = 2.0 * frame_seconds + repetitions * std::max(1.6 * min_time, frame_seconds);
  if (const BackendCost cost = cost_of(backend); cost.extra_timed_seconds)
    seconds += cost.extra_timed_seconds(frame_seconds, min_time);
  return seconds;
}

int edge_count(const Scene& scene) {
  int edges = 0;
  for (const Polygon& polygon : scene.polygons) edges += static_cast<int>(polygon.size());
  return edges;
}

double scene_cost_factor(const Scene& scene) {
  return surface_type(scene) == "prism" ? 5.0 : 1.0;
}

double oracle_case_cost(int edges, int width, int height) {
  // About 0.1 s at 160x90, more with more edges.
  const double frame = static_cast<double>(width) * static_cast<double>(height) / 14400.0;
  return 0.1 * frame * (1.0 + 0.02 * edges);
}

double conformance_case_cost(const std::string& backend, const std::string& method, int edges,
                             int width, int height) {
  // The oracle's share; then the backend's frames; a browser's page costs half a second more to
  // open and compile.
  return oracle_case_cost(edges, width, height) + cost_of(backend).startup_seconds +
         frame_cost(backend, method, width, height);
}

json shard_record(const Shard& shard, const std::vector<std::string>& cases,
                  const std::vector<int>& assignment, const std::vector<double>& costs) {
  std::vector<double> load(static_cast<size_t>(shard.count), 0.0);
  json holds = json::array();
  for (size_t k = 0; k < cases.size(); ++k) {
    load[static_cast<size_t>(assignment[k] - 1)] += costs[k];
    if (assignment[k] == shard.index) holds.push_back(cases[k]);
  }
  return {{"index", shard.index},
          {"count", shard.count},
          {"cases", cases},
          {"holds", holds},
          {"costs", load}};
}

ShardPlan plan_shard(const Shard& shard, const std::vector<std::pair<std::string, double>>& cases,
                     const std::string& noun) {
  std::vector<std::string> names;
  std::vector<double> costs;
  for (const auto& [name, cost] : cases) {
    names.push_back(name);
    costs.push_back(cost);
  }
  ShardPlan plan;
  plan.record = shard_record(shard, names, assign_shards(costs, shard.count), costs);
  const auto held = std::make_shared<std::set<std::string>>(plan.record["holds"].begin(),
                                                            plan.record["holds"].end());
  plan.holds = [held](const std::string& name) { return held->count(name) > 0; };
  const auto seconds = [](double s) {
    char text[32];
    std::snprintf(text, sizeof text, s < 10.0 ? "%.1f" : "%.0f", s);
    return std::string(text);
  };
  plan.summary = "shard " + shard.text() + " holds " + std::to_string(held->size()) +
                 " of the run's " + std::to_string(names.size()) + " " + noun + ", about " +
                 seconds(plan.record["costs"][static_cast<size_t>(shard.index - 1)]) +
                 " s here by their expected costs (each shard's:";
  // append(), not " " + std::string: GCC 12 at -O3 (the Release build) warns falsely on that.
  for (const json& c : plan.record["costs"])
    plan.summary.append(" ").append(seconds(c.get<double>()));
  plan.summary += " s)";
  return plan;
}

namespace {

[[noreturn]] void bad(const std::string& file, const std::string& why) {
  throw std::invalid_argument(file + ": " + why);
}

// What must be the same in every shard of one run, and how to say it differs.
void same(const std::string& file, const json& doc, const json& first,
          const std::string& first_file, const char* key, const std::string& what) {
  if (doc.value(key, json()) != first.value(key, json()))
    bad(file, what + " " + first_file + "'s: not a shard of the same run");
}

}  // namespace

ShardContents::ShardContents(std::string file, const json& shard)
    : file_(std::move(file)),
      holds_(shard.at("holds").begin(), shard.at("holds").end()),
      held_(holds_.begin(), holds_.end()) {}

void ShardContents::add(const std::string& key) {
  if (!held_.count(key)) bad(file_, "holds " + key + ", which is not its shard's");
  found_.insert(key);
}

void ShardContents::complete() const {
  for (const std::string& key : holds_)
    if (!found_.count(key))
      bad(file_, "has no results of " + key + ", which its shard holds (an interrupted run?)");
}

std::vector<const std::pair<std::string, json>*> check_shards(
    const std::vector<std::pair<std::string, json>>& files, const std::string& format,
    const std::string& command) {
  if (files.empty()) throw std::invalid_argument("nothing to merge");
  const auto& [first_file, first] = files.front();
  std::map<int, const std::pair<std::string, json>*> seen;  // shard index -> file
  for (const auto& entry : files) {
    const auto& [file, doc] = entry;
    if (!doc.is_object() || doc.value("format", "") != format)
      bad(file, "not the results of `" + command + "` (no \"format\": \"" + format + "\")");
    if (!doc.contains("shard")) bad(file, "holds no shard (run with --shard I/N)");
    if (doc["fingerprint"].value("build", json()) != first["fingerprint"].value("build", json()))
      bad(file, "made by another flatmarch build (" + doc["fingerprint"]["build"].dump() +
                    ") than " + first_file + " (" + first["fingerprint"]["build"].dump() + ")");
    // The same kind of machine: a job array runs on several nodes of a cluster, whose host names
    // alone differ.
    if (machine_of(doc) != machine_of(first))
      bad(file, "measured on another kind of machine than " + first_file +
                    " (its fingerprint differs beyond the host name)");
    same(file, doc, first, first_file, "options", "its parameters differ from");
    const json& s = doc["shard"];
    if (s["count"] != first["shard"]["count"])
      bad(file, "is a shard of " + s["count"].dump() + ", " + first_file + " of " +
                    first["shard"]["count"].dump());
    if (s["cases"] != first["shard"]["cases"])
      bad(file, "its run's case list differs from " + first_file + "'s");
    const int index = s["index"].get<int>();
    if (seen.count(index))
      bad(file, "shard " + std::to_string(index) + "/" + s["count"].dump() + " again (also " +
                    seen[index]->first + ")");
    seen[index] = &entry;
  }
  const int count = first["shard"]["count"].get<int>();
  std::vector<const std::pair<std::string, json>*> ordered;
  for (int k = 1; k <= count; ++k) {
    if (!seen.count(k))
      throw std::invalid_argument("shard " + std::to_string(k) + "/" + std::to_string(count) +
                                  " is missing (given " + std::to_string(files.size()) + " of " +
                                  std::to_string(count) + ")");
    ordered.push_back(seen[k]);
  }
  return ordered;
}

json machine_of(const json& results) {
  json machine = results.value("fingerprint", json::object());
  if (machine.is_object()) machine.erase("host");
  return machine;
}

json merged_header(const std::vector<std::pair<std::string, json>>& files) {
  const json& first = files.front().second;
  json out = {{"format", first["format"]},
              {"fingerprint", first["fingerprint"]},
              {"options", first["options"]},
              {"merged_from", json::array()},
              {"hosts", json::array()}};
  for (const auto& [file, doc] : files) {
    out["merged_from"].push_back(file);
    const json host = doc["fingerprint"].value("host", json(""));
    if (std::find(out["hosts"].begin(), out["hosts"].end(), host) == out["hosts"].end())
      out["hosts"].push_back(host);
  }
  return out;
}

json merge_conformance(const std::vector<std::pair<std::string, json>>& files) {
  check_shards(files, "flatmarch-conform/1", "flatmarch conform");
  std::map<std::string, json> cases;
  for (const auto& [file, doc] : files) {
    ShardContents contents(file, doc["shard"]);
    for (const json& c : doc["cases"]) {
      const std::string name = c["backend"].get<std::string>() + "/" +
                               c["method"].get<std::string>() + "/" + c["scene"].get<std::string>();
      contents.add(name);
      cases[name] = c;
    }
    contents.complete();
  }
  const json& first = files.front().second;
  json out = merged_header(files);
  out["cases"] = json::array();
  out["skipped"] = first.value("skipped", json::array());
  for (const json& name : first["shard"]["cases"]) out["cases"].push_back(cases.at(name));
  return out;
}

bool is_benchmark_shard(const json& doc) {
  return doc.is_object() && doc.contains("benchmarks") && doc.contains("context") &&
         doc["context"].is_object() && doc["context"].contains("flatmarch_shard");
}

json merge_benchmarks(const std::vector<std::pair<std::string, json>>& files) {
  // Each program's output in the form check_shards reads: its fingerprint from the context's
  // fingerprint/... entries, its options the program and its flags.
  std::vector<std::pair<std::string, json>> docs;
  for (const auto& [file, doc] : files) {
    if (!is_benchmark_shard(doc))
      bad(file, "not the --benchmark_out JSON of a benchmark program run with --shard=I/N");
    const json& context = doc["context"];
    json flat = json::object();
    for (const auto& [key, value] : context.items())
      if (key.rfind("fingerprint/", 0) == 0)
        flat[key.substr(std::string("fingerprint").size())] = value;  // from its "/"
    json shard = json::parse(context["flatmarch_shard"].get<std::string>(), nullptr, false);
    if (shard.is_discarded() || !shard.is_object()) bad(file, "its flatmarch_shard is not JSON");
    const std::string executable = context.value("executable", "");
    docs.emplace_back(file, json{{"format", "flatmarch-bench/1"},
                                 {"fingerprint", flat.empty() ? json::object() : flat.unflatten()},
                                 {"options",
                                  {{"program", executable.substr(executable.rfind('/') + 1)},
                                   {"flags", context.value("flatmarch_flags", "")}}},
                                 {"shard", shard}});
  }
  const auto shards = check_shards(docs, "flatmarch-bench/1", "a benchmark program");
  // Runs by the position of their benchmark in the run's list (Google Benchmark adds settings
  // to the registered name: "/repeats:3", "/manual_time", arguments).
  const json& list = docs.front().second["shard"]["cases"];
  const auto position = [&](const std::string& run_name) {
    size_t best = list.size(), length = 0;
    for (size_t k = 0; k < list.size(); ++k) {
      const std::string& name = list[k].get_ref<const std::string&>();
      if (name.size() >= length && run_name.rfind(name, 0) == 0 &&
          (run_name.size() == name.size() || run_name[name.size()] == '/')) {
        best = k;
        length = name.size();
      }
    }
    return best;
  };
  std::vector<std::pair<size_t, json>> runs;
  for (const auto* entry : shards) {
    const std::string& file = entry->first;
    const json& doc = files[static_cast<size_t>(entry - docs.data())].second;
    ShardContents contents(file, entry->second["shard"]);
    for (const json& run : doc["benchmarks"]) {
      const std::string name = run.value("run_name", run.value("name", "?"));
      const size_t k = position(name);
      contents.add(k == list.size() ? name : list[k].get<std::string>());
      runs.emplace_back(k, run);
    }
    contents.complete();
  }
  std::stable_sort(runs.begin(), runs.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  json out = {
      {"context", files[static_cast<size_t>(shards.front() - docs.data())].second["context"]},
      {"benchmarks", json::array()}};
  out["context"].erase("flatmarch_shard");
  std::string from;
  for (const auto& [file, doc] : files) from += (from.empty() ? "" : " ") + file;
  out["context"]["flatmarch_merged_from"] = from;
  for (auto& [k, run] : runs) out["benchmarks"].push_back(std::move(run));
  return out;
}

}  // namespace flatmarch::reports
