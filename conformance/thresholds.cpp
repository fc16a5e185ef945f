#include "conformance/thresholds.hpp"

#include <fstream>
#include <stdexcept>

namespace flatmarch::conformance {

extern const char* const kThresholdsJson;

namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw std::runtime_error(where + ": " + what);
}

double number(const json& v, const std::string& where, double lo, double hi) {
  if (!v.is_number()) fail(where, "expected a number");
  const double x = v.get<double>();
  if (!(x >= lo && x <= hi))
    fail(where, "must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return x;
}

int integer(const json& v, const std::string& where, int lo, int hi) {
  if (!v.is_number_integer()) fail(where, "expected an integer");
  const int x = v.get<int>();
  if (x < lo || x > hi)
    fail(where, "must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return x;
}

void read_image(const json& j, ImageThresholds& t, const std::string& where) {
  if (!j.is_object()) fail(where, "expected an object");
  for (const auto& [key, v] : j.items()) {
    const std::string at = where + "/" + key;
    if (key == "fail")
      t.fail = number(v, at, 0, 1e9);
    else if (key == "failpercent")
      t.failpercent = number(v, at, 0, 100);
    else if (key == "hardfail")
      t.hardfail = number(v, at, 0, 1e9);
    else if (key == "warn")
      t.warn = number(v, at, 0, 1e9);
    else if (key == "warnpercent")
      t.warnpercent = number(v, at, 0, 100);
    else if (key == "perceptual_failpercent")
      t.perceptual_failpercent = number(v, at, 0, 100);
    else
      fail(at, "unknown key");
  }
}

void read_colour(const json& j, ColourThresholds& t, const std::string& where) {
  if (!j.is_object()) fail(where, "expected an object");
  for (const auto& [key, v] : j.items()) {
    const std::string at = where + "/" + key;
    if (key == "delta_e")
      t.delta_e = number(v, at, 0, 1000);
    else if (key == "failpercent")
      t.failpercent = number(v, at, 0, 100);
    else if (key == "allowed")
      t.allowed = integer(v, at, 0, 1000000);
    else
      fail(at, "unknown key");
  }
}

// Applies one set of thresholds (a patch already merged, or a part of one) to `t`.
void read(const json& j, Thresholds& t, const std::string& where) {
  if (!j.is_object()) fail(where, "expected an object");
  for (const auto& [key, v] : j.items()) {
    const std::string at = where + "/" + key;
    if (key == "hit_rate")
      t.hit_rate = number(v, at, 0, 1);
    else if (key == "crossings_rate")
      t.crossings_rate = number(v, at, 0, 1);
    else if (key == "ambiguous_max")
      t.ambiguous_max = number(v, at, 0, 1);
    else if (key == "t_exceeded_max")
      t.t_exceeded_max = number(v, at, 0, 1);
    else if (key == "image")
      read_image(v, t.image, at);
    else if (key == "colour")
      read_colour(v, t.colour, at);
    else if (key == "steps_ks_max")
      t.steps_ks_max = number(v, at, 0, 1);
    else if (key == "steps_mean_ratio_max")
      t.steps_mean_ratio_max = number(v, at, 1, 1e9);
    else if (key == "probe_rays")
      t.probe_rays = integer(v, at, 0, 1000);
    else if (key == "trace_events")
      t.trace_events = integer(v, at, 1, 100000);
    else if (key == "trace_failures_max")
      t.trace_failures_max = integer(v, at, 0, 1000);
    else if (key == "trace_error")
      t.trace_error = number(v, at, 0, 1e9);
    else if (key == "failures") {
      if (!v.is_object()) fail(at, "expected an object");
      for (const auto& [name, share] : v.items()) {
        int c = 0;
        while (c < kFailureClasses && name != to_string(static_cast<Failure>(c))) ++c;
        if (c == kFailureClasses) fail(at + "/" + name, "unknown failure class");
        t.failure_max[static_cast<size_t>(c)] = number(share, at + "/" + name, 0, 1);
      }
    } else
      fail(at, "unknown key");
  }
}

bool names(const json& exception, const char* key, const std::string& value) {
  if (!exception.contains(key)) return true;  // every one
  for (const json& v : exception[key])
    if (v.get<std::string>() == value) return true;
  return false;
}

void check(const json& doc, const std::string& file) {
  if (!doc.is_object()) fail(file, "expected an object");
  for (const auto& [key, v] : doc.items()) {
    const std::string at = file + ": /" + key;
    Thresholds scratch;
    if (key == "comment") continue;
    if (key == "defaults")
      read(v, scratch, at);
    else if (key == "methods" || key == "backends") {
      if (!v.is_object()) fail(at, "expected an object");
      for (const auto& [name, patch] : v.items()) {
        if (!patch.is_object()) fail(at + "/" + name, "expected an object");
        json p = patch;
        if (p.contains("why") && !p["why"].is_string())
          fail(at + "/" + name + "/why", "expected a string");
        p.erase("why");
        read(p, scratch, at + "/" + name);
      }
    } else if (key == "exceptions") {
      if (!v.is_array()) fail(at, "expected an array");
      for (size_t k = 0; k < v.size(); ++k) {
        const json& e = v[k];
        const std::string here = at + "/" + std::to_string(k);
        if (!e.is_object()) fail(here, "expected an object");
        for (const auto& [ekey, ev] : e.items()) {
          if (ekey == "why") {
            if (!ev.is_string()) fail(here + "/why", "expected a string");
          } else if (ekey == "set") {
            read(ev, scratch, here + "/set");
          } else if (ekey == "scenes" || ekey == "methods" || ekey == "backends") {
            if (!ev.is_array()) fail(here + "/" + ekey, "expected an array of names");
            for (const json& name : ev)
              if (!name.is_string()) fail(here + "/" + ekey, "expected an array of names");
          } else {
            fail(here + "/" + ekey, "unknown key");
          }
        }
        if (!e.contains("why")) fail(here, "an exception must say why");
        if (!e.contains("set")) fail(here, "an exception must set something");
      }
    } else {
      fail(at, "unknown key");
    }
  }
}

}  // namespace

const json& builtin_thresholds() {
  static const json doc = [] {
    json d = json::parse(kThresholdsJson);
    check(d, "conformance/thresholds.json (built in)");
    return d;
  }();
  return doc;
}

json load_thresholds(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) fail(file.string(), "cannot be read");
  json doc;
  try {
    doc = json::parse(in);
  } catch (const json::parse_error& e) {
    fail(file.string(), e.what());
  }
  check(doc, file.string());
  return doc;
}

Thresholds thresholds_for(const json& doc, const std::string& backend, Method method,
                          const std::string& scene) {
  json merged = doc.value("defaults", json::object());
  const std::string m = to_string(method);
  std::string why;
  // A method's or backend's layer, with its reason.
  const auto layer = [&](const char* key, const std::string& name) {
    if (!doc.contains(key) || !doc[key].contains(name)) return;
    json patch = doc[key][name];
    if (patch.contains("why")) {
      why += (why.empty() ? "" : "; ") + name + ": " + patch["why"].get<std::string>();
      patch.erase("why");
    }
    merged.merge_patch(patch);
  };
  layer("methods", m);
  layer("backends", backend);
  for (const json& e : doc.value("exceptions", json::array()))
    if (names(e, "scenes", scene) && names(e, "methods", m) && names(e, "backends", backend)) {
      merged.merge_patch(e["set"]);
      why += (why.empty() ? "" : "; ") + e["why"].get<std::string>();
    }
  Thresholds t;
  read(merged, t, "thresholds");
  t.why = why;
  return t;
}

json to_json(const Thresholds& t) {
  json failures = json::object();
  for (int c = 0; c < kFailureClasses; ++c)
    failures[to_string(static_cast<Failure>(c))] = t.failure_max[static_cast<size_t>(c)];
  return {{"hit_rate", t.hit_rate},
          {"crossings_rate", t.crossings_rate},
          {"ambiguous_max", t.ambiguous_max},
          {"t_exceeded_max", t.t_exceeded_max},
          {"image",
           {{"fail", t.image.fail},
            {"failpercent", t.image.failpercent},
            {"hardfail", t.image.hardfail},
            {"warn", t.image.warn},
            {"warnpercent", t.image.warnpercent},
            {"perceptual_failpercent", t.image.perceptual_failpercent}}},
          {"colour",
           {{"delta_e", t.colour.delta_e},
            {"failpercent", t.colour.failpercent},
            {"allowed", t.colour.allowed}}},
          {"steps_ks_max", t.steps_ks_max},
          {"steps_mean_ratio_max", t.steps_mean_ratio_max},
          {"probe_rays", t.probe_rays},
          {"trace_events", t.trace_events},
          {"trace_failures_max", t.trace_failures_max},
          {"trace_error", t.trace_error},
          {"failures", failures},
          {"why", t.why}};
}

}  // namespace flatmarch::conformance
