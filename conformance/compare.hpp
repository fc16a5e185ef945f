// Comparing a backend's output with the truth: images, AOVs, step distributions, traces, and the
// class of every failure.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <future>
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
// (ImageBufAlgo::compare_Yee, through the image module): the share of pixels whose difference a
// viewer would see; not measured where the module cannot be loaded.
struct ImageThresholds {
  double fail = 0.05, failpercent = 1.0, hardfail = 1.0;
  double warn = 0.01, warnpercent = 5.0;
  double perceptual_failpercent = 1.0;
};

struct ImageComparison {
  double mean_error = 0.0, rms_error = 0.0, psnr = 0.0, max_error = 0.0;
  int max_x = 0, max_y = 0;   // where the largest difference is
  size_t warn = 0, fail = 0;  // pixels over the thresholds
  size_t perceptual = 0;      // pixels Yee's metric tells apart
  bool perceptual_measured = false;
  std::string perceptual_why;     // why not, where it was not
  size_t pixels = 0, masked = 0;  // masked: ambiguous pixels, left out
  bool failed = false, warned = false, perceptual_failed = false;
};

// Colour (linear) of `got` against `truth`, leaving out pixels where `mask` is non-zero. Without
// `perceptual`, Yee's metric is left to a PerceptualCheck.
ImageComparison compare_images(const Frame& got, const Frame& truth,
                               const std::vector<uint8_t>& mask, const ImageThresholds& t,
                               bool perceptual = true);

// Yee's metric of compare_images on a thread of its own, so that the rest of a case is measured
// meanwhile (42 ms of a 160x90 case on one core of a 2-vCPU Intel Xeon, Emerald Rapids; the
// traces, the steps reference and the regions take about as long). Begun where the image module
// loads; `truth` must outlive it.
class PerceptualCheck {
 public:
  PerceptualCheck(const Frame& got, const Frame& truth, const std::vector<uint8_t>& mask);
  PerceptualCheck(const PerceptualCheck&) = delete;
  PerceptualCheck& operator=(const PerceptualCheck&) = delete;
  ~PerceptualCheck();
  // Waits for it and puts it into `c` (perceptual, its measured, why and failed); once.
  void finish(ImageComparison& c, const ImageThresholds& t);

 private:
  Frame masked_;  // the colours compared: `got`'s, the masked pixels the truth's
  std::string why_;
  std::future<size_t> count_;  // none where the module does not load
};

// --- Colour per region (issue 22): over a whole frame a wrongly shaded object, a few percent of
// the pixels, hides under the image thresholds; judged over its own pixels it cannot. A region is
// an object or vertex marker (by its hit index), the walls, the floor or the sky (escape, miss,
// max_distance). A pixel is compared where the mask decides it and the backend's ray ended as the
// oracle's (same hit, same crossings: the others are failures of their own class). It fails when
// its colour differs by more than `delta_e` (CIE 1976 Delta E in CIELAB, of the tone-mapped
// linear colour, D65) from the oracle's at that pixel and at each of its 8 neighbours of the same
// region: a colour that an edge, a rim or a crease moves by less than a pixel is not a wrong
// shading, a wrong shading of a face is.
struct ColourThresholds {
  double delta_e = 6.0;      // a pixel's largest colour difference
  double failpercent = 2.0;  // of a region's compared pixels, at most
  int allowed = 2;           // failing pixels any region may have, whatever its size
};

enum class Region { object, marker, walls, floor, sky };
struct RegionColour {
  Region region = Region::object;
  int hit = 0;         // the object's or the vertex marker's index
  size_t pixels = 0;   // compared
  size_t failed = 0;   // over delta_e from every neighbour
  double worst = 0.0;  // the largest difference from the nearest neighbour's colour
  int worst_x = 0, worst_y = 0;
  bool passed = true;
  std::string name() const;  // "object 0", "marker 1", "walls", "floor", "sky"
};

// CIE 1976 Delta E between two linear sRGB colours (clamped to [0, 1]).
double delta_e(const float* a, const float* b);

// The regions of `truth`, compared as above; `failing`, when given, gets 1 at each failing pixel.
std::vector<RegionColour> compare_regions(const Frame& got, const Frame& truth,
                                          const std::vector<uint8_t>& mask,
                                          const ColourThresholds& t, int objects,
                                          std::vector<uint8_t>* failing = nullptr);

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
  size_t pixels = 0, ambiguous = 0;  // ambiguous: the path undecided (kPathAmbiguity)
  size_t hit_equal = 0;              // decided pixels whose hit is the oracle's
  size_t crossings_equal = 0;        // decided pixels whose crossings are the oracle's
  // t on the decided pixels that end as the oracle's, at a surface or escaping: |t - t'| against
  // 1.25 times the truth's t_slack plus rounding, 64 u (t + scale) (steps + 1).
  size_t t_compared = 0, t_exceeded = 0;
  double t_worst = 0.0;                             // the largest |t - t'| / allowed
  FailureCounts failures{};                         // decided pixels, by class
  std::map<std::pair<int, int>, size_t> confusion;  // (oracle's hit, got) -> decided pixels
  std::array<size_t, kAmbiguityReasons>
      ambiguity_reasons{};  // pixels with each Ambiguity bit, in bit order (creases too)
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
