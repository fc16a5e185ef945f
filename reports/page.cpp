#include "reports/page.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <tuple>

#include "conformance/vocabulary.hpp"
#include "reports/fingerprint.hpp"
#include "reports/report.hpp"

namespace flatmarch::reports {

using nlohmann::json;
namespace vocab = conformance;

namespace {

// Appends `item` unless `list` has it: a list in order of first appearance.
void add_once(std::vector<std::string>& list, const std::string& item) {
  if (std::find(list.begin(), list.end(), item) == list.end()) list.push_back(item);
}

// The place of `item` in `list`, or its size where it is not there (after every item).
size_t index_in(const std::vector<std::string>& list, const std::string& item) {
  return static_cast<size_t>(std::find(list.begin(), list.end(), item) - list.begin());
}

// The matrix's cases of a results file (none where it has no matrix).
const json& cases_of(const json& results) {
  static const json none = json::array();
  const auto m = results.find("matrix");
  if (m == results.end() || !m->contains("cases")) return none;
  return (*m)["cases"];
}

// Whether doc[key] is there and would read as true in Python: not null, false, zero or empty.
bool truthy(const json& doc, const char* key) {
  const auto at = doc.find(key);
  if (at == doc.end() || at->is_null()) return false;
  if (at->is_boolean()) return at->get<bool>();
  if (at->is_number()) return at->get<double>() != 0.0;
  return !at->empty() && !(at->is_string() && at->get<std::string>().empty());
}

std::string text(const json& doc, const char* key) {
  const auto at = doc.find(key);
  return at != doc.end() && at->is_string() ? at->get<std::string>() : std::string();
}

// The registry's lists (backends, methods, surface types) of a results file; for one written
// before it had them, those its cases (and sweep) name, in order of appearance.
struct Lists {
  std::vector<std::string> backends, methods, types;
};

Lists registry_lists(const json& results) {
  Lists l;
  if (results.contains("registry")) {
    const json& r = results["registry"];
    l.backends = r.value("backends", std::vector<std::string>{});
    l.methods = r.value("methods", std::vector<std::string>{});
    l.types = r.value("surface_types", std::vector<std::string>{});
  }
  if (l.types.empty()) {
    for (const json& c : cases_of(results)) add_once(l.types, c.value("surface_type", ""));
    if (results.contains("sweep"))
      for (const json& g : results["sweep"].value("analysis", json::array()))
        add_once(l.types, g.value("surface_type", ""));
  }
  // Every case's backend and method: an external renderer, registered by the run alone, too.
  for (const json& c : cases_of(results)) {
    add_once(l.backends, c.value("backend", ""));
    add_once(l.methods, c.value("method", ""));
  }
  return l;
}

// The renderers we did not write (cases with "external"): per case, how many of its decided
// pixels end where the oracle's do and cross as they do, its colour's failing share, the failure
// classes it shows, its verdict and its time (its command's).
json external_table(const json& cases) {
  json rows = json::array();
  for (const json& c : cases) {
    if (!c.contains("external")) continue;
    const json& x = c["external"];
    const json a = c.value("accuracy", json::object());
    std::set<std::string> unmeasured;
    const json left_out = a.value("unmeasured", json::array());  // iterated: not a temporary
    for (const json& u : left_out) unmeasured.insert(u.value("check", ""));
    const auto share = [&](const char* check, const char* key) {
      return unmeasured.count(check) || !a.contains(key) ? json(nullptr)
                                                         : json(1.0 - a[key].get<double>());
    };
    json classes = json::object();
    const json failures = a.value("failures", json::object());  // iterated: not a temporary
    for (const auto& [name, n] : failures.items())
      if (n.get<double>() > 0) classes[name] = n;
    rows.push_back(
        {{"backend", c.value("backend", "")},
         {"version", x.value("version", "")},
         {"look", x.value("look", "")},
         {"scene", c.value("scene", "")},
         {"method", c.value("method", "")},
         {"verdict", a.value("verdict", c.contains("error") ? "error" : "")},
         {"error", c.value("error", "")},
         {"hit_right", share("hit_rate", "hit_mismatch")},
         {"crossings_right", share("crossings_rate", "crossings_mismatch")},
         {"ambiguous", a.value("ambiguous", 0.0)},
         {"colour_failing",
          unmeasured.count("image") || !a.contains("image_fail") ? json(nullptr) : a["image_fail"]},
         {"classes", classes},
         {"time_ms", c.value("time_ms", 0.0)},
         {"diff", c.value("diff", "")},
         {"time", x.value("time", "")}});
  }
  return rows;
}

std::vector<std::string> verdict_names() {
  std::vector<std::string> names;
  for (const vocab::VerdictWord& v : vocab::verdict_words()) names.emplace_back(v.name);
  return names;
}

// A failed check's line ("name value < limit") with what the check measures ("" where none).
json reason(const std::string& line) {
  const std::string name = line.substr(0, line.find(' '));
  const char* meaning = nullptr;
  for (const vocab::Word& w : vocab::check_words())
    if (name == w.name) meaning = w.meaning;
  if (!meaning) meaning = vocab::check_meaning(line);  // a check named per region, by prefix
  return {{"line", line}, {"meaning", meaning ? meaning : ""}};
}

json reasons(const json& lines) {
  json out = json::array();
  for (const json& l : lines) out.push_back(reason(l.get<std::string>()));
  return out;
}

// The verdicts counted, overall and per backend and method.
json summary_table(const json& cases, const std::vector<std::string>& verdicts,
                   const Lists& lists) {
  std::map<std::string, int> counts;
  std::vector<std::string> backends;
  std::map<std::string, std::map<std::string, std::map<std::string, int>>> per;
  for (const json& c : cases) {
    const std::string v = page_verdict(c);
    if (v.empty() || index_in(verdicts, v) == verdicts.size()) continue;
    ++counts[v];
    add_once(backends, c["backend"]);
    ++per[c["backend"]][c["method"]][v];
  }
  // The verdicts shown even at zero: those a run without a supervisor's trouble has.
  const auto always = [](const std::string& v) {
    return v != vocab::kVerdictError && !vocab::is_unfinished_verdict(v);
  };
  json shown = json::array(), meanings = json::array(), rows = json::array();
  int total = 0;
  for (const vocab::VerdictWord& w : vocab::verdict_words()) {
    const int n = counts[w.name];
    total += n;
    if (always(w.name) || n) shown.push_back({{"verdict", w.name}, {"n", n}});
    if (!w.unfinished || n) meanings.push_back({{"verdict", w.name}, {"meaning", w.meaning}});
  }
  for (const std::string& b : backends) {
    json cells = json::array();
    for (const std::string& m : lists.methods) {
      const auto at = per[b].find(m);
      if (at == per[b].end()) {
        cells.push_back(nullptr);
        continue;
      }
      json parts = json::array();
      bool bad = false;
      for (const std::string& v : verdicts) {
        const int n = at->second.count(v) ? at->second.at(v) : 0;
        if (n || always(v)) parts.push_back({{"n", n}, {"verdict", v}});
        bad = bad || (n && vocab::is_bad_verdict(v));
      }
      const bool limit = at->second.count(vocab::kVerdictLimit) > 0;
      cells.push_back({{"parts", parts}, {"cls", bad ? "bad" : limit ? "limit" : ""}});
    }
    rows.push_back({{"backend", b}, {"cells", cells}});
  }
  return {{"total", total}, {"shown", shown}, {"meanings", meanings}, {"rows", rows}};
}

// The ambiguous share per scene and method, as the first backend (in the registry's order) that
// measured the pair found it; others that found another share are named.
json ambiguity_table(const json& cases, const Lists& lists) {
  std::map<std::pair<std::string, std::string>, std::vector<std::pair<std::string, double>>> shares;
  std::vector<std::string> scenes;
  std::map<std::string, std::string> types;
  for (const json& c : cases) {
    add_once(scenes, c["scene"]);
    types[c["scene"]] = c.value("surface_type", "");
    if (c.contains("accuracy") && c["accuracy"].contains("ambiguous"))
      shares[{c["scene"], c["method"]}].emplace_back(c["backend"],
                                                     c["accuracy"]["ambiguous"].get<double>());
  }
  if (shares.empty()) return nullptr;
  for (auto& [key, got] : shares)
    std::stable_sort(got.begin(), got.end(), [&](const auto& a, const auto& b) {
      return index_in(lists.backends, a.first) < index_in(lists.backends, b.first);
    });
  std::vector<std::string> methods;
  for (const std::string& m : lists.methods)
    for (const auto& [key, got] : shares)
      if (key.second == m) add_once(methods, m);
  std::set<std::string> first_backends;
  json rows = json::array(), means = json::array();
  for (const std::string& s : scenes) {
    json cells = json::array();
    for (const std::string& m : methods) {
      const auto at = shares.find({s, m});
      if (at == shares.end()) {
        cells.push_back(nullptr);
        continue;
      }
      const auto& [backend, share] = at->second.front();
      first_backends.insert(backend);
      json others = json::array();
      for (size_t k = 1; k < at->second.size(); ++k)
        if (std::abs(at->second[k].second - share) > 1e-9)
          others.push_back({{"backend", at->second[k].first}, {"share", at->second[k].second}});
      double goal = -1.0;
      for (const vocab::AmbiguityGoal& g : vocab::ambiguity_goals())
        if (m == g.method) goal = types[s] == "prism" ? g.prism : g.other;
      cells.push_back(
          {{"share", share}, {"others", others}, {"over_goal", goal >= 0.0 && share > goal}});
    }
    rows.push_back({{"scene", s}, {"surface_type", types[s]}, {"cells", cells}});
  }
  for (const std::string& m : methods) {
    double sum = 0.0;
    int n = 0;
    for (const std::string& s : scenes)
      if (const auto at = shares.find({s, m}); at != shares.end()) {
        sum += at->second.front().second;
        ++n;
      }
    means.push_back(n ? json(sum / n) : json(nullptr));
  }
  return {
      {"first_backends", first_backends}, {"methods", methods}, {"rows", rows}, {"means", means}};
}

// The gallery per backend: the verdict of each scene's case of the first method measured (whose
// frames the matrix keeps), per backend of the ranking.
json gallery_table(const json& results) {
  const json& cases = cases_of(results);
  const std::string method = cases.empty() ? "?" : cases[0].value("method", "?");
  std::vector<std::string> backends = {"oracle"};
  for (const json& b : results.value("ranking", json::array())) backends.push_back(b["backend"]);
  std::map<std::pair<std::string, std::string>, std::string> verdicts;
  for (const json& c : cases)
    if (c.value("method", "") == method) verdicts[{c["backend"], c["scene"]}] = page_verdict(c);
  json rows = json::array();
  for (const json& s : results["options"].value("scenes", json::array())) {
    json row = json::array();
    for (const std::string& b : backends) {
      const auto at = verdicts.find({b, s.get<std::string>()});
      row.push_back(at == verdicts.end() || at->second.empty() ? json(nullptr) : json(at->second));
    }
    rows.push_back({{"scene", s}, {"verdicts", row}});
  }
  return {{"method", method}, {"backends", backends}, {"rows", rows}};
}

// The recommended gallery's scenes: their pixels decided, the share of those that differ, and
// each class's share of all pixels.
json recommended_table(const json& results) {
  json out = json::array();
  // None where no backend is recommended: the gallery is null then.
  if (!results.contains("gallery") || !results["gallery"].is_object()) return out;
  for (const json& sc : results["gallery"].value("scenes", json::array())) {
    if (sc.contains("error")) {
      out.push_back({{"scene", sc["scene"]}, {"error", sc["error"]}});
      continue;
    }
    const json& counts = sc["counts"];
    const int pixels = sc["pixels"];
    const int decided = pixels - counts.value("ambiguous", 0);
    const int wrong = decided - counts.value("agree", 0);
    json differ = json::array();
    for (const auto& [name, n] : counts.items())
      if (n.get<int>() && name != "agree")
        differ.push_back({{"class", name}, {"share", double(n.get<int>()) / pixels}});
    out.push_back({{"scene", sc["scene"]},
                   {"wrong_share", decided ? json(double(wrong) / decided) : json(nullptr)},
                   {"differ", differ},
                   {"pixels", pixels}});
  }
  return out;
}

// Per backend and method, the cases of each verdict and the rays of each failure class; then the
// cases that did not pass, those whose verdict and reasons read alike (the same scene and method
// on several backends) in one group.
json failures_table(const json& cases) {
  struct Totals {
    int cases = 0, pass = 0, limit = 0, bad = 0;
    std::map<std::string, int> failures;
  };
  std::map<std::pair<std::string, std::string>, Totals> totals;
  for (const json& c : cases) {
    Totals& t = totals[{c["backend"], c["method"]}];
    ++t.cases;
    const std::string v = page_verdict(c);
    if (v.empty()) continue;
    t.pass += v == vocab::kVerdictPass;
    t.limit += v == vocab::kVerdictLimit;
    t.bad += vocab::is_bad_verdict(v);
    if (c.contains("accuracy") && c["accuracy"].contains("failures"))
      for (const vocab::PixelClassWord& f : vocab::failure_words())
        t.failures[f.name] += c["accuracy"]["failures"].value(f.name, 0);
  }
  json rows = json::array();
  for (const auto& [key, t] : totals) {
    json failures = json::array();
    for (const vocab::PixelClassWord& f : vocab::failure_words())
      failures.push_back(t.failures.count(f.name) ? t.failures.at(f.name) : 0);
    rows.push_back({{"backend", key.first},
                    {"method", key.second},
                    {"cases", t.cases},
                    {"pass", t.pass},
                    {"limit", t.limit},
                    {"bad", t.bad},
                    {"failures", failures}});
  }
  // Bad verdicts first, then those at their limit; by scene, method and backend.
  std::vector<const json*> shown;
  for (const json& c : cases) {
    const std::string v = page_verdict(c);
    if (vocab::is_bad_verdict(v) || v == vocab::kVerdictLimit) shown.push_back(&c);
  }
  std::stable_sort(shown.begin(), shown.end(), [](const json* a, const json* b) {
    const auto key = [](const json* c) {
      return std::make_tuple(page_verdict(*c) == vocab::kVerdictLimit,
                             (*c)["scene"].get<std::string>(), (*c)["method"].get<std::string>(),
                             (*c)["backend"].get<std::string>());
    };
    return key(a) < key(b);
  });
  json groups = json::array();
  for (const json* c : shown) {
    const std::string v = page_verdict(*c);
    json why;
    if (v == vocab::kVerdictError || vocab::is_unfinished_verdict(v)) {
      why = {{"error", c->value("error", "")}, {"checks", json::array()}};
    } else {
      const json& a = (*c)["accuracy"];
      why = {{"checks", reasons(a.value("failed_checks", json::array()))}};
      if (v == vocab::kVerdictLimit) why["limit"] = a.value("limit", "");
    }
    why["scene"] = (*c)["scene"];
    why["method"] = (*c)["method"];
    why["verdict"] = v;
    const auto alike =
        std::find_if(groups.begin(), groups.end(), [&](const json& g) { return g["why"] == why; });
    json& group = alike != groups.end()
                      ? *alike
                      : groups.emplace_back(json{
                            {"why", why}, {"cases", json::array()}, {"backends", json::array()}});
    group["cases"].push_back((*c)["name"]);
    group["backends"].push_back((*c)["backend"]);
  }
  json out = json::array();
  for (json& g : groups) {
    json row = g["why"];
    const std::string first = g["cases"][0];
    row["size"] = first.substr(first.rfind('/') + 1);
    row["cases"] = g["cases"];
    row["backends"] = g["backends"];
    out.push_back(row);
  }
  return {{"totals", rows}, {"cases", out}};
}

// The SIMD backend's lanes per scene and method: busy, of this CPU's peak, and its lane
// efficiency where the scalar backend measured the same scene and method.
json lanes_table(const json& cases, const Lists& lists) {
  std::map<std::pair<std::string, std::string>, json> simd;
  std::map<std::pair<std::string, std::string>, double> scalar;
  std::set<std::string> scenes;
  for (const json& c : cases) {
    scenes.insert(c["scene"]);
    if (!c.contains("counters")) continue;
    if (c["counters"].contains("lane_utilisation")) simd[{c["scene"], c["method"]}] = c["counters"];
    if (c.value("backend", "") == "scalar")
      scalar[{c["scene"], c["method"]}] = c["counters"].value("rays_per_s", 0.0);
  }
  if (simd.empty()) return nullptr;
  std::vector<std::string> methods;
  for (const std::string& m : lists.methods)
    for (const auto& [key, counters] : simd)
      if (key.second == m) add_once(methods, m);
  json rows = json::array();
  for (const std::string& s : scenes) {
    json cells = json::array();
    for (const std::string& m : methods) {
      const auto at = simd.find({s, m});
      if (at == simd.end()) {
        cells.push_back(nullptr);
        continue;
      }
      const json& counters = at->second;
      json cell = {{"busy", counters["lane_utilisation"]}};
      if (counters.contains("of_peak")) cell["of_peak"] = counters["of_peak"];
      const auto base = scalar.find({s, m});
      const double e = lane_efficiency(counters, base == scalar.end() ? 0.0 : base->second);
      if (e > 0.0) {
        cell["efficiency"] = e;
        cell["lanes"] = static_cast<int>(counters.value("lanes", 0.0));
      }
      cells.push_back(cell);
    }
    rows.push_back({{"scene", s}, {"cells", cells}});
  }
  return {{"methods", methods}, {"rows", rows}};
}

// The change per case (backend, method, scene) since an earlier run: verdicts that changed,
// worse first, then the figures that moved beyond their bounds, largest hit change first.
json previous_table(const json& results, const json& previous,
                    const std::vector<std::string>& verdicts) {
  using Key = std::tuple<std::string, std::string, std::string>;
  const auto key = [](const json& c) -> Key { return {c["backend"], c["method"], c["scene"]}; };
  std::map<Key, const json*> now, was;
  std::vector<Key> order;
  for (const json& c : cases_of(results)) {
    if (!now.count(key(c))) order.push_back(key(c));
    now[key(c)] = &c;
  }
  for (const json& c : cases_of(previous)) was[key(c)] = &c;
  std::vector<Key> common;
  for (const Key& k : order)
    if (was.count(k)) common.push_back(k);
  // Worse the later in the vocabulary's order; a case not judged before all.
  const auto rank = [&](const std::string& v) {
    return v.empty() ? -1 : static_cast<int>(index_in(verdicts, v));
  };
  std::vector<std::tuple<Key, std::string, std::string>> changed;
  for (const Key& k : common) {
    const std::string before = page_verdict(*was[k]), after = page_verdict(*now[k]);
    if (before != after) changed.emplace_back(k, before, after);
  }
  std::stable_sort(changed.begin(), changed.end(), [&](const auto& a, const auto& b) {
    return std::make_pair(rank(std::get<1>(a)) >= rank(std::get<2>(a)), std::get<0>(a)) <
           std::make_pair(rank(std::get<1>(b)) >= rank(std::get<2>(b)), std::get<0>(b));
  });
  json verdict_rows = json::array();
  for (const auto& [k, before, after] : changed) {
    const json& c = *now[k];
    const json lines = c.contains("accuracy") ? c["accuracy"].value("failed_checks", json::array())
                                              : json::array();
    verdict_rows.push_back({{"case", c["name"]},
                            {"before", before.empty() ? "not judged" : before},
                            {"now", after.empty() ? "not judged" : after},
                            {"worse", rank(after) > rank(before)},
                            {"checks", reasons(lines)},
                            {"error", c.value("error", "")}});
  }
  struct Moved {
    std::string name;
    std::optional<double> hit, ambiguous, speed;
  };
  std::vector<Moved> moved;
  for (const Key& k : common) {
    const json &a = *was[k], &b = *now[k];
    Moved m{b["name"], {}, {}, {}};
    if (truthy(a, "accuracy") && truthy(b, "accuracy")) {
      m.hit =
          b["accuracy"]["hit_mismatch"].get<double>() - a["accuracy"]["hit_mismatch"].get<double>();
      m.ambiguous = b["accuracy"].value("ambiguous", 0.0) - a["accuracy"].value("ambiguous", 0.0);
    }
    const double ra = a.contains("counters") ? a["counters"].value("rays_per_s", 0.0) : 0.0;
    const double rb = b.contains("counters") ? b["counters"].value("rays_per_s", 0.0) : 0.0;
    if (ra != 0.0 && rb != 0.0) m.speed = rb / ra;
    if ((m.hit && std::abs(*m.hit) > 1e-4) || (m.ambiguous && std::abs(*m.ambiguous) > 1e-4) ||
        (m.speed && !(0.9 <= *m.speed && *m.speed <= 1.1)))
      moved.push_back(m);
  }
  std::stable_sort(moved.begin(), moved.end(), [](const Moved& a, const Moved& b) {
    const auto size_of = [](const Moved& m) {
      return std::make_tuple(-std::abs(m.hit.value_or(0.0)), -std::abs(m.ambiguous.value_or(0.0)),
                             m.speed ? -std::abs(std::log(*m.speed)) : 0.0);
    };
    return size_of(a) < size_of(b);
  });
  const auto opt = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
  json figure_rows = json::array();
  for (const Moved& m : moved)
    figure_rows.push_back({{"case", m.name},
                           {"hit", opt(m.hit)},
                           {"ambiguous", opt(m.ambiguous)},
                           {"speed", opt(m.speed)}});
  const auto sizes = [](const json& r) {
    const json o = r.value("options", json::object());
    return json::array({o.value("size", json(nullptr)), o.value("conform_size", json(nullptr))});
  };
  const json cpu_now = results.value("fingerprint", json::object()).value("cpu", json(nullptr));
  const json cpu_was = previous.value("fingerprint", json::object()).value("cpu", json(nullptr));
  return {{"common", common.size()},
          {"new", now.size() - common.size()},
          {"gone", was.size() - common.size()},
          {"sizes", json::array({sizes(previous), sizes(results)})},
          {"same_cpu", cpu_now == cpu_was},
          {"verdicts", verdict_rows},
          {"figures", figure_rows}};
}

// The sweep's tables: the codes of the causes its unstable points show, per surface type its
// scenes, and per group the recommended point, or why none is stable and what to use instead.
json sweep_tables(const json& sweep, const Lists& lists) {
  const json analysis = sweep.value("analysis", json::array());
  if (analysis.empty()) return nullptr;
  // The causes with a code, in the vocabulary's order: the failure classes, the checks, the rest.
  std::vector<std::pair<std::string, std::string>> causes;  // name, code
  std::map<std::string, std::string> meanings;
  for (const vocab::PixelClassWord& w : vocab::failure_words()) {
    if (*w.code) causes.emplace_back(w.name, w.code);
    meanings[w.name] = w.meaning;
  }
  for (const auto& words : {vocab::check_words(), vocab::other_cause_words()})
    for (const vocab::Word& w : words) {
      if (*w.code) causes.emplace_back(w.name, w.code);
      meanings[w.name] = w.meaning;
    }
  const auto code_of = [&](const std::string& cause) {
    for (const auto& [name, code] : causes)
      if (name == cause) return code;
    return cause.substr(0, 3);
  };
  const auto place = [&](const std::string& cause) {
    size_t k = 0;
    while (k < causes.size() && causes[k].first != cause) ++k;
    return k;
  };
  std::set<std::string> unstable_causes;
  for (const json& g : analysis)
    for (const json& c : g["grid"])
      if (!c.value("stable", false) && !text(c, "cause").empty())
        unstable_causes.insert(c["cause"]);
  std::vector<std::string> shown(unstable_causes.begin(), unstable_causes.end());
  std::stable_sort(shown.begin(), shown.end(),
                   [&](const std::string& a, const std::string& b) { return place(a) < place(b); });
  json legend = json::array(), codes = json::object();
  for (const std::string& k : shown)
    legend.push_back({{"code", code_of(k)}, {"cause", k}, {"meaning", meanings[k]}});
  for (const json& g : analysis)
    for (const json& c : g["grid"])
      if (!text(c, "cause").empty()) codes[c["cause"].get<std::string>()] = code_of(c["cause"]);

  json types = json::array(), recommendations = json::array(), no_stable = json::array();
  for (const std::string& t : lists.types) {
    std::vector<const json*> groups;
    for (const json& g : analysis)
      if (g.value("surface_type", "") == t) groups.push_back(&g);
    if (groups.empty()) continue;
    std::set<std::string> scenes;
    for (const json& p : sweep.value("points", json::array()))
      if (p.value("surface_type", "") == t) scenes.insert(p["scene"]);
    types.push_back({{"type", t}, {"scenes", scenes}});
    std::map<std::string, std::vector<std::string>> stable_methods;  // by precision
    for (const json* g : groups)
      if (g->contains("recommended") && !(*g)["recommended"].is_null())
        stable_methods[(*g)["precision"]].push_back((*g)["method"]);
    for (const json* g : groups) {
      json row = {{"surface_type", t},
                  {"method", (*g)["method"]},
                  {"precision", (*g)["precision"]},
                  {"stable", g->value("stable", json::array()).size()},
                  {"points", (*g)["grid"].size()}};
      if (g->contains("recommended") && !(*g)["recommended"].is_null()) {
        row["recommended"] = (*g)["recommended"];
        recommendations.push_back(row);
        continue;
      }
      json others = json::array();
      for (const std::string& m : stable_methods[(*g)["precision"]])
        if (m != (*g)["method"]) others.push_back(m);
      std::map<std::string, int> counts;
      std::vector<std::string> first_seen;
      for (const json& c : (*g)["grid"])
        if (!text(c, "cause").empty()) {
          add_once(first_seen, c["cause"]);
          ++counts[c["cause"]];
        }
      std::string top;
      for (const std::string& k : first_seen)
        if (top.empty() || counts[k] > counts[top]) top = k;
      row["others"] = others;
      row["top_cause"] = top;
      recommendations.push_back(row);
      const auto same = std::find_if(no_stable.begin(), no_stable.end(), [&](const json& n) {
        return n["surface_type"] == t && n["method"] == (*g)["method"] && n["top_cause"] == top &&
               n["others"] == others;
      });
      if (same != no_stable.end())
        (*same)["precisions"].push_back((*g)["precision"]);
      else
        no_stable.push_back({{"surface_type", t},
                             {"method", (*g)["method"]},
                             {"top_cause", top},
                             {"others", others},
                             {"precisions", {(*g)["precision"]}}});
    }
  }
  return {{"legend", legend},
          {"codes", codes},
          {"types", types},
          {"recommendations", recommendations},
          {"no_stable", no_stable}};
}

// The machine table's rows, as the run wrote them (its registry's fingerprint_rows: the CPU, what
// each backend says of the machine, the OS, the libraries, the build); a run written before they
// were has its CPU and OS alone.
std::vector<std::pair<std::string, std::string>> machine_rows_of(const json& r) {
  std::vector<std::pair<std::string, std::string>> rows;
  if (r.contains("registry") && r["registry"].contains("fingerprint_rows")) {
    for (const json& row : r["registry"]["fingerprint_rows"]) rows.emplace_back(row[0], row[1]);
    return rows;
  }
  const json fp = r.value("fingerprint", json::object());
  const json cpu = fp.value("cpu", json::object());
  const auto str = [](const json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); };
  rows.emplace_back("CPU", str(cpu.value("model", json("?"))) + ", " +
                               str(cpu.value("logical_cores", json("?"))) + " threads");
  rows.emplace_back("OS",
                    str(fp.value("os", json("?"))) + " on " + str(fp.value("host", json("?"))));
  return rows;
}

}  // namespace

std::string page_verdict(const json& c) {
  const std::string v = text(c, "verdict");
  if (vocab::is_unfinished_verdict(v)) return v;
  if (c.contains("error")) return vocab::kVerdictError;
  const auto a = c.find("accuracy");
  if (a == c.end() || a->is_null() || a->empty()) return "";
  if (a->contains("verdict")) return (*a)["verdict"];
  return a->value("passed", false) ? vocab::kVerdictPass : vocab::kVerdictFail;
}

json page_tables(const json& results, const json* previous) {
  const Lists lists = registry_lists(results);
  const std::vector<std::string> verdicts = verdict_names();
  const json& cases = cases_of(results);
  json page = {
      {"methods", lists.methods}, {"backends", lists.backends}, {"surface_types", lists.types}};
  json case_verdicts = json::array();
  for (const json& c : cases) {
    const std::string v = page_verdict(c);
    case_verdicts.push_back(v.empty() ? json(nullptr) : json(v));
  }
  page["verdicts"] = case_verdicts;
  page["summary"] = summary_table(cases, verdicts, lists);
  page["ambiguity"] = ambiguity_table(cases, lists);
  std::set<std::string> missing;  // GPU backends whose cases have no device time
  for (const json& c : cases)
    if (truthy(c, "device") && !(c.contains("counters") && truthy(c["counters"], "device_ms")))
      missing.insert(c["backend"]);
  page["device_time_missing"] = missing;
  page["gallery"] = gallery_table(results);
  page["recommended"] = recommended_table(results);
  page["failures"] = failures_table(cases);
  page["external"] = external_table(cases);
  page["lanes"] = lanes_table(cases, lists);
  // The last lines of what each unfinished case's worker wrote on its standard error.
  json last_words = json::array();
  for (const json& u : results.value("unfinished", json::array())) {
    std::vector<std::string> lines;
    const std::string tail = text(u, "stderr_tail");
    for (size_t at = 0; at < tail.size();) {
      const size_t end = std::min(tail.find('\n', at), tail.size());
      const std::string line = tail.substr(at, end - at);
      if (line.find_first_not_of(" \t\r\f\v") != std::string::npos) lines.push_back(line);
      at = end + 1;
    }
    if (lines.size() > 6) lines.erase(lines.begin(), lines.end() - 6);
    last_words.push_back(lines);
  }
  page["unfinished_last_words"] = last_words;
  json shards = json::array();
  for (const json& s : results.value("shards", json::array())) {
    double measured = 0.0;
    const json stages = s.value("seconds", json::object());
    for (const auto& [stage, seconds] : stages.items()) measured += seconds.get<double>();
    shards.push_back({{"host", s.value("host", "")},
                      {"measured", measured},
                      {"estimated", s.value("expected_seconds", 0.0)}});
  }
  page["shards"] = shards;
  page["sweep"] = sweep_tables(results.value("sweep", json::object()), lists);
  std::set<std::string> prisms;
  for (const json& c : cases)
    if (c.value("surface_type", "") == "prism") prisms.insert(c["scene"]);
  page["prisms"] = prisms;
  // The suite's words; the classes a difference map paints, with their colours, apart.
  page["vocabulary"] = vocab::vocabulary_json();
  json legend = json::array();
  for (const json& w : page["vocabulary"]["pixel_classes"])
    if (w["name"] != "agree" && !w["traces_only"].get<bool>()) legend.push_back(w);
  page["legend"] = legend;
  json regression = json::object();
  if (results.contains("regression") && results["regression"].value("checked", false))
    for (const char* list : {"regressions", "improvements"}) {
      json rows = json::array();
      for (const json& g : results["regression"].value(list, json::array())) {
        const json &was = g["was"], &now = g["now"];
        const bool numbers = was.is_number() && now.is_number();
        rows.push_back(
            {{"change", numbers ? json(now.get<double>() - was.get<double>()) : json(nullptr)},
             {"checks", reasons(g.value("failed_checks", json::array()))}});
      }
      regression[list] = rows;
    }
  page["regression"] = regression;
  json machine = json::array();
  for (const auto& [label, row_text] : machine_rows_of(results))
    machine.push_back({label, row_text});
  page["machine_rows"] = machine;
  page["previous"] = previous ? previous_table(results, *previous, verdicts) : json(nullptr);
  return page;
}

json machines_tables(const std::vector<std::pair<std::string, json>>& runs) {
  json names = json::array();
  for (const auto& [path, r] : runs) {
    // The machine's GPU: a device of its GPU backends' fingerprints that is not software.
    std::string gpu;
    for (const auto& [key, d] : r["fingerprint"].items()) {
      if (!gpu.empty() || !d.is_object()) continue;
      const json name = d.contains("device") ? d["device"] : d.value("renderer", json(nullptr));
      if (name.is_string() && d.contains("software") && !d["software"].get<bool>())
        gpu = ", GPU " + name.get<std::string>();
    }
    std::string folder =
        std::filesystem::absolute(path).lexically_normal().parent_path().filename();
    if (folder.empty()) folder = path;
    names.push_back(folder + ": " + r["fingerprint"]["cpu"].value("model", "?") + gpu);
  }
  // Each machine's fingerprint rows side by side, by the first machine's labels.
  json machine_rows = json::array();
  for (const auto& [label, unused] : machine_rows_of(runs.front().second)) {
    json row = json::array({label});
    for (const auto& [path, r] : runs) {
      std::string cell;
      for (const auto& [l, t] : machine_rows_of(r))
        if (l == label) cell = t;
      row.push_back(cell);
    }
    machine_rows.push_back(row);
  }
  std::map<std::string, double> base;
  for (const json& c : cases_of(runs.front().second))
    if (c.contains("time_ms")) base[c["name"]] = c["time_ms"];
  json speedups = json::array();
  for (size_t k = 1; k < runs.size(); ++k) {
    std::map<std::string, std::vector<double>> ratios;
    for (const json& c : cases_of(runs[k].second))
      if (c.contains("time_ms") && base.count(c["name"]))
        ratios[c["backend"]].push_back(base[c["name"]] / c["time_ms"].get<double>());
    for (const auto& [backend, v] : ratios) {
      double logs = 0.0;
      for (double x : v) logs += std::log(x);
      speedups.push_back({{"run", k},
                          {"backend", backend},
                          {"cases", v.size()},
                          {"mean", std::exp(logs / static_cast<double>(v.size()))},
                          {"least", *std::min_element(v.begin(), v.end())},
                          {"greatest", *std::max_element(v.begin(), v.end())}});
    }
  }
  return {{"names", names}, {"machine_rows", machine_rows}, {"speedups", speedups}};
}

}  // namespace flatmarch::reports
