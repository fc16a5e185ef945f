#include "conformance/compare.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

#include "conformance/vocabulary.hpp"
#include "output/image_library.hpp"

namespace flatmarch::conformance {

namespace {

bool is_object(int hit) {
  return hit >= 0;
}
bool is_escape(int hit) {
  return hit == kHitEscape || hit == kHitMiss || hit == kHitMaxDistance;
}

double quantile(const std::vector<float>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const size_t k = std::min(
      sorted.size() - 1,
      static_cast<size_t>(std::ceil(q * static_cast<double>(sorted.size()))) - (q > 0.0 ? 1 : 0));
  return static_cast<double>(sorted[k]);
}

}  // namespace

const char* to_string(Failure f) {
  const auto classes = failure_words();
  const auto k = static_cast<size_t>(f);
  return k < classes.size() ? classes[k].name : "?";
}

std::optional<int> end_code(const Event& e) {
  switch (e.kind) {
    case EventKind::object:
      return e.object;
    case EventKind::wall:
      return kHitWall;
    case EventKind::floor:
      return kHitFloor;
    case EventKind::escape:
      return kHitEscape;
    case EventKind::vertex:
      return kHitVertex;
    case EventKind::max_steps:
      return kHitMaxSteps;
    case EventKind::max_distance:
      return kHitMaxDistance;
    case EventKind::miss:
      return kHitMiss;
    case EventKind::gluing:
    case EventKind::mirror:
    case EventKind::enter:
      return std::nullopt;
  }
  return std::nullopt;
}

std::optional<Failure> classify(int hit, int crossings, int want, int want_crossings) {
  if (hit == want && crossings == want_crossings) return std::nullopt;
  if (hit == kHitMaxSteps) return Failure::stuck;
  if (is_object(want) && hit != want) return Failure::missed_object;
  if (is_object(hit) && hit != want) return Failure::phantom_hit;
  if (is_escape(hit) && !is_escape(want)) return Failure::early_escape;
  if (is_escape(want) && !is_escape(hit)) return Failure::late_escape;
  return Failure::wrong_edge;  // the same end reached by another path, or another wall
}

namespace {

// `got`'s colours, where `mask` is non-zero the truth's: ambiguous pixels neither pass nor fail.
Frame masked_colours(const Frame& got, const Frame& truth, const std::vector<uint8_t>& mask,
                     size_t* masked) {
  Frame out;
  out.width = got.width;
  out.height = got.height;
  out.rgb = got.rgb;
  const size_t pixels = truth.rgb.size() / 3;
  for (size_t px = 0; px < mask.size() && px < pixels; ++px)
    if (mask[px]) {
      if (masked) ++*masked;
      for (size_t k = 0; k < 3; ++k) out.rgb[3 * px + k] = truth.rgb[3 * px + k];
    }
  return out;
}

}  // namespace

PerceptualCheck::PerceptualCheck(const Frame& got, const Frame& truth,
                                 const std::vector<uint8_t>& mask)
    : masked_(masked_colours(got, truth, mask, nullptr)) {
  // Yee's metric is OpenImageIO's alone: where the image module cannot be loaded it is not
  // measured, and the case says so (CaseResult::unmeasured).
  if (const ImageLibrary* images = image_library_if_loadable(&why_))
    count_ = std::async(std::launch::async,
                        [images, this, &truth] { return images->perceptual(masked_, truth); });
}

PerceptualCheck::~PerceptualCheck() {
  if (count_.valid()) count_.wait();  // it reads masked_
}

void PerceptualCheck::finish(ImageComparison& c, const ImageThresholds& t) {
  c.perceptual_measured = count_.valid();
  c.perceptual_why = why_;
  if (c.perceptual_measured) c.perceptual = count_.get();
  const double percent = 100.0 / static_cast<double>(std::max<size_t>(c.pixels, 1));
  c.perceptual_failed = c.perceptual_measured &&
                        static_cast<double>(c.perceptual) * percent > t.perceptual_failpercent;
}

ImageComparison compare_images(const Frame& got, const Frame& truth,
                               const std::vector<uint8_t>& mask, const ImageThresholds& t,
                               bool perceptual) {
  ImageComparison c;
  c.pixels = truth.rgb.size() / 3;
  const Frame masked = masked_colours(got, truth, mask, &c.masked);
  // idiff's figures (OpenImageIO's ImageBufAlgo::compare, as its documentation defines them): a
  // channel's difference |a - b|; a pixel warns, or fails, where one of its channels differs by
  // more than the threshold (a NaN difference too); the mean and RMS of the differences over
  // every channel, the PSNR against a peak of 1, and the largest difference with the first
  // pixel that has it. Summed in double, row by row (compare_test holds them to OpenImageIO's).
  double total = 0.0, squares = 0.0;
  const int width = std::max(truth.width, 1);
  for (size_t px = 0; px < c.pixels; ++px) {
    bool warned = false, failed = false;
    double row_total = 0.0, row_squares = 0.0;
    for (size_t k = 0; k < 3; ++k) {
      const double f = std::abs(masked.rgb[3 * px + k] - truth.rgb[3 * px + k]);
      row_total += f;
      row_squares += f * f;
      if (!(f <= c.max_error)) {
        c.max_error = f;
        c.max_x = static_cast<int>(px % static_cast<size_t>(width));
        c.max_y = static_cast<int>(px / static_cast<size_t>(width));
      }
      warned |= !(f <= t.warn);
      failed |= !(f <= t.fail);
    }
    total += row_total;
    squares += row_squares;
    c.warn += warned;
    c.fail += failed;
  }
  const double values = 3.0 * static_cast<double>(std::max<size_t>(c.pixels, 1));
  c.mean_error = total / values;
  c.rms_error = std::sqrt(squares / values);
  c.psnr = 20.0 * std::log10(1.0 / c.rms_error);
  const double percent = 100.0 / static_cast<double>(std::max<size_t>(c.pixels, 1));
  c.failed = static_cast<double>(c.fail) * percent > t.failpercent || c.max_error > t.hardfail;
  c.warned = static_cast<double>(c.warn) * percent > t.warnpercent;
  if (perceptual) PerceptualCheck(got, truth, mask).finish(c, t);
  return c;
}

namespace {

// CIELAB of a linear sRGB colour (D65 white).
std::array<double, 3> lab(const float* rgb) {
  const auto c = [&](int k) { return std::clamp(static_cast<double>(rgb[k]), 0.0, 1.0); };
  const double r = c(0), g = c(1), b = c(2);
  const double x = (0.4124564 * r + 0.3575761 * g + 0.1804375 * b) / 0.95047;
  const double y = 0.2126729 * r + 0.7151522 * g + 0.0721750 * b;
  const double z = (0.0193339 * r + 0.1191920 * g + 0.9503041 * b) / 1.08883;
  const auto f = [](double v) {
    constexpr double d = 6.0 / 29.0;
    return v > d * d * d ? std::cbrt(v) : v / (3.0 * d * d) + 4.0 / 29.0;
  };
  return {116.0 * f(y) - 16.0, 500.0 * (f(x) - f(y)), 200.0 * (f(y) - f(z))};
}

// CIE76's delta E: the distance of two CIELAB colours.
double lab_distance(const std::array<double, 3>& p, const std::array<double, 3>& q) {
  return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                   (p[2] - q[2]) * (p[2] - q[2]));
}

// The region a hit code belongs to: {region, object or marker index}; nothing for a ray that
// ended without a surface (max_steps, vertex).
std::optional<std::pair<Region, int>> region_of(int hit, int objects) {
  if (hit >= objects) return std::pair{Region::marker, hit - objects};
  if (hit >= 0) return std::pair{Region::object, hit};
  if (hit == kHitWall) return std::pair{Region::walls, 0};
  if (hit == kHitFloor) return std::pair{Region::floor, 0};
  if (is_escape(hit)) return std::pair{Region::sky, 0};
  return std::nullopt;
}

}  // namespace

double delta_e(const float* a, const float* b) {
  return lab_distance(lab(a), lab(b));
}

std::string RegionColour::name() const {
  switch (region) {
    case Region::object:
      return "object " + std::to_string(hit);
    case Region::marker:
      return "marker " + std::to_string(hit);
    case Region::walls:
      return "walls";
    case Region::floor:
      return "floor";
    case Region::sky:
      return "sky";
  }
  return "?";
}

std::vector<RegionColour> compare_regions(const Frame& got, const Frame& truth,
                                          const std::vector<uint8_t>& mask,
                                          const ColourThresholds& t, int objects,
                                          std::vector<uint8_t>* failing) {
  std::map<std::pair<Region, int>, RegionColour> regions;
  if (failing) failing->assign(truth.hit.size(), 0);
  // Each pixel's region and CIELAB colours once, not once for each of its nine neighbourhoods
  // (three cube roots a colour: 70% of a 160x90 comparison's time). The same numbers as
  // delta_e's.
  const size_t pixels = truth.hit.size();
  std::vector<std::optional<std::pair<Region, int>>> keys(pixels);
  std::vector<std::array<double, 3>> got_lab(pixels), truth_lab(pixels);
  for (size_t px = 0; px < pixels; ++px) {
    keys[px] = region_of(static_cast<int>(truth.hit[px]), objects);
    if (keys[px]) truth_lab[px] = lab(&truth.rgb[3 * px]);
  }
  for (int j = 0; j < truth.height; ++j)
    for (int i = 0; i < truth.width; ++i) {
      const size_t px = truth.pixel(i, j);
      const int want = static_cast<int>(truth.hit[px]);
      const auto& key = keys[px];
      if (!key || (px < mask.size() && mask[px]) || static_cast<int>(got.hit[px]) != want ||
          got.crossings[px] != truth.crossings[px])
        continue;
      RegionColour& r = regions[*key];
      r.region = key->first;
      r.hit = key->second;
      ++r.pixels;
      got_lab[px] = lab(&got.rgb[3 * px]);
      double nearest = std::numeric_limits<double>::infinity();
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const int x = i + di, y = j + dj;
          if (x < 0 || y < 0 || x >= truth.width || y >= truth.height) continue;
          const size_t q = truth.pixel(x, y);
          if (keys[q] != key) continue;
          nearest = std::min(nearest, lab_distance(got_lab[px], truth_lab[q]));
        }
      if (nearest > t.delta_e) {
        ++r.failed;
        if (failing) (*failing)[px] = 1;
      }
      if (nearest > r.worst) {
        r.worst = nearest;
        r.worst_x = i;
        r.worst_y = j;
      }
    }
  std::vector<RegionColour> out;
  for (auto& [key, r] : regions) {
    r.passed =
        r.failed <= static_cast<size_t>(t.allowed) ||
        100.0 * static_cast<double>(r.failed) <= t.failpercent * static_cast<double>(r.pixels);
    out.push_back(r);
  }
  return out;
}

StepStats step_stats(const Channel& steps) {
  StepStats s;
  if (steps.empty()) return s;
  std::vector<float> sorted(steps.begin(), steps.end());
  std::sort(sorted.begin(), sorted.end());
  double sum = 0.0;
  for (float v : sorted) sum += static_cast<double>(v);
  s.mean = sum / static_cast<double>(sorted.size());
  s.p50 = quantile(sorted, 0.5);
  s.p90 = quantile(sorted, 0.9);
  s.p99 = quantile(sorted, 0.99);
  s.max = static_cast<double>(sorted.back());
  return s;
}

double ks_statistic(const Channel& a, const Channel& b) {
  if (a.empty() || b.empty()) return a.empty() == b.empty() ? 0.0 : 1.0;
  std::vector<float> x(a.begin(), a.end()), y(b.begin(), b.end());
  std::sort(x.begin(), x.end());
  std::sort(y.begin(), y.end());
  const double nx = static_cast<double>(x.size()), ny = static_cast<double>(y.size());
  size_t i = 0, k = 0;
  double gap = 0.0;
  while (i < x.size() && k < y.size()) {  // at each distinct value, both step functions' heights
    const float v = std::min(x[i], y[k]);
    while (i < x.size() && x[i] == v) ++i;
    while (k < y.size() && y[k] == v) ++k;
    gap = std::max(gap, std::abs(static_cast<double>(i) / nx - static_cast<double>(k) / ny));
  }
  return gap;
}

double AovComparison::hit_rate() const {
  return decided() ? static_cast<double>(hit_equal) / static_cast<double>(decided()) : 1.0;
}
double AovComparison::crossings_rate() const {
  return decided() ? static_cast<double>(crossings_equal) / static_cast<double>(decided()) : 1.0;
}

double AovComparison::t_exceeded_share() const {
  return t_compared ? static_cast<double>(t_exceeded) / static_cast<double>(t_compared) : 0.0;
}

AovComparison compare_aovs(const Frame& got, const FrameTruth& truth, double scale) {
  AovComparison c;
  c.pixels = truth.frame.hit.size();
  for (size_t px = 0; px < c.pixels; ++px) {
    c.most_steps = std::max(c.most_steps, got.steps[px]);
    const uint8_t bits = truth.ambiguity[px];
    for (size_t b = 0; b < c.ambiguity_reasons.size(); ++b)
      c.ambiguity_reasons[b] += (bits >> b) & 1u;
    if (bits & kPathAmbiguity) {
      ++c.ambiguous;
      continue;
    }
    const int hit = static_cast<int>(got.hit[px]), want = static_cast<int>(truth.frame.hit[px]);
    const int crossings = static_cast<int>(got.crossings[px]);
    const int want_crossings = static_cast<int>(truth.frame.crossings[px]);
    c.hit_equal += hit == want;
    c.crossings_equal += crossings == want_crossings;
    if (hit != want) ++c.confusion[{want, hit}];
    if (hit == want && crossings == want_crossings && hit != kHitMiss && hit != kHitMaxSteps &&
        hit != kHitVertex) {
      const double t = static_cast<double>(truth.frame.t[px]);
      const double allowed =
          1.25 * static_cast<double>(truth.t_slack[px]) +
          64.0 * truth.unit_roundoff * (t + scale) * (static_cast<double>(got.steps[px]) + 1.0);
      const double error = std::abs(static_cast<double>(got.t[px]) - t);
      ++c.t_compared;
      c.t_exceeded += error > allowed;
      c.t_worst = std::max(c.t_worst, error / allowed);
    }
    if (const auto f = classify(hit, crossings, want, want_crossings))
      ++c.failures[static_cast<size_t>(*f)];
  }
  return c;
}

std::string describe(const Event& e) {
  std::string s = std::string(to_string(e.kind)) + " p" + std::to_string(e.polygon);
  if (e.edge >= 0) s += " e" + std::to_string(e.edge);
  if (e.object >= 0) s += " o" + std::to_string(e.object);
  return s;
}

TraceComparison compare_traces(const Scene& scene, const Trace& got, const Trace& truth,
                               double eps) {
  TraceComparison c;
  const auto& a = got.events;
  const auto& b = truth.events;
  c.compared = static_cast<int>(std::min(a.size(), b.size()));
  for (int i = 0; i < c.compared; ++i) {
    const Event &e = a[static_cast<size_t>(i)], &w = b[static_cast<size_t>(i)];
    if (describe(e) != describe(w) || e.to_polygon != w.to_polygon || e.to_edge != w.to_edge) {
      c.first_divergence = i;
      c.divergence = "event " + std::to_string(i) + ": got " + describe(e) +
                     " where the oracle has " + describe(w);
      break;
    }
    c.max_t_error = std::max(c.max_t_error, std::abs(e.t - w.t));
    if (e.kind == EventKind::gluing || e.kind == EventKind::mirror)
      c.max_position_error = std::max(c.max_position_error, glm::length(e.at - w.at));
  }
  c.length_differs = c.first_divergence < 0 && a.size() != b.size();
  // A leak: an event in the band that lies outside its room by more than the kernel's own reach.
  const double reach = 2.0 * eps + 1e-5 * scene.scale;
  for (size_t i = 0; i < a.size() && !c.leak; ++i) {
    const Event& e = a[i];
    if (e.polygon < 0 || e.polygon >= static_cast<int>(scene.polygons.size())) continue;
    if (!scene.in_band(e.at.z) || e.kind == EventKind::miss) continue;
    const Polygon& polygon = scene.polygons[static_cast<size_t>(e.polygon)];
    if (!polygon.contains(Vec2(e.at)) && polygon.distance_to_boundary(Vec2(e.at)) > reach) {
      c.leak = true;
      std::ostringstream s;
      s << "event " << i << " (" << describe(e) << ") lies "
        << polygon.distance_to_boundary(Vec2(e.at)) << " outside its room";
      c.leak_at = s.str();
    }
  }
  if (c.leak) {
    c.failure = Failure::leak;
  } else if (c.first_divergence >= 0) {
    const std::optional<int> hit = end_code(a[static_cast<size_t>(c.first_divergence)]);
    const std::optional<int> want = end_code(b[static_cast<size_t>(c.first_divergence)]);
    if (hit && want) {  // both ended, differently: as a pixel would be classed
      c.failure = classify(*hit, 0, *want, *hit == *want ? 1 : 0).value_or(Failure::wrong_edge);
    } else if (want) {  // the backend went on where the oracle ended
      c.failure = is_object(*want)   ? Failure::missed_object
                  : is_escape(*want) ? Failure::late_escape
                                     : Failure::wrong_edge;
    } else if (hit) {  // the backend ended where the oracle went on
      c.failure = *hit == kHitMaxSteps ? Failure::stuck
                  : is_object(*hit)    ? Failure::phantom_hit
                  : is_escape(*hit)    ? Failure::early_escape
                                       : Failure::wrong_edge;
    } else {  // both crossed, through different edges
      c.failure = Failure::wrong_edge;
    }
  } else if (c.length_differs) {
    c.failure = a.size() < b.size() && !a.empty() && a.back().kind == EventKind::max_steps
                    ? Failure::stuck
                    : Failure::wrong_edge;
  }
  return c;
}

}  // namespace flatmarch::conformance
