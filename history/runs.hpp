// A results file as the history keeps it: one run (a report, a conformance run, a benchmark
// program's JSON) with what identifies it (its content, commit, machine, build and options) and
// its figures per case, each a deterministic figure (judged at any change) or a timing (judged
// as a series).
#pragma once

#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace flatmarch::history {

// How a figure is judged over runs: deterministic figures (steps, crossings, accuracy, verdicts)
// are the same on every run of the same code and change only with it; timings wander with the
// machine, better higher (rays a second) or lower (a frame's time).
enum class Judged { kDeterministic, kHigherIsBetter, kLowerIsBetter };
const char* to_string(Judged judged);
Judged judged_from_string(const std::string& text);

struct Measurement {
  std::string case_name;  // "report/scalar/sphere/torus/160x90", "bench/BM_Frame/..."
  std::string figure;     // "rays_per_s", "steps_mean", "verdict", "real_time", ...
  Judged judged = Judged::kDeterministic;
  double value = 0.0;  // numbers
  std::string text;    // a verdict ("" for a number)
  // The relative spread (standard deviation over the median) of the run's repetitions of a
  // timing, and their number: how far this one run's figure can be trusted.
  double spread = 0.0;
  int repetitions = 1;
};

struct Run {
  std::string digest;  // of the file's content: a run added twice is one run
  std::string kind;    // report, conform or benchmark
  std::string commit;
  std::string created;  // when it was measured (the file's own time), ISO 8601
  // The series a figure belongs to: the same machine (CPU, its instruction sets, the GPU
  // backends' devices), build (compiler and type) and options (sizes and parameters), as a
  // key; and the machine in words.
  std::string machine, machine_text, build, options;
  std::string baseline;  // digest of the baseline its gate judged it by ("" where none)
  std::string page;      // its own report page, where it has one (a path or URL)
  std::string source;    // the file it was read from
  std::vector<Measurement> measurements;
};

// Reads a results file of `flatmarch report` (or `merge`), `flatmarch conform` or a Google
// Benchmark program's --benchmark_out JSON as a run of `commit`; `baseline`: the baseline file
// the run was gated against, or "" (then a report's own regression.baseline where it names an
// existing file). Throws std::invalid_argument naming the file and why for anything else: not
// JSON, another program's JSON, a results file without cases.
Run read_run(const std::filesystem::path& file, const std::string& commit,
             const std::filesystem::path& baseline = {});

// A time as the results files write it: ISO 8601 in UTC ("2026-12-05T10:00:00Z").
std::string utc_text(std::time_t t);

// A stable digest of text (two 64-bit FNV-1a hashes, 32 hex digits): the same on every machine.
std::string digest_of(const std::string& text);

}  // namespace flatmarch::history
