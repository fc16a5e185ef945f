// Splitting a run's cases among N shards for a scheduler to run apart (a Slurm job array, a CI
// matrix), and putting the shards' results back together (issue 24). The split is deterministic:
// every shard computes the same one from the same case list, each case's expected cost
// balancing them (longest first, each to the least loaded shard).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

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
// share, the method's steps on the backend, a browser's page. The split's balance depends on it,
// and the estimate a shard prints before it starts.
double conformance_case_cost(const std::string& backend, const std::string& method, int edges,
                             int width, int height);

// What a shard's results carry so that merge() can check they belong together: the shard, the
// whole run's case list (names, in order), and the cost of each shard's cases.
nlohmann::json shard_record(const Shard& shard, const std::vector<std::string>& cases,
                            const std::vector<int>& assignment, const std::vector<double>& costs);

// Merges the results of a sharded `flatmarch conform` (each file's JSON, with its name for
// errors): checks that they are the shards 1..N of one run (same format, flatmarch build,
// machine, parameters and case list, none missing or twice) and returns the whole run's results,
// cases in the run's order. Throws std::invalid_argument naming the file and why.
nlohmann::json merge_conformance(const std::vector<std::pair<std::string, nlohmann::json>>& files);

}  // namespace flatmarch::reports
