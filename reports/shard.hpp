// Splitting a run's cases among N shards for a scheduler to run apart (a Slurm job array, a CI
// matrix), and putting the shards' results back together (issue 24). The split is deterministic:
// every shard computes the same one from the same case list, each case's expected cost
// balancing them (longest first, each to the least loaded shard).
#pragma once

#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/scene.hpp"

namespace flatmarch::reports {

// Shard I of N, I from 1 (as written: "2/7").
struct Shard {
  int index = 1, count = 1;
  bool whole() const { return count == 1; }
  std::string text() const { return std::to_string(index) + "/" + std::to_string(count); }
};
// "I/N" with 1 <= I <= N <= 1000; none otherwise.
std::optional<Shard> parse_shard(const std::string& text);

// The shard (1..count) of each case: the cases by decreasing cost (ties by their order), each to
// the shard with the least cost so far (ties to the lowest). Costs must be finite and >= 0.
std::vector<int> assign_shards(const std::vector<double>& costs, int count);

// The expected seconds of a conformance case on a 2-core machine like this one: the oracle's
// share (oracle_case_cost), the method's steps on the backend, a browser's page. The split's
// balance depends on it, and the estimate a shard prints before it starts.
double conformance_case_cost(const std::string& backend, const std::string& method, int edges,
                             int width, int height);
// The oracle's share of a conformance case: the truth, the steps reference and the probe rays'
// traces of its scene and method at WxH, which a suite keeps for the next backend's case of them.
double oracle_case_cost(int edges, int width, int height);

// The expected seconds of one frame of WxH by `backend` and `method` on this machine (sphere and
// relaxed march about ten times the analytic method's steps).
double frame_cost(const std::string& backend, const std::string& method, int width, int height);

// The expected seconds of a case of `backend` timed by Google Benchmark (register_frame_benchmark
// in matrix.hpp): two untimed frames (the whole frame, then its colour alone: what compiles a GPU
// backend's programs); then each of `repetitions` is one frame when a frame takes longer than
// `min_time`, else the runs Google Benchmark makes on its way up to min_time, about 1.6 x
// min_time in all. The SIMD backend adds its counted frame, its lane peak (0.05 s) and four
// frames on one thread.
double timed_case_cost(const std::string& backend, double frame_seconds, int repetitions,
                       double min_time);

// The number of edges of a scene's polygons: the oracle's cost grows with it.
int edge_count(const Scene& scene);
// How many times a gallery scene of its kind a case of `scene` takes: a prism's rays march in 3D,
// through floors and ceilings, and took 2-15x the time of a flat scene's case (the default
// report's matrix, per scene and backend, on a 2-core Zen 5): 5; else 1.
double scene_cost_factor(const Scene& scene);

// What a shard's results carry so that merge() can check they belong together: the shard, the
// whole run's case list (names, in order), and the cost of each shard's cases.
nlohmann::json shard_record(const Shard& shard, const std::vector<std::string>& cases,
                            const std::vector<int>& assignment, const std::vector<double>& costs);

// Checks that `files` (each file's JSON, with its name for errors) are the shards 1..N of one
// run of `command`, whose results have "format": `format`: the same flatmarch build, machine
// (machine_of), parameters ("options") and case list; none missing, none twice. Returns them by
// shard index. Throws std::invalid_argument naming the file and why.
std::vector<const std::pair<std::string, nlohmann::json>*> check_shards(
    const std::vector<std::pair<std::string, nlohmann::json>>& files, const std::string& format,
    const std::string& command);

// A results file's machine: its fingerprint without the host name (the nodes of a cluster's
// job array differ by that alone).
nlohmann::json machine_of(const nlohmann::json& results);

// What every merged result begins with: the first shard's format, fingerprint and options, and
// "merged_from" (the files) and "hosts" (where the shards ran).
nlohmann::json merged_header(const std::vector<std::pair<std::string, nlohmann::json>>& files);

// A shard's part of a run: its shard_record, whether it holds a case (by name), and the line it
// says before it starts ("shard 1/4 holds 86 of the run's 348 cases, about 81 s here by their
// expected costs (each shard's: 81 81 81 81 s)", `noun` naming the cases).
struct ShardPlan {
  nlohmann::json record;
  std::function<bool(const std::string& name)> holds;
  std::string summary;
};
// The plan of `shard` over a run's cases (names in the run's order, each with its expected
// seconds), split by assign_shards.
ShardPlan plan_shard(const Shard& shard, const std::vector<std::pair<std::string, double>>& cases,
                     const std::string& noun = "cases");

// What one shard's results hold, checked against its shard record's "holds" as they are read:
// add() throws for a case that is not its shard's, complete() for a case of its shard it holds
// no results of (an interrupted run). Both throw std::invalid_argument naming the file.
class ShardContents {
 public:
  ShardContents(std::string file, const nlohmann::json& shard);
  void add(const std::string& key);
  void complete() const;

 private:
  std::string file_;
  std::vector<std::string> holds_;  // in the run's order, for the first one missing
  std::set<std::string> held_, found_;
};

// Merges the results of a sharded `flatmarch conform` (each file's JSON, with its name for
// errors): checks that they are the shards 1..N of one run (same format, flatmarch build,
// machine, parameters and case list, none missing or twice) and returns the whole run's results,
// cases in the run's order. Throws std::invalid_argument naming the file and why.
nlohmann::json merge_conformance(const std::vector<std::pair<std::string, nlohmann::json>>& files);

// Merges the --benchmark_out JSON of a benchmark program's shards (--shard=I/N; bench/gallery.hpp
// bench::run) into one Google Benchmark document: the context of shard 1 (less the shard), every
// run in the order the program registered its benchmarks, "flatmarch_merged_from" in the context.
// Checks as check_shards: the same program, flags, build and machine (the context's fingerprint),
// case list and N; none missing, none twice; and that each shard ran its benchmarks. Throws
// std::invalid_argument naming the file and why.
nlohmann::json merge_benchmarks(const std::vector<std::pair<std::string, nlohmann::json>>& files);

// Whether a document is a benchmark program's sharded output (Google Benchmark's JSON with
// "flatmarch_shard" in its context).
bool is_benchmark_shard(const nlohmann::json& doc);

}  // namespace flatmarch::reports
