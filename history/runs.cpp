#include "history/runs.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <stdexcept>

namespace flatmarch::history {

using nlohmann::json;
namespace fs = std::filesystem;

const char* to_string(Judged judged) {
  switch (judged) {
    case Judged::kDeterministic:
      return "deterministic";
    case Judged::kHigherIsBetter:
      return "higher_is_better";
    case Judged::kLowerIsBetter:
      return "lower_is_better";
  }
  return "?";
}

Judged judged_from_string(const std::string& text) {
  for (Judged j : {Judged::kDeterministic, Judged::kHigherIsBetter, Judged::kLowerIsBetter})
    if (text == to_string(j)) return j;
  throw std::invalid_argument("not a way of judging a figure: " + text);
}

std::string utc_text(std::time_t t) {
  char s[32];
  std::strftime(s, sizeof s, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return s;
}

std::string digest_of(const std::string& text) {
  // FNV-1a, 64 bits, from two offset bases: 128 bits of digest, stable everywhere.
  uint64_t a = 14695981039346656037ull, b = 1099511628211ull * 31ull;
  for (unsigned char c : text) {
    a = (a ^ c) * 1099511628211ull;
    b = (b ^ c) * 1099511628211ull;
  }
  char out[33];
  std::snprintf(out, sizeof out, "%016" PRIx64 "%016" PRIx64, a, b);
  return out;
}

namespace {

// Google Benchmark writes a counter that is not a number as a bare NaN or inf, which JSON has
// not: those tokens, outside strings, read as null.
std::string without_bare_non_numbers(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      out += c;
      if (c == '\\' && i + 1 < text.size())
        out += text[++i];
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"') in_string = true;
    bool replaced = false;
    for (const char* word :
         {"-Infinity", "Infinity", "-inf", "inf", "-nan", "nan", "NaN", "-NaN"}) {
      const size_t n = std::char_traits<char>::length(word);
      if (text.compare(i, n, word) == 0 &&
          (i + n == text.size() || !std::isalnum(static_cast<unsigned char>(text[i + n])))) {
        out += "null";
        i += n - 1;
        replaced = true;
        break;
      }
    }
    if (!replaced) out += c;
  }
  return out;
}

[[noreturn]] void refuse(const fs::path& file, const std::string& why) {
  throw std::invalid_argument(file.string() + ": " + why);
}

// A deterministic figure of a case: steps and crossings, the accuracy, the verdict.
Measurement fixed(const std::string& case_name, const std::string& figure, const json& value) {
  Measurement m;
  m.case_name = case_name;
  m.figure = figure;
  if (value.is_string())
    m.text = value.get<std::string>();
  else
    m.value = value.get<double>();
  return m;
}

// A timing of a case, its spread and repetitions to be filled in.
Measurement timing(const std::string& case_name, const std::string& figure, Judged judged,
                   const json& value) {
  Measurement m;
  m.case_name = case_name;
  m.figure = figure;
  m.judged = judged;
  m.value = value.get<double>();
  return m;
}

// The median and the relative spread (sample standard deviation over the median) of samples.
std::pair<double, double> median_and_spread(std::vector<double> samples) {
  std::sort(samples.begin(), samples.end());
  const size_t n = samples.size();
  const double median = n % 2 ? samples[n / 2] : (samples[n / 2 - 1] + samples[n / 2]) / 2;
  if (n < 2 || median <= 0.0) return {median, 0.0};
  double mean = 0.0, var = 0.0;
  for (double s : samples) mean += s / static_cast<double>(n);
  for (double s : samples) var += (s - mean) * (s - mean) / static_cast<double>(n - 1);
  return {median, std::sqrt(var) / median};
}

// The machine a fingerprint describes, for grouping series: the CPU (model, cores, instruction
// sets) and the devices of the GPU backends; not the host's name, which a CI runner changes
// every run.
std::pair<std::string, std::string> machine_of(const json& fp) {
  // Words of any JSON value (a benchmark's context holds numbers as text).
  const auto words = [](const json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); };
  const json cpu = fp.value("cpu", json::object());
  json key = {{"model", words(cpu.value("model", json("?")))},
              {"logical_cores", words(cpu.value("logical_cores", json(0)))},
              {"isas", cpu.value("isas", json::array())}};
  std::string text = words(cpu.value("model", json("?"))) + ", " +
                     words(cpu.value("logical_cores", json("?"))) + " threads, " +
                     words(cpu.value("isa", json("?")));
  for (const auto& [name, entry] : fp.items())
    if (entry.is_object() && entry.contains("device") && entry["device"].is_string()) {
      key["devices"][name] = entry["device"];
      text += "; " + name + ": " + entry["device"].get<std::string>();
    }
  return {digest_of(key.dump()).substr(0, 16), text};
}

// A Google Benchmark context's fingerprint fields ("fingerprint/cpu/model": ..., lists as
// "fingerprint/cpu/isas/0": ..., reports/fingerprint.hpp's add_to_benchmark_context) as a
// fingerprint.
json fingerprint_of_context(const json& context) {
  json fp = json::object();
  for (const auto& [key, value] : context.items())
    if (key.rfind("fingerprint/", 0) == 0) fp[json::json_pointer(key.substr(11))] = value;
  return fp;
}

void read_report(const json& doc, Run& run) {
  const json& cases = doc.at("matrix").at("cases");
  for (const json& c : cases) {
    const std::string name = "report/" + c.value("name", "?");
    if (c.contains("counters")) {
      const json& k = c["counters"];
      if (k.contains("rays_per_s")) {
        Measurement m = timing(name, "rays_per_s", Judged::kHigherIsBetter, k["rays_per_s"]);
        if (c.contains("time_samples_ms") && c["time_samples_ms"].size() > 1) {
          m.spread = median_and_spread(c["time_samples_ms"].get<std::vector<double>>()).second;
          m.repetitions = static_cast<int>(c["time_samples_ms"].size());
        }
        run.measurements.push_back(m);
      }
      for (const char* f : {"steps_mean", "crossings_mean"})
        if (k.contains(f) && k[f].is_number()) run.measurements.push_back(fixed(name, f, k[f]));
      // The CPU's count of the work (reports/work_count.hpp): nearly still from run to run, so a
      // series of it shows a change a timing's wander hides.
      if (k.contains("instructions_per_ray") && k["instructions_per_ray"].is_number())
        run.measurements.push_back(timing(name, "instructions_per_ray", Judged::kLowerIsBetter,
                                          k["instructions_per_ray"]));
    }
    if (c.contains("accuracy") && c["accuracy"].is_object()) {
      const json& a = c["accuracy"];
      for (const char* f : {"hit_mismatch", "crossings_mismatch", "ambiguous"})
        if (a.contains(f) && a[f].is_number()) run.measurements.push_back(fixed(name, f, a[f]));
    }
    const std::string verdict = c.contains("accuracy") && c["accuracy"].contains("verdict")
                                    ? c["accuracy"]["verdict"].get<std::string>()
                                    : c.value("verdict", c.contains("error") ? "error" : "");
    if (!verdict.empty()) run.measurements.push_back(fixed(name, "verdict", verdict));
  }
}

void read_conform(const json& doc, Run& run) {
  for (const json& c : doc.at("cases")) {
    const std::string name = "conform/" + c.value("backend", "?") + "/" + c.value("method", "?") +
                             "/" + c.value("scene", "?") + "/" + c.value("size", "?");
    for (const char* f : {"hit_rate", "crossings_rate", "steps_ks"})
      if (c.contains(f) && c[f].is_number()) run.measurements.push_back(fixed(name, f, c[f]));
    if (c.contains("verdict")) run.measurements.push_back(fixed(name, "verdict", c["verdict"]));
  }
}

void read_benchmark(const json& doc, Run& run) {
  // Per benchmark (its run_name): its median time, spread and repetitions from the aggregates
  // where it was repeated, else its one run; its steps and crossings counters where it has them.
  struct Entry {
    json median, mean, iteration;
    double cv = 0.0;
    int repetitions = 1;
  };
  std::map<std::string, Entry> entries;
  std::vector<std::string> order;
  for (const json& b : doc.at("benchmarks")) {
    if (b.contains("error_occurred") && b["error_occurred"].get<bool>()) continue;
    const std::string name = b.value("run_name", b.value("name", "?"));
    if (!entries.count(name)) order.push_back(name);
    Entry& e = entries[name];
    if (b.value("run_type", "iteration") == "aggregate") {
      const std::string kind = b.value("aggregate_name", "");
      e.repetitions = b.value("repetitions", 1);
      if (kind == "median") e.median = b;
      if (kind == "mean") e.mean = b;
      if (kind == "cv") e.cv = b.value("real_time", 0.0);
    } else if (e.iteration.is_null()) {
      e.iteration = b;
    }
  }
  for (const std::string& name : order) {
    const Entry& e = entries[name];
    const json& b = !e.median.is_null() ? e.median : !e.mean.is_null() ? e.mean : e.iteration;
    if (b.is_null() || !b.contains("real_time")) continue;
    Measurement m = timing("bench/" + name, "real_time", Judged::kLowerIsBetter, b["real_time"]);
    m.spread = e.cv;
    m.repetitions = e.repetitions;
    run.measurements.push_back(m);
    for (const char* f : {"steps_mean", "crossings_mean"})
      if (b.contains(f) && b[f].is_number())
        run.measurements.push_back(fixed("bench/" + name, f, b[f]));
  }
}

}  // namespace

Run read_run(const fs::path& file, const std::string& commit, const fs::path& baseline) {
  std::ifstream in(file, std::ios::binary);
  if (!in) refuse(file, "cannot be read");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  json doc;
  try {
    doc = json::parse(without_bare_non_numbers(text));
  } catch (const json::exception& e) {
    refuse(file, std::string("not JSON (corrupt or cut short?): ") + e.what());
  }
  if (!doc.is_object()) refuse(file, "not a results file: its JSON is no object");
  Run run;
  run.commit = commit;
  run.source = file.string();
  json fingerprint, options;
  try {
    const std::string format = doc.value("format", "");
    if (format.rfind("flatmarch-report/", 0) == 0 ||
        (doc.contains("matrix") && doc.contains("ranking"))) {
      run.kind = "report";
      read_report(doc, run);
      fingerprint = doc.at("fingerprint");
      options = doc.value("options", json::object());
      options.erase("scenes");
      options.erase("methods");
      options.erase("repetitions");
      run.created = doc.value("created", "");
      if (fs::exists(file.parent_path() / "index.html"))
        run.page = (file.parent_path() / "index.html").string();
    } else if (format.rfind("flatmarch-conform/", 0) == 0) {
      run.kind = "conform";
      read_conform(doc, run);
      fingerprint = doc.at("fingerprint");
      options = doc.value("options", json::object());
      options.erase("thresholds");  // its words: the figures judged are the checks' values
      run.created = doc.value("created", "");
    } else if (doc.contains("context") && doc.contains("benchmarks")) {
      run.kind = "benchmark";
      read_benchmark(doc, run);
      fingerprint = fingerprint_of_context(doc["context"]);
      if (fingerprint.empty())  // a benchmark program of another project: its context's CPU
        fingerprint = {{"cpu",
                        {{"model", doc["context"].value("host_name", "?")},
                         {"logical_cores", doc["context"].value("num_cpus", 0)}}}};
      options = {{"executable", fs::path(doc["context"].value("executable", "?")).filename()}};
      run.created = doc["context"].value("date", "");
    } else {
      refuse(file,
             "not a results file of flatmarch report, flatmarch conform or a Google Benchmark "
             "program (no \"format\", no \"context\" and \"benchmarks\")");
    }
  } catch (const json::exception& e) {
    refuse(file, std::string("a ") + (run.kind.empty() ? "results" : run.kind) +
                     " file with a field missing or of the wrong type: " + e.what());
  }
  if (run.measurements.empty()) refuse(file, "holds no case: nothing to keep");
  if (!fingerprint.is_object())
    refuse(file, "its fingerprint (the machine it ran on) is no object");
  std::tie(run.machine, run.machine_text) = machine_of(fingerprint);
  run.build = fingerprint.value("build", json::object()).dump();
  run.options = options.dump();
  run.digest = digest_of(text);
  fs::path gated_by = baseline;
  if (gated_by.empty() && doc.contains("regression") && doc["regression"].value("checked", false) &&
      doc["regression"].contains("baseline"))
    gated_by = doc["regression"]["baseline"].get<std::string>();
  if (!gated_by.empty()) {
    std::ifstream b(gated_by, std::ios::binary);
    if (b)
      run.baseline = digest_of(
          std::string((std::istreambuf_iterator<char>(b)), std::istreambuf_iterator<char>()));
    else if (!baseline.empty())
      throw std::invalid_argument("--baseline " + baseline.string() + ": cannot be read");
  }
  if (run.created.empty()) {  // a file that does not say when: when it was written
    const auto written = std::chrono::file_clock::to_sys(fs::last_write_time(file));
    run.created = utc_text(std::chrono::system_clock::to_time_t(written));
  }
  return run;
}

}  // namespace flatmarch::history
