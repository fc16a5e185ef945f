// What each backend and method must achieve, read from conformance/thresholds.json: defaults,
// overridden per method, then per backend, then by named exceptions (scene, method, backend),
// each applied as a JSON merge patch. The file is built into the program; --thresholds reads
// another.
#pragma once

#include <array>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "conformance/compare.hpp"

namespace flatmarch::conformance {

struct Thresholds {
  double hit_rate = 0.999;       // decided pixels whose hit is the oracle's, at least
  double crossings_rate = 0.99;  // decided pixels whose crossings are the oracle's, at least
  double ambiguous_max = 0.25;   // share of ambiguous pixels, at most
  double t_exceeded_max = 0.0;   // share of compared pixels whose t is off by more than allowed
  ImageThresholds image;
  ColourThresholds colour;             // per region: each object and marker, walls, floor, sky
  double steps_ks_max = 0.05;          // Kolmogorov-Smirnov statistic against the reference
  double steps_mean_ratio_max = 1.05;  // mean steps within this factor of the reference's
  int probe_rays = 8;                  // generic rays traced per case
  int trace_events = 20;               // events compared per probe ray
  int trace_failures_max = 0;          // probe rays whose trace may diverge
  double trace_error = 1e-2;           // largest |t - t'| and |at - at'|, in units of scene scale
  std::array<double, kFailureClasses> failure_max{};  // share of decided pixels per class
  std::string why;  // the method, backend and exception layers applied, and why
};

// The thresholds.json built into the program.
const nlohmann::json& builtin_thresholds();
// A thresholds file, checked: an unknown key or a value out of range is an error naming its path.
nlohmann::json load_thresholds(const std::filesystem::path& file);
// The thresholds for one case.
Thresholds thresholds_for(const nlohmann::json& doc, const std::string& backend, Method method,
                          const std::string& scene);

nlohmann::json to_json(const Thresholds& t);

}  // namespace flatmarch::conformance
