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
};

// The label of an offset rule on the grid's axis: "2xeps", or the fixed value ("0.01").
std::vector<std::string> offset_labels(const SweepOptions& options);

using SweepProgress = std::function<void(const std::string& line, int done, int total)>;

// Runs the grid on the scenes. Returns {"options", "points": one per scene x method x precision x
// eps x offset, "analysis": analyse_sweep(points)}. Throws std::invalid_argument for an unknown
// or unavailable backend.
nlohmann::json run_sweep(const std::vector<Scene>& scenes, const SweepOptions& options,
                         conformance::Suite& suite, const SweepProgress& progress);

// Per surface type x method x precision: "grid" (per eps x offset: scenes passed of scenes —
// every conformance check but the perceptual one, which small frames make noisy —
// mean time_ms, mean steps_mean, mean hit_mismatch, traces diverged, failures), "stable" (the
// grid points every scene passes), "pareto" (points no other beats on both time and hit
// mismatch), "recommended" ({eps, offset, offset_label, why}; null when nothing is stable).
nlohmann::json analyse_sweep(const nlohmann::json& points);

}  // namespace flatmarch::reports
