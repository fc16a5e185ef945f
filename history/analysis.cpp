#include "history/analysis.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "conformance/vocabulary.hpp"

namespace flatmarch::history {

using nlohmann::json;

namespace {

// Which way is worse for a deterministic number: +1 higher, -1 lower, 0 neither (crossings: a
// scene's rays cross as many edges as its geometry makes them).
int worse_direction(const std::string& figure) {
  for (const char* f :
       {"steps_mean", "hit_mismatch", "crossings_mismatch", "ambiguous", "steps_ks"})
    if (figure == f) return 1;
  for (const char* f : {"hit_rate", "crossings_rate"})
    if (figure == f) return -1;
  return 0;
}

// A verdict's place in the vocabulary's order (pass, limit, fail, error, then the unfinished).
int verdict_rank(const std::string& v) {
  int k = 0;
  for (const conformance::VerdictWord& w : conformance::verdict_words()) {
    if (v == w.name) return k;
    ++k;
  }
  return k;
}

json point_json(const Point& p, bool text) {
  json j = {{"run", p.run}, {"commit", p.commit}, {"created", p.created}};
  if (text)
    j["text"] = p.text;
  else
    j["value"] = p.value;
  if (p.repetitions > 1) {
    j["spread"] = p.spread;
    j["repetitions"] = p.repetitions;
  }
  return j;
}

}  // namespace

json analyse(const Database& db, const ChangeOptions& options) {
  json out = {{"runs", json::array()}, {"series", json::array()}, {"findings", json::array()}};
  for (const RunInfo& r : db.runs())
    out["runs"].push_back({{"id", r.id},
                           {"kind", r.kind},
                           {"commit", r.commit},
                           {"created", r.created},
                           {"machine", r.machine},
                           {"machine_text", r.machine_text},
                           {"page", r.page},
                           {"measurements", r.measurements}});
  for (const SeriesKey& key : db.series_keys()) {
    const std::vector<Point> points = db.series(key);
    const bool text = !points.empty() && !points.front().text.empty();
    json series = {
        {"case", key.case_name},   {"figure", key.figure},    {"judged", to_string(key.judged)},
        {"machine", key.machine},  {"build", key.build},      {"options", key.options},
        {"points", json::array()}, {"changes", json::array()}};
    for (const Point& p : points) series["points"].push_back(point_json(p, text));
    const auto finding = [&](size_t at, const char* kind) {
      return json{{"case", key.case_name},
                  {"figure", key.figure},
                  {"judged", to_string(key.judged)},
                  {"machine", key.machine},
                  {"kind", kind},
                  {"at", at},
                  {"run", points[at].run},
                  {"created", points[at].created},
                  {"commits", {points[at - 1].commit, points[at].commit}},
                  {"page", points[at].page}};
    };
    if (key.judged == Judged::kDeterministic) {
      std::vector<size_t> changed;
      if (text) {
        std::vector<std::string> texts;
        for (const Point& p : points) texts.push_back(p.text);
        changed = deterministic_changes(texts);
      } else {
        std::vector<double> values;
        for (const Point& p : points) values.push_back(p.value);
        changed = deterministic_changes(values);
      }
      for (size_t at : changed) {
        json f = finding(at, "deterministic");
        const Point &a = points[at - 1], &b = points[at];
        if (text) {
          f["before"] = a.text;
          f["after"] = b.text;
          f["worse"] = verdict_rank(b.text) > verdict_rank(a.text);
        } else {
          f["before"] = a.value;
          f["after"] = b.value;
          const int d = worse_direction(key.figure);
          f["worse"] = d != 0 && (b.value - a.value) * d > 0;
        }
        // A baseline commit: the gate's baseline changed with the figure, on purpose.
        f["accepted"] = !b.baseline.empty() && b.baseline != a.baseline;
        // Open: a regression not accepted that the newest run still shows.
        const Point& newest = points.back();
        const bool still = text ? newest.text == b.text : newest.value == b.value;
        f["open"] = f["worse"].get<bool>() && !f["accepted"].get<bool>() && still;
        series["changes"].push_back(f);
      }
    } else {
      std::vector<TimingSample> samples;
      for (const Point& p : points) samples.push_back({p.value, p.spread, p.repetitions});
      const std::vector<TimingChange> changes = timing_changes(samples, options);
      const double last = changes.empty() ? 0.0 : changes.back().after;
      for (const TimingChange& c : changes) {
        json f = finding(c.at, "timing");
        f["before"] = c.before;
        f["after"] = c.after;
        f["z"] = c.z;
        f["ratio"] = c.after / c.before;
        const bool slower =
            key.judged == Judged::kLowerIsBetter ? c.after > c.before : c.after < c.before;
        f["worse"] = slower;
        f["accepted"] = false;
        // Open: the series' last level is still worse than the level before this change.
        const double ratio = last / c.before;
        f["open"] =
            slower && (key.judged == Judged::kLowerIsBetter ? ratio > 1.0 + options.min_change
                                                            : ratio < 1.0 - options.min_change);
        series["changes"].push_back(f);
      }
    }
    for (const json& f : series["changes"]) out["findings"].push_back(f);
    out["series"].push_back(std::move(series));
  }
  std::stable_sort(
      out["findings"].begin(), out["findings"].end(), [](const json& a, const json& b) {
        if (a["open"] != b["open"]) return a["open"].get<bool>();
        return std::make_pair(a["created"].get<std::string>(), a["run"].get<int64_t>()) >
               std::make_pair(b["created"].get<std::string>(), b["run"].get<int64_t>());
      });
  return out;
}

json newest_changes(const json& analysed) {
  json out = {
      {"deterministic", json::array()}, {"accepted", json::array()}, {"timing", json::array()}};
  for (const json& s : analysed["series"]) {
    const size_t newest = s["points"].size() - 1;
    for (const json& f : s["changes"]) {
      if (f["kind"] == "timing") {
        if (f["open"].get<bool>()) out["timing"].push_back(f);
      } else if (f["at"].get<size_t>() == newest) {
        out[f["accepted"].get<bool>() ? "accepted" : "deterministic"].push_back(f);
      }
    }
  }
  return out;
}

}  // namespace flatmarch::history
