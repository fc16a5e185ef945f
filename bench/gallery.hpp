// What the benchmark programs share: the gallery scenes and the counters of a rendered frame.
#pragma once

#include <benchmark/benchmark.h>
#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include "backends/backend.hpp"
#include "reports/fingerprint.hpp"
#include "reports/matrix.hpp"
#include "reports/shard.hpp"
#include "scene/load.hpp"

namespace flatmarch::bench {

using reports::frame_counters;  // the counters every benchmark program reports

// Frames are renders' largest allocations (7 MB at 640x360). By default glibc gives memory that
// big back to the system when it is freed and maps it afresh for the next frame, whose pages
// then fault in one by one (about 4 ms a frame here, mostly serialised in the kernel). A renderer
// that draws frame after frame keeps the memory; so do the benchmarks, for every backend alike.
inline void keep_freed_frames() {
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

// Takes a program's own flags, --NAME=VALUE with NAME one of `names`, out of argv before Google
// Benchmark reads it (it reports flags it does not know); returns their values by name.
inline std::map<std::string, std::string> take_flags(int& argc, char** argv,
                                                     const std::vector<std::string>& names) {
  std::map<std::string, std::string> values;
  for (int k = 1; k < argc;) {
    const std::string arg = argv[k];
    const auto name = std::find_if(names.begin(), names.end(), [&](const std::string& n) {
      return arg.rfind("--" + n + "=", 0) == 0;
    });
    if (name == names.end()) {
      ++k;
      continue;
    }
    values[*name] = arg.substr(name->size() + 3);
    std::copy(argv + k + 1, argv + argc + 1, argv + k);
    --argc;
  }
  return values;
}

// A --size value, WxH with each 1 to 8192, into width and height; false if it is not one.
inline bool parse_size(const std::string& text, int& width, int& height) {
  return std::sscanf(text.c_str(), "%dx%d", &width, &height) == 2 && width >= 1 && height >= 1 &&
         width <= 8192 && height <= 8192;
}

// --- Sharded runs (issue 24): --shard=I/N runs shard I of N of the program's benchmarks, for a
// scheduler to run apart; `flatmarch merge` puts the shards' --benchmark_out JSON together.

// The program's run: its --shard, the names registered with add() or note() in order, and its
// own flags as given (the shards of one run must be given the same).
struct Run {
  std::optional<reports::Shard> shard;
  std::vector<std::string> names;
  std::vector<double> costs;  // of each name: expected seconds, NaN where none was given
  std::string flags;
  bool writes_json = false;  // --benchmark_out given
};
inline Run& run_state() {
  static Run run;
  return run;
}

// Registers a benchmark as benchmark::RegisterBenchmark does, and records its name for --shard.
template <class... Args>
benchmark::internal::Benchmark* add(const std::string& name, Args&&... args) {
  run_state().names.push_back(name);
  run_state().costs.push_back(std::nan(""));
  return benchmark::RegisterBenchmark(name.c_str(), std::forward<Args>(args)...);
}
// Records the name of a benchmark registered otherwise (reports::register_frame_benchmark).
inline void note(const std::string& name) {
  run_state().names.push_back(name);
  run_state().costs.push_back(std::nan(""));
}
// The expected cost of the benchmark registered last (reports::frame_cost of its frame), by
// which --shard balances the shards; one without costs the median of those with (all alike
// where none has one).
inline void cost(double seconds) {
  if (!run_state().costs.empty()) run_state().costs.back() = seconds;
}

// What a benchmark program does first: keep freed frames, take --shard, and take Google
// Benchmark's flags. False when a flag is unknown or --shard is not I/N (it has been reported;
// exit with 2).
inline bool begin(int& argc, char** argv) {
  keep_freed_frames();
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg.rfind("--shard=", 0) != 0 && arg.rfind("--benchmark_out", 0) != 0)
      run_state().flags += (run_state().flags.empty() ? "" : " ") + arg;
    if (arg.rfind("--benchmark_out=", 0) == 0) run_state().writes_json = true;
  }
  const auto flags = take_flags(argc, argv, {"shard"});
  if (flags.count("shard")) {
    run_state().shard = reports::parse_shard(flags.at("shard"));
    if (!run_state().shard) {
      std::fprintf(stderr, "%s: --shard=I/N with 1 <= I <= N <= 1000, not %s\n", argv[0],
                   flags.at("shard").c_str());
      return false;
    }
  }
  benchmark::Initialize(&argc, argv);
  return !benchmark::ReportUnrecognizedArguments(argc, argv);
}

// Whether --benchmark_filter selects the benchmark of this name: a regular expression searched
// for in the name, a leading '-' negating it; none, "." and "all" select every one. Throws
// std::regex_error where the filter is not a regular expression.
inline bool selected(const std::string& name) {
  std::string filter = benchmark::GetBenchmarkFilter();
  const bool negative = !filter.empty() && filter[0] == '-';
  if (negative) filter.erase(0, 1);
  if (filter.empty() || filter == "." || filter == "all") return true;
  return std::regex_search(name, std::regex(filter)) != negative;
}

// Whether the filter selects any of these names (false where it is not a regular expression:
// run() says so). A program asks before it starts a backend whose benchmarks these are: a
// browser or a GPU driver takes seconds to start, for nothing where none of them is run.
inline bool selects_any(const std::vector<std::string>& names) {
  try {
    return std::any_of(names.begin(), names.end(), selected);
  } catch (const std::regex_error&) {
    return false;
  }
}

// A name as a regular expression that matches it alone.
inline std::string regex_escaped(const std::string& name) {
  static const std::regex special(R"([.^$|()\[\]{}*+?\\])");
  return std::regex_replace(name, special, R"(\$&)");
}

// Runs the registered benchmarks, or with --shard=I/N those of shard I: of the names that
// --benchmark_filter selects, in the order registered, split by their cost (cost()), the same
// split in every shard. The JSON context then carries the machine's fingerprint and
// "flatmarch_shard" (the shard's record: reports::shard_record) and "flatmarch_flags", for
// `flatmarch merge`. Returns the exit status.
inline int run() {
  Run& r = run_state();
  if (!r.shard) {
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
  }
  std::vector<std::pair<std::string, double>> cases;
  try {
    for (size_t k = 0; k < r.names.size(); ++k)
      if (selected(r.names[k])) cases.emplace_back(r.names[k], r.costs[k]);
  } catch (const std::regex_error& e) {
    std::fprintf(stderr, "--benchmark_filter: not a regular expression: %s\n", e.what());
    return 2;
  }
  if (static_cast<size_t>(r.shard->count) > cases.size()) {
    std::fprintf(stderr, "--shard=%s: more shards than the run's %zu benchmarks\n",
                 r.shard->text().c_str(), cases.size());
    return 2;
  }
  std::vector<double> given;
  for (const auto& c : cases)
    if (!std::isnan(c.second)) given.push_back(c.second);
  std::sort(given.begin(), given.end());
  for (auto& c : cases)
    if (std::isnan(c.second)) c.second = given.empty() ? 1.0 : given[given.size() / 2];
  const nlohmann::json record = reports::plan_shard(*r.shard, cases, "benchmarks").record;
  std::string spec;
  for (const auto& name : record["holds"])
    spec += (spec.empty() ? "" : "|") + regex_escaped(name.get<std::string>());
  std::fprintf(stderr, "shard %s holds %zu of the run's %zu benchmarks%s\n",
               r.shard->text().c_str(), record["holds"].size(), cases.size(),
               r.writes_json ? ""
                             : " (give --benchmark_out=FILE: `flatmarch merge` puts the shards' "
                               "JSON together)");
  reports::add_to_benchmark_context(reports::hardware_fingerprint());
  benchmark::AddCustomContext("flatmarch_shard", record.dump());
  benchmark::AddCustomContext("flatmarch_flags", r.flags);
  benchmark::RunSpecifiedBenchmarks("^(" + spec + ")(/|$)");
  benchmark::Shutdown();
  return 0;
}

// The gallery scenes (scenes/*.json), sorted by file name; pointers stay valid for benchmarks.
inline std::vector<std::unique_ptr<Scene>> load_gallery() {
  std::vector<std::filesystem::path> files;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(FLATMARCH_SOURCE_DIR) / "scenes"))
    if (entry.path().extension() == ".json") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  std::vector<std::unique_ptr<Scene>> scenes;
  for (const auto& f : files) scenes.push_back(std::make_unique<Scene>(load_scene(f)));
  return scenes;
}

}  // namespace flatmarch::bench
