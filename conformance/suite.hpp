// One conformance case: a backend, a scene, a method and its parameters, measured against the
// oracle — frame (hit, crossings, colour, steps) and probe-ray traces — and judged by the
// thresholds. The suite caches the truth (oracle frames, probe rays and their traces, the steps
// reference) across the cases that share it.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "conformance/ambiguity.hpp"
#include "conformance/compare.hpp"
#include "conformance/thresholds.hpp"

namespace flatmarch::conformance {

// One threshold checked: `value` against `limit` (`at_least`: value >= limit, else <=).
struct Check {
  std::string name;
  double value = 0.0, limit = 0.0;
  bool at_least = false;
  bool passed = true;
};

// A case's verdict (issue 22): it passes its thresholds; it fails them only through a
// documented failure mode of its method (rays out of max_steps, offset <= eps), by no more than
// that mode accounts for: a `limit` of the method, never a pass; or it fails.
enum class Verdict { pass, limit, fail };
const char* to_string(Verdict v);

struct CaseResult {
  std::string backend, scene;
  MarchParams params;
  int width = 0, height = 0;
  Thresholds thresholds;
  double delta = 0.0;  // the ambiguity mask's delta (ambiguity.hpp)
  AovComparison aov;
  ImageComparison image;
  std::vector<RegionColour> regions;  // colour per object, marker, walls, floor, sky
  StepStats steps, reference_steps;   // reference: the scalar backend in float64
  double steps_ks = 0.0;
  std::vector<TraceComparison> traces;
  FailureCounts trace_failures{};
  std::vector<Check> checks;
  // Checks left out where what they need is missing here (Yee's metric without the image
  // module: ImageComparison::perceptual_why), by name; the verdict is the other checks'.
  std::vector<std::string> unmeasured;
  std::map<std::string, std::string> unmeasured_why;  // where not the perceptual metric's
  // A renderer we did not write (Backend::external): what it is; `seconds` is its command's,
  // start-up and all.
  std::optional<ExternalInfo> external;
  std::vector<std::string> warnings;
  bool passed = true;  // every check within its threshold
  Verdict verdict = Verdict::pass;
  std::string limit;     // for Verdict::limit: the failure mode and its measured size
  double seconds = 0.0;  // the backend's frame
  // Why each pixel is off, row-major (PixelClass): filled when the suite keeps error images.
  std::vector<uint8_t> pixel_classes;
  // The checks that failed, one line each.
  std::vector<std::string> failed_checks() const;
};

// What a pixel of a case's error image shows: agreement, the mask's doubt, a colour beyond the
// region's tolerance, or the failure class (compare.hpp) of its ray, kPixelFailure + the class.
// Each has its name, meaning and colour in vocabulary.hpp (pixel_class_words(), in this order).
enum PixelClass : uint8_t {
  kPixelAgrees = 0,
  kPixelAmbiguous = 1,
  kPixelColour = 2,
  kPixelFailure = 3
};

// The class of each pixel of `got` against the oracle's frame `truth`, row-major: ambiguous where
// `ambiguity` says, else the failure class of its ray, else colour where `colour_failing` says
// (compare_regions), else agrees.
std::vector<uint8_t> classify_pixels(const Frame& got, const Frame& truth,
                                     const std::vector<uint8_t>& ambiguity,
                                     const std::vector<uint8_t>& colour_failing);

// The error image of a case from its pixel classes and the oracle's frame: the oracle's colour,
// dimmed to grey, where the pixel agrees; elsewhere its class's colour (pixel_class_words()).
// Its hit channel holds the pixel's class.
Frame error_image(const std::vector<uint8_t>& classes, const Frame& truth);
// The colours of error_image in words, one per class: "magenta: stuck (...)".
std::string error_legend();

// Nearly horizontal rays from random points of random rooms (a fixed seed), kept when their exact
// path up to `events` events keeps 1% of the scene's scale from every vertex and crosses every
// edge at a sine of at least 0.05: rays whose fate neither rounding nor eps can decide.
std::vector<Ray> probe_rays(const Scene& scene, int count, int events);

class Suite {
 public:
  explicit Suite(nlohmann::json thresholds = builtin_thresholds());
  // Runs one case at `width` x `height` with the scene's camera. Exceptions from the backend
  // (a failed compile, a validation message) propagate.
  CaseResult run(const Backend& backend, const Scene& scene, const MarchParams& params, int width,
                 int height);
  const nlohmann::json& thresholds() const { return thresholds_; }
  // Judges every later case against the oracle's truth masked as for `mask.eps` and
  // `mask.offset` (each case keeps its method and precision), not as for the case's own: a sweep
  // over eps and offset then measures each point against one truth, and a large eps cannot
  // widen the mask over the pixels it gets wrong.
  void fix_mask(const MarchParams& mask) { mask_ = mask; }
  // Draws the steps references (the scalar backend in float64, one thread each) of the cases
  // run() will be given with these parameters at this size, all cores at once: a sweep's points
  // are half their time in them on one core otherwise. The same frames run() would draw.
  void prepare_references(const Scene& scene, const std::vector<MarchParams>& params, int width,
                          int height);
  // How many steps references it holds.
  size_t references() const { return references_.size(); }
  // Keeps each case's pixel classes (CaseResult::pixel_classes) for an error image.
  void keep_pixel_classes(bool keep) { keep_classes_ = keep; }
  // The oracle's frame a case was judged against (run() computes it first).
  const Frame& truth_frame(const Scene& scene, const MarchParams& params, int width, int height) {
    return truth(scene, params, width, height).frame;
  }

 private:
  const FrameTruth& truth(const Scene& scene, const MarchParams& params, int width, int height);
  const Frame& reference(const Scene& scene, const MarchParams& params, int width, int height);
  const std::vector<std::pair<Ray, Trace>>& probes(const Scene& scene, int count, int events,
                                                   double max_distance);
  // The oracle's frame with its colours in `look` (external.hpp's look_colours).
  const Frame& looked(const Scene& scene, const MarchParams& params, int width, int height,
                      const std::string& look);
  // The ambiguous share of a case's frame had its method not pushed (judge's limit).
  double unpushed_ambiguity(const CaseResult& r, const Scene& scene, int width, int height);

  nlohmann::json thresholds_;
  std::optional<MarchParams> mask_;
  bool keep_classes_ = false;
  std::map<std::string, FrameTruth> truths_;
  std::map<std::string, Frame> references_;
  std::map<std::string, Frame> looks_;
  std::map<std::string, std::vector<std::pair<Ray, Trace>>> probes_;
};

nlohmann::json to_json(const CaseResult& r);
// The checks a case left out and why, [{"check", "why"}] (CaseResult::unmeasured).
nlohmann::json unmeasured_json(const CaseResult& r);

}  // namespace flatmarch::conformance
