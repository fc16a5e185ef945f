// `flatmarch sweep`: the march over a grid of hit thresholds eps and re-entry offsets (relative
// to eps, and fixed), for each method and precision, on each scene: time, steps, accuracy against
// the oracle (the conformance suite's verdict, image and trace agreement, failures by class).
// Per surface type it finds the stable region (the grid points where every scene of the type
// passes), the speed-accuracy Pareto front, and recommends an eps and offset.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "backends/backend.hpp"
#include "conformance/suite.hpp"

namespace flatmarch::reports {

struct SweepOptions {
  std::string backend = "scalar";
  BackendOptions backend_options;
  std::vector<double> eps = {1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7};
  std::vector<double> offset_factors = {0.5, 1.0, 2.0, 5.0, 10.0};  // offset = factor x eps
  std::vector<double> offset_fixed = {1e-4, 1e-2};                  // and these, whatever eps
  std::vector<Method> methods{kKernelMethods.begin(), kKernelMethods.end()};
  std::vector<Precision> precisions = {Precision::f32, Precision::f64};  // those it has
  MarchParams params;  // max_steps, max_distance, omega
  int width = 64, height = 36;
  int repetitions = 3;  // frames timed per point (median)
  // The recommended point of each group is checked again at this multiple of the frame size on
  // every scene of its type, and replaced when it fails there; 1: not checked again.
  int confirm_scale = 2;
  // The groups to run, by sweep_case_key (a shard's, issue 24); empty: every group. A group's
  // analysis and re-checks need only its own points, so a shard holds whole groups.
  std::function<bool(const std::string& key)> holds;
};

// A sweep group's key in a sharded run's case list: "sweep/SURFACE_TYPE/METHOD" (its every
// precision and grid point on every scene of the type).
std::string sweep_case_key(const std::string& surface_type, const std::string& method);

// The sweep's groups on `scenes` (surface types in the order they first appear x methods) by key,
// each with its expected seconds on this machine (its grid on its scenes, and the re-checks).
std::vector<std::pair<std::string, double>> sweep_cases(const std::vector<Scene>& scenes,
                                                        const SweepOptions& options);

// The label of an offset rule on the grid's axis: "2xeps", or the fixed value ("0.01").
std::vector<std::string> offset_labels(const SweepOptions& options);

using SweepProgress = std::function<void(const std::string& line, int done, int total)>;

// Runs the grid on the scenes. Returns {"options", "points": one per scene x method x precision x
// eps x offset, "confirmations": the recommended points checked again at confirm_scale times the
// size (ordered by surface type, method and precision, each group's in the order made),
// "analysis": analyse_sweep(points, confirmations)}. Throws std::invalid_argument for an
// unknown or unavailable backend.
nlohmann::json run_sweep(const std::vector<Scene>& scenes, const SweepOptions& options,
                         conformance::Suite& suite, const SweepProgress& progress);

// The sweep of a sharded run, from its shards' points and re-checks, as run_sweep makes it
// unsharded: the points in its order (by `scenes`, then `methods`: the run's lists of names), the
// re-checks by group, the analysis made again; "options" as given.
nlohmann::json merged_sweep(const nlohmann::json& options, nlohmann::json points,
                            nlohmann::json confirmations, const nlohmann::json& scenes,
                            const nlohmann::json& methods);

// Merges the results of a sharded `flatmarch sweep` (each file's JSON, with its name for
// errors): checks that they are the shards 1..N of one run (check_shards) and that each holds
// the points of its own groups, and returns the whole sweep (merged_sweep) with merged_header's
// fields. Throws std::invalid_argument naming the file and why.
nlohmann::json merge_sweep(const std::vector<std::pair<std::string, nlohmann::json>>& files);

// Per surface type x method x precision: "grid" (per eps x offset: scenes whose conformance
// verdict is pass, at the method's limit, in error; the checks failed and the failure class
// counts over the scenes; "cause", the one that made the point unstable; mean time_ms,
// steps_mean, hit_mismatch; traces diverged, failures), "stable" (the grid points that pass on
// every scene, and in their re-check at a larger size if they had one), "pareto" (points no
// other beats on both time and hit mismatch), "recommended" ({eps, offset, offset_label,
// fallback: no stable neighbours, confirmed: its re-check or null, why}; null when nothing is
// stable). `confirmations` are run_sweep's re-checks.
nlohmann::json analyse_sweep(const nlohmann::json& points,
                             const nlohmann::json& confirmations = nlohmann::json::array());

}  // namespace flatmarch::reports
