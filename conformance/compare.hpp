// Comparing a backend's output with the truth: images, AOVs, step distributions, traces, and the
// class of every failure.
#pragma once

#include <array>
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "backends/backend.hpp"
#include "conformance/ambiguity.hpp"

namespace flatmarch::conformance {

// How a ray went wrong.
enum class Failure {
  stuck,          // ran out of steps where the oracle ended
  wrong_edge,     // crossed another edge than the oracle (at corners), or another number of them
  missed_object,  // the oracle hit an object; the ray did not (or hit another)
  phantom_hit,    // hit an object the oracle did not
  early_escape,   // escaped (or ran out of distance) where the oracle met a wall or the floor
  late_escape,    // met a wall or the floor where the oracle escaped
  leak            // a push landed outside the destination room (traces only)
};
inline constexpr int kFailureClasses = 7;
const char* to_string(Failure f);

using FailureCounts = std::array<size_t, kFailureClasses>;

// The class of a ray that ended with `hit` after `crossings` where the oracle's ended with
// `want` after `want_crossings`; nothing if they agree.
std::optional<Failure> classify(int hit, int crossings, int want, int want_crossings);

// --- Images, as OpenImageIO's idiff: a pixel fails when a channel differs by more than `fail`,
// warns above `warn`; the image fails when more than failpercent % of its pixels fail (or any
// pixel differs by more than hardfail), warns likewise. The perceptual metric is Yee's
// (ImageBufAlgo::compare_Yee): the share of pixels whose difference a viewer would see.
struct ImageThresholds {
  double fail = 0.05, failpercent = 1.0, hardfail = 1.0;
  double warn = 0.01, warnpercent = 5.0;
  double perceptual_failpercent = 1.0;
};

struct ImageComparison {
  double mean_error = 0.0, rms_error = 0.0, psnr = 0.0, max_error = 0.0;
  int max_x = 0, max_y = 0;       // where the largest difference is
  size_t warn = 0, fail = 0;      // pixels over the thresholds
  size_t perceptual = 0;          // pixels Yee's metric tells apart
  size_t pixels = 0, masked = 0;  // masked: ambiguous pixels, left out
  bool failed = false, warned = false, perceptual_failed = false;
};

// Colour (linear) of `got` against `truth`, leaving out pixels where `mask` is non-zero.
ImageComparison compare_images(const Frame& got, const Frame& truth,
                               const std::vector<uint8_t>& mask, const ImageThresholds& t);

// --- Step counts: their distribution against a reference's.
struct StepStats {
  double mean = 0.0, p50 = 0.0, p90 = 0.0, p99 = 0.0, max = 0.0;
};
StepStats step_stats(const Channel& steps);
// The two-sample Kolmogorov-Smirnov statistic: the largest gap between the two distributions'
// cumulative shares, in [0, 1].
double ks_statistic(const Channel& a, const Channel& b);

// --- AOVs against the oracle's, on the pixels the ambiguity mask leaves decided.
struct AovComparison {
  size_t pixels = 0, ambiguous = 0;
  size_t hit_equal = 0;        // decided pixels whose hit is the oracle's
  size_t crossings_equal = 0;  // decided pixels whose crossings are the oracle's
  // t on the decided pixels that end as the oracle's, at a surface or escaping: |t - t'| against
  // 1.25 times the truth's t_slack plus rounding, 64 u (t + scale) (steps + 1).
  size_t t_compared = 0, t_exceeded = 0;
  double t_worst = 0.0;                             // the largest |t - t'| / allowed
  FailureCounts failures{};                         // decided pixels, by class
  std::map<std::pair<int, int>, size_t> confusion;  // (oracle's hit, got) -> decided pixels
  std::array<size_t, kAmbiguityReasons>
      ambiguity_reasons{};  // pixels with each Ambiguity bit, in bit order
  float most_steps = 0.0f;
  size_t decided() const { return pixels - ambiguous; }
  double hit_rate() const;
  double crossings_rate() const;
  double t_exceeded_share() const;
};
AovComparison compare_aovs(const Frame& got, const FrameTruth& truth, double scale);

// --- Traces: the backend's events against the oracle's.
struct TraceComparison {
  int compared = 0;                 // events compared (the shorter list)
  int first_divergence = -1;        // index of the first event that differs in kind, room or edge
  std::string divergence;           // "got ... where the oracle has ..."
  double max_position_error = 0.0;  // |at - at'| over the agreeing crossings
  double max_t_error = 0.0;         // |t - t'| over the agreeing events
  bool length_differs = false;      // one list ended before the other did
  bool leak = false;                // an event lies outside its room (a push went astray)
  std::string leak_at;
  std::optional<Failure> failure;  // the class, when the traces disagree
};
// `eps` bounds how far outside its room an event may lie before it counts as a leak.
TraceComparison compare_traces(const Scene& scene, const Trace& got, const Trace& truth,
                               double eps);

// The hit code (as in the hit AOV) a final event stands for; nothing for a crossing.
std::optional<int> end_code(const Event& e);

// One line describing an event: kind, room, edge or object.
std::string describe(const Event& e);

}  // namespace flatmarch::conformance
