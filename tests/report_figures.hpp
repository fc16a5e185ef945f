// What two runs of `flatmarch report` that measure alike must agree on: every figure but the
// timings (and what is ranked by them).
#pragma once

#include <nlohmann/json.hpp>

namespace flatmarch::test {

using nlohmann::json;

// What a rerun measures alike: every field but the timings (and what is ranked by them).
inline json deterministic_report(const json& results) {
  json d;
  for (json c : results["matrix"]["cases"]) {
    c.erase("time_ms");
    c.erase("time_samples_ms");
    json counters;
    for (const char* k : {"steps_mean", "steps_p99", "crossings_mean", "out_of_steps"})
      counters[k] = c["counters"][k];
    c["counters"] = counters;
    d["matrix"].push_back(c);
  }
  d["skipped"] = results["matrix"]["skipped"];
  const json sweep = results.value("sweep", json::object());
  for (json p : sweep.value("points", json::array())) {
    p.erase("time_ms");
    d["points"].push_back(p);
  }
  d["confirmations"] = sweep.value("confirmations", json::array());
  for (json g : sweep.value("analysis", json::array())) {
    g.erase("pareto");
    for (json& cell : g["grid"]) cell.erase("time_ms");
    if (!g["recommended"].is_null()) g["recommended"].erase("time_ms");
    d["analysis"].push_back(g);
  }
  for (json s : results.value("scaling", json::object()).value("series", json::array())) {
    for (const char* k : {"time_ms", "slope", "lane_utilisation"}) s.erase(k);
    d["scaling"].push_back(s);
  }
  for (const json& b : results["ranking"])
    for (const char* k : {"cases", "passed", "limits", "errors"})
      d["ranking"][b["backend"].get<std::string>()][k] = b[k];
  // Which backend is recommended follows from speed where backends pass alike (the fastest
  // one), and a run's speeds are not its shards': compared apart (expect_fastest_recommended).
  d["recommendation"] = results["recommendation"];
  for (const char* k : {"rays_per_s", "backend", "why"}) d["recommendation"].erase(k);
  return d;
}

}  // namespace flatmarch::test
