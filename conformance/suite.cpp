#include "conformance/suite.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <sstream>

#include <tbb/parallel_for.h>

#include "backends/scalar/scalar.hpp"
#include "conformance/external.hpp"
#include "conformance/vocabulary.hpp"
#include "scene/scene.hpp"

namespace flatmarch::conformance {

namespace {

using nlohmann::json;

// Whether the oracle's path keeps `margin` from every vertex and crosses every edge at a sine of
// at least `min_sine`.
bool generic(const Scene& scene, const OracleResult& r, double margin, double min_sine) {
  const double horizon = r.trace.events.empty() ? 0.0 : r.trace.events.back().t;
  double t = 0.0;
  for (const PathSegment& seg : r.path) {
    if (t > horizon) break;
    const Vec3 step = seg.to - seg.from;
    t += glm::length(step);
    const Polygon& polygon = scene.polygons[static_cast<size_t>(seg.polygon)];
    for (int v = 0; v < polygon.size(); ++v) {
      if (!polygon.is_ideal(v) &&
          distance_to_segment(polygon.vertex(v), Vec2(seg.from), Vec2(seg.to)) < margin)
        return false;
      const Edge& edge = polygon.edges[static_cast<size_t>(v)];
      const bool ends_on_edge = edge.distance(Vec2(seg.to)) < 1e-9;
      if (ends_on_edge && glm::length(step) > 0.0 &&
          std::abs(glm::dot(Vec2(step), edge.normal)) < min_sine * glm::length(step))
        return false;
    }
  }
  return true;
}

std::string key(const Scene& scene, const MarchParams& p, int width, int height, bool method) {
  std::ostringstream s;
  s.precision(17);
  s << scene.name << "|" << width << "x" << height << "|" << p.eps << "|" << p.offset << "|"
    << p.max_distance << "|" << static_cast<int>(p.precision);
  if (method) s << "|" << static_cast<int>(p.method) << "|" << p.max_steps << "|" << p.omega;
  return s.str();
}

void add_check(CaseResult& r, const std::string& name, double value, double limit, bool at_least) {
  const bool passed = at_least ? value >= limit : value <= limit;
  r.checks.push_back({name, value, limit, at_least, passed});
  r.passed &= passed;
}

std::string percent(double share) {
  std::ostringstream s;
  s.precision(3);
  s << 100.0 * share << "%";
  return s.str();
}

// The verdict of a case whose checks are in. A method's documented failure modes (DESIGN.md
// section 3): with offset <= eps, sphere and relaxed tracing cross back and forth at every gluing
// until max_steps; a ray that needs more than max_steps steps ends with max_steps; and the
// re-entry push moves each ray sideways at every crossing, so that after dozens of them (a
// translation prism's rays cross a room every unit or two) the mask cannot decide as many
// pixels as for a method without it. A case is at its method's limit when every check it fails
// is one that these modes fail, by no more than they account for: hit and crossings agreement
// short of the threshold by at most the stuck share, colour off on at most that many more pixels
// (a stuck ray is shaded as fog), the step distribution (stuck rays take max_steps), and an
// ambiguous share over the threshold only where, without the push, it would be within it
// (`unpushed_ambiguous`, the mask's share for the same scene without a push).
void judge(CaseResult& r, double unpushed_ambiguous) {
  if (r.passed) {
    r.verdict = Verdict::pass;
    return;
  }
  r.verdict = Verdict::fail;
  const Method m = r.params.method;
  if (m == Method::analytic) return;  // no steps to run out of between walls, no push
  const double decided = static_cast<double>(std::max<size_t>(r.aov.decided(), 1));
  const double stuck_pixels =
      static_cast<double>(r.aov.failures[static_cast<size_t>(Failure::stuck)]);
  const double stuck = stuck_pixels / decided;
  const double stuck_percent =
      100.0 * stuck_pixels / static_cast<double>(std::max<size_t>(r.aov.pixels, 1));
  bool drift = false;
  for (const Check& c : r.checks) {
    if (c.passed) continue;
    const bool pushed = c.name == "ambiguous" && unpushed_ambiguous <= c.limit;
    drift |= pushed;
    const bool explained =
        pushed || c.name == "failures.stuck" || c.name == "steps.ks" ||
        c.name == "steps.mean_ratio" ||
        ((c.name == "hit_rate" || c.name == "crossings_rate") && c.value + stuck >= c.limit) ||
        ((c.name == "image.failpercent" || c.name == "image.perceptual_failpercent") &&
         c.value - stuck_percent <= c.limit);
    if (!explained) return;
  }
  const bool crossing_back = r.params.offset <= r.params.eps;
  if (stuck == 0.0 && !crossing_back && !drift) return;
  r.verdict = Verdict::limit;
  std::ostringstream s;
  s << to_string(m) << ": ";
  std::string sep;
  if (stuck > 0.0 || !drift) {
    s << percent(stuck) << " of the decided pixels ran out of steps (max_steps "
      << r.params.max_steps << ")";
    sep = "; ";
  }
  if (crossing_back)
    s << ", offset " << r.params.offset << " <= eps " << r.params.eps
      << " (rays cross each gluing back and forth)";
  if (drift) {
    s << sep << "the re-entry push's sideways drift leaves "
      << percent(static_cast<double>(r.aov.ambiguous) /
                 static_cast<double>(std::max<size_t>(r.aov.pixels, 1)))
      << " of the pixels undecided (" << percent(unpushed_ambiguous) << " without the push)";
  }
  s << "; this method cannot render this scene at these parameters";
  r.limit = s.str();
}

}  // namespace

const char* to_string(Verdict v) {
  switch (v) {
    case Verdict::pass:
      return kVerdictPass;
    case Verdict::limit:
      return kVerdictLimit;
    case Verdict::fail:
      return kVerdictFail;
  }
  return "?";
}

std::vector<uint8_t> classify_pixels(const Frame& got, const Frame& truth,
                                     const std::vector<uint8_t>& ambiguity,
                                     const std::vector<uint8_t>& colour_failing) {
  std::vector<uint8_t> classes(truth.hit.size(), kPixelAgrees);
  for (size_t px = 0; px < classes.size() && px < got.hit.size(); ++px) {
    const auto f = classify(static_cast<int>(got.hit[px]), static_cast<int>(got.crossings[px]),
                            static_cast<int>(truth.hit[px]), static_cast<int>(truth.crossings[px]));
    if (px < ambiguity.size() && ambiguity[px])
      classes[px] = kPixelAmbiguous;
    else if (f)
      classes[px] = static_cast<uint8_t>(kPixelFailure + static_cast<int>(*f));
    else if (px < colour_failing.size() && colour_failing[px])
      classes[px] = kPixelColour;
  }
  return classes;
}

Frame error_image(const std::vector<uint8_t>& classes, const Frame& truth) {
  Frame image(truth.width, truth.height);
  const auto words = pixel_class_words();
  for (size_t px = 0; px < classes.size() && px < truth.hit.size(); ++px) {
    float* out = &image.rgb[3 * px];
    if (classes[px] == kPixelAgrees) {
      const float luma = 0.2126f * truth.rgb[3 * px] + 0.7152f * truth.rgb[3 * px + 1] +
                         0.0722f * truth.rgb[3 * px + 2];
      out[0] = out[1] = out[2] = 0.01f + 0.3f * std::clamp(luma, 0.0f, 1.0f);
    } else {
      const PixelClassWord& w = words[std::min<size_t>(classes[px], words.size() - 1)];
      for (size_t c = 0; c < 3; ++c)
        out[c] = static_cast<float>(decode_srgb(static_cast<double>(w.srgb[c]) / 255.0));
    }
    image.hit[px] = static_cast<float>(classes[px]);
  }
  return image;
}

std::string error_legend() {
  std::string s;
  for (const PixelClassWord& w : pixel_class_words())
    s += std::string(s.empty() ? "" : "; ") + w.colour + ": " + w.name + " (" + w.meaning + ")";
  return s;
}

std::vector<std::string> CaseResult::failed_checks() const {
  std::vector<std::string> lines;
  for (const Check& c : checks)
    if (!c.passed) {
      std::ostringstream s;
      s << c.name << " " << c.value << (c.at_least ? " < " : " > ") << c.limit;
      lines.push_back(s.str());
    }
  return lines;
}

std::vector<Ray> probe_rays(const Scene& scene, int count, int events) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double top = scene.period ? *scene.period : scene.height;
  std::vector<Ray> rays;
  for (int attempt = 0; attempt < 100 * count && static_cast<int>(rays.size()) < count; ++attempt) {
    const int p = static_cast<int>(unit(rng) * static_cast<double>(scene.polygons.size()));
    const Polygon& polygon = scene.polygons[static_cast<size_t>(p)];
    // Within the polygon's box; an unbounded one's cut off a few units of scale out.
    const std::vector<Vec2> outline = polygon.outline(4.0 * scene.scale);
    Vec2 lo = outline[0], hi = lo;
    for (const Vec2& v : outline) lo = glm::min(lo, v), hi = glm::max(hi, v);
    const Vec2 xy = lo + Vec2(unit(rng), unit(rng)) * (hi - lo);
    if (!polygon.contains(xy, 0.05 * scene.scale)) continue;
    const double angle = 2.0 * kPi * unit(rng);
    const Ray ray{p, Vec3(xy, top * (0.3 + 0.4 * unit(rng))),
                  Vec3(std::cos(angle), std::sin(angle), 0.05 * (unit(rng) - 0.5))};
    bool inside_object = false;
    for (const Object& o : scene.objects)
      inside_object |= o.polygon == p && glm::length(Vec2(ray.from) - Vec2(o.center)) <
                                             o.footprint_radius() + 0.05 * scene.scale;
    if (inside_object) continue;
    const OracleResult r =
        oracle_trace(scene, ray, {}, {.max_events = events, .record_path = true});
    if (generic(scene, r, 0.01 * scene.scale, 0.05)) rays.push_back(ray);
  }
  return rays;
}

Suite::Suite(json thresholds) : thresholds_(std::move(thresholds)) {}

const FrameTruth& Suite::truth(const Scene& scene, const MarchParams& params, int width,
                               int height) {
  // The mask depends on the method: the analytic method crosses edges without a push.
  MarchParams masked = params;
  if (mask_) {
    masked.eps = mask_->eps;
    masked.offset = mask_->offset;
  }
  const std::string k = key(scene, masked, width, height, true);
  auto it = truths_.find(k);
  if (it == truths_.end())
    it = truths_.emplace(k, frame_truth(scene, scene.camera, width, height, masked)).first;
  return it->second;
}

namespace {

// The parameters of a case's steps reference: its own in float64.
MarchParams reference_params(const MarchParams& params) {
  MarchParams p = params;
  p.precision = Precision::f64;
  return p;
}

}  // namespace

const Frame& Suite::reference(const Scene& scene, const MarchParams& params, int width,
                              int height) {
  const MarchParams p = reference_params(params);
  const std::string k = key(scene, p, width, height, true);
  auto it = references_.find(k);
  if (it == references_.end())
    it = references_.emplace(k, ScalarBackend().render(scene, scene.camera, width, height, p, {}))
             .first;
  return it->second;
}

void Suite::prepare_references(const Scene& scene, const std::vector<MarchParams>& params,
                               int width, int height) {
  std::vector<std::pair<std::string, MarchParams>> missing;
  for (const MarchParams& each : params) {
    const MarchParams p = reference_params(each);
    std::string k = key(scene, p, width, height, true);
    if (!references_.count(k) &&
        std::none_of(missing.begin(), missing.end(), [&](const auto& m) { return m.first == k; }))
      missing.emplace_back(std::move(k), p);
  }
  std::vector<Frame> frames(missing.size());
  tbb::parallel_for(size_t{0}, missing.size(), [&](size_t i) {
    frames[i] = ScalarBackend().render(scene, scene.camera, width, height, missing[i].second, {});
  });
  for (size_t i = 0; i < missing.size(); ++i)
    references_.emplace(std::move(missing[i].first), std::move(frames[i]));
}

const std::vector<std::pair<Ray, Trace>>& Suite::probes(const Scene& scene, int count, int events,
                                                        double max_distance) {
  std::ostringstream k;
  k.precision(17);
  k << scene.name << "|" << count << "|" << events << "|" << max_distance;
  auto it = probes_.find(k.str());
  if (it == probes_.end()) {
    MarchParams exact;  // the oracle, as far as the case's rays go
    exact.method = Method::oracle;
    exact.max_distance = max_distance;
    exact.max_steps = 100000;
    std::vector<std::pair<Ray, Trace>> list;
    for (const Ray& ray : probe_rays(scene, count, events))
      list.emplace_back(ray, oracle_trace(scene, ray, exact, {.max_events = events}).trace);
    it = probes_.emplace(k.str(), std::move(list)).first;
  }
  return it->second;
}

CaseResult Suite::run(const Backend& backend, const Scene& scene, const MarchParams& asked,
                      int width, int height) {
  CaseResult r;
  r.backend = backend.name();
  r.scene = scene.name;
  // A renderer we did not write is judged as marching with the parameters it has built in, and
  // on what it gives (ExternalInfo): what it does not give is left unmeasured, saying why.
  const ExternalInfo* external = backend.external();
  const MarchParams params = external ? external->marches_with(asked) : asked;
  const auto unmeasured = [&](const std::string& check, const std::string& why) {
    r.unmeasured.push_back(check);
    r.unmeasured_why[check] = why;
  };
  r.params = params;
  r.width = width;
  r.height = height;
  r.thresholds = thresholds_for(thresholds_, r.backend, params.method, scene.name);
  const Thresholds& t = r.thresholds;

  const FrameTruth& exact = truth(scene, params, width, height);
  r.delta = exact.delta;
  const auto started = std::chrono::steady_clock::now();
  Frame got = backend.render(scene, scene.camera, width, height, params, {});
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (external) {
    r.external = *external;
    if (const std::optional<double> s = backend.last_frame_seconds()) r.seconds = *s;
    // A channel it does not give is the truth's, so that the others are compared on their own.
    const std::string own = "its manifest does not list ";
    if (!external->hit) {
      got.hit = exact.frame.hit;
      for (const char* check : {"hit_rate", "failures"}) unmeasured(check, own + "hit");
    }
    if (!external->crossings) {
      got.crossings = exact.frame.crossings;
      unmeasured("crossings_rate", own + "crossings");
    }
    if (!external->t) {
      got.t = exact.frame.t;
      unmeasured("t.exceeded", own + "t");
    }
    if (!external->steps) std::fill(got.steps.begin(), got.steps.end(), 0.0f);
  }

  r.aov = compare_aovs(got, exact, scene.scale);
  const double pixels = static_cast<double>(r.aov.pixels);
  const double decided = static_cast<double>(std::max<size_t>(r.aov.decided(), 1));
  const auto measured = [&](const std::string& check) {
    return std::find(r.unmeasured.begin(), r.unmeasured.end(), check) == r.unmeasured.end();
  };
  if (measured("hit_rate")) add_check(r, "hit_rate", r.aov.hit_rate(), t.hit_rate, true);
  if (measured("crossings_rate"))
    add_check(r, "crossings_rate", r.aov.crossings_rate(), t.crossings_rate, true);
  add_check(r, "ambiguous", static_cast<double>(r.aov.ambiguous) / pixels, t.ambiguous_max, false);
  if (measured("t.exceeded"))
    add_check(r, "t.exceeded", r.aov.t_exceeded_share(), t.t_exceeded_max, false);
  if (!external) add_check(r, "most_steps", r.aov.most_steps, params.max_steps, false);
  if (measured("failures"))
    for (int c = 0; c < kFailureClasses; ++c)
      add_check(r, std::string("failures.") + to_string(static_cast<Failure>(c)),
                static_cast<double>(r.aov.failures[static_cast<size_t>(c)]) / decided,
                t.failure_max[static_cast<size_t>(c)], false);

  // The truth's colours in the look the renderer declares.
  const Frame& truth_colour =
      external ? looked(scene, params, width, height, external->look) : exact.frame;
  const bool colour = !external || external->colour;
  if (!colour) {
    got.rgb = truth_colour.rgb;
    for (const char* check : {"image", "colour"})
      unmeasured(check, external->look == "none" ? "its manifest's look is none"
                                                 : "its manifest does not list colour");
  }
  r.image = compare_images(got, truth_colour, exact.ambiguity, t.image, /*perceptual=*/false);
  if (colour) {
    add_check(r, "image.failpercent", 100.0 * static_cast<double>(r.image.fail) / pixels,
              t.image.failpercent, false);
    add_check(r, "image.max_error", r.image.max_error, t.image.hardfail, false);
  }
  // Yee's metric runs on a thread of its own while the rest is measured; the checks are added in
  // their order once it is done.
  std::optional<PerceptualCheck> perceptual;
  if (colour) perceptual.emplace(got, truth_colour, exact.ambiguity);
  std::vector<uint8_t> colour_failing;
  r.regions = compare_regions(got, truth_colour, exact.ambiguity, t.colour,
                              static_cast<int>(scene.objects.size()), &colour_failing);
  if (!colour) r.regions.clear();
  if (keep_classes_)
    r.pixel_classes = classify_pixels(got, exact.frame, exact.ambiguity, colour_failing);
  r.steps = step_stats(got.steps);

  int diverged = 0;
  double trace_error = 0.0;
  if (!external) {
    const Frame& ref = reference(scene, params, width, height);
    r.reference_steps = step_stats(ref.steps);
    r.steps_ks = ks_statistic(got.steps, ref.steps);
    for (const auto& [ray, want] :
         probes(scene, t.probe_rays, t.trace_events, params.max_distance)) {
      const Trace trace = backend.trace(scene, ray, params, t.trace_events);
      TraceComparison c = compare_traces(scene, trace, want, params.eps);
      if (c.failure) {
        ++diverged;
        ++r.trace_failures[static_cast<size_t>(*c.failure)];
      }
      trace_error = std::max({trace_error, c.max_t_error, c.max_position_error});
      r.traces.push_back(std::move(c));
    }
  }

  if (!perceptual) {
  } else if (perceptual->finish(r.image, t.image); r.image.perceptual_measured)
    add_check(r, "image.perceptual_failpercent",
              100.0 * static_cast<double>(r.image.perceptual) / pixels,
              t.image.perceptual_failpercent, false);
  else
    r.unmeasured.push_back("image.perceptual_failpercent");
  if (r.image.warned)
    r.warnings.push_back(std::to_string(r.image.warn) + " pixels differ by more than " +
                         std::to_string(t.image.warn));
  for (const RegionColour& region : r.regions) {
    std::string name = region.name();
    std::replace(name.begin(), name.end(), ' ', '_');
    const double n = static_cast<double>(std::max<size_t>(region.pixels, 1));
    add_check(r, "colour." + name, 100.0 * static_cast<double>(region.failed) / n,
              std::max(t.colour.failpercent, 100.0 * t.colour.allowed / n), false);
  }
  if (external) {
    // Its steps are its own loop's count, not our kernel's: shown, not compared.
    unmeasured("steps", external->steps ? "an external renderer's steps count its own loop"
                                        : "its manifest does not list steps");
    unmeasured("traces", "an external renderer traces no probe rays");
    judge(r, unpushed_ambiguity(r, scene, width, height));
    return r;
  }
  add_check(r, "steps.ks", r.steps_ks, t.steps_ks_max, false);
  const double ratio = r.reference_steps.mean > 0.0 ? r.steps.mean / r.reference_steps.mean : 1.0;
  add_check(r, "steps.mean_ratio", std::max(ratio, 1.0 / std::max(ratio, 1e-9)),
            t.steps_mean_ratio_max, false);
  add_check(r, "traces.diverged", diverged, t.trace_failures_max, false);
  add_check(r, "traces.error", trace_error / scene.scale, t.trace_error, false);
  if (static_cast<int>(r.traces.size()) < t.probe_rays)
    r.warnings.push_back("only " + std::to_string(r.traces.size()) + " generic probe rays found");
  judge(r, unpushed_ambiguity(r, scene, width, height));
  return r;
}

double Suite::unpushed_ambiguity(const CaseResult& r, const Scene& scene, int width, int height) {
  if (r.params.method == Method::analytic || r.passed) return 0.0;
  MarchParams analytic = r.params;
  analytic.method = Method::analytic;
  return static_cast<double>(truth(scene, analytic, width, height).ambiguous()) /
         static_cast<double>(std::max<size_t>(r.aov.pixels, 1));
}

const Frame& Suite::looked(const Scene& scene, const MarchParams& params, int width, int height,
                           const std::string& look) {
  const FrameTruth& exact = truth(scene, params, width, height);
  const std::string k = key(scene, params, width, height, false) + "|" + look;
  auto it = looks_.find(k);
  if (it == looks_.end()) {
    Frame frame = exact.frame;
    if (std::optional<Channel> rgb = look_colours(look, scene, scene.camera, width, height, params))
      frame.rgb = std::move(*rgb);
    it = looks_.emplace(k, std::move(frame)).first;
  }
  return it->second;
}

json unmeasured_json(const CaseResult& r) {
  json checks = json::array();
  for (const std::string& name : r.unmeasured)
    checks.push_back({{"check", name},
                      {"why", name == "image.perceptual_failpercent" ? r.image.perceptual_why
                              : r.unmeasured_why.count(name)         ? r.unmeasured_why.at(name)
                                                                     : std::string()}});
  return checks;
}

json to_json(const CaseResult& r) {
  json failures = json::object(), trace_failures = json::object();
  for (int c = 0; c < kFailureClasses; ++c) {
    failures[to_string(static_cast<Failure>(c))] = r.aov.failures[static_cast<size_t>(c)];
    trace_failures[to_string(static_cast<Failure>(c))] = r.trace_failures[static_cast<size_t>(c)];
  }
  const char* reasons[] = {"near_vertex", "near_edge",     "band_edge",
                           "silhouette",  "near_distance", "crease"};
  json ambiguity = json::object();
  for (size_t b = 0; b < r.aov.ambiguity_reasons.size(); ++b)
    ambiguity[reasons[b]] = r.aov.ambiguity_reasons[b];
  json confusion = json::array();
  for (const auto& [hits, count] : r.aov.confusion)
    confusion.push_back({{"oracle", hits.first}, {"got", hits.second}, {"pixels", count}});
  json traces = json::array();
  for (const TraceComparison& c : r.traces) {
    json tr = {{"compared", c.compared},
               {"first_divergence", c.first_divergence},
               {"max_t_error", c.max_t_error},
               {"max_position_error", c.max_position_error}};
    if (!c.divergence.empty()) tr["divergence"] = c.divergence;
    if (c.leak) tr["leak"] = c.leak_at;
    if (c.failure) tr["failure"] = to_string(*c.failure);
    traces.push_back(tr);
  }
  json colour = json::array();
  for (const RegionColour& c : r.regions)
    colour.push_back({{"region", c.name()},
                      {"pixels", c.pixels},
                      {"failed", c.failed},
                      {"worst_delta_e", c.worst},
                      {"worst_at", {c.worst_x, c.worst_y}},
                      {"passed", c.passed}});
  json checks = json::array();
  for (const Check& c : r.checks)
    checks.push_back({{"name", c.name},
                      {"value", c.value},
                      {"limit", c.limit},
                      {"at_least", c.at_least},
                      {"passed", c.passed}});
  const auto stats = [](const StepStats& s) {
    return json{{"mean", s.mean}, {"p50", s.p50}, {"p90", s.p90}, {"p99", s.p99}, {"max", s.max}};
  };
  return {
      {"backend", r.backend},
      {"scene", r.scene},
      {"method", to_string(r.params.method)},
      {"precision", r.params.precision == Precision::f32 ? "f32" : "f64"},
      {"eps", r.params.eps},
      {"offset", r.params.offset},
      {"max_steps", r.params.max_steps},
      {"max_distance", r.params.max_distance},
      {"size", std::to_string(r.width) + "x" + std::to_string(r.height)},
      {"passed", r.passed},
      {"verdict", to_string(r.verdict)},
      {"limit", r.limit},
      {"seconds", r.seconds},
      {"delta", r.delta},
      {"pixels", r.aov.pixels},
      {"ambiguous", r.aov.ambiguous},
      {"ambiguity", ambiguity},
      {"hit_rate", r.aov.hit_rate()},
      {"crossings_rate", r.aov.crossings_rate()},
      {"t",
       {{"compared", r.aov.t_compared}, {"exceeded", r.aov.t_exceeded}, {"worst", r.aov.t_worst}}},
      {"failures", failures},
      {"confusion", confusion},
      {"image",
       {{"mean_error", r.image.mean_error},
        {"rms_error", r.image.rms_error},
        {"psnr", r.image.psnr},
        {"max_error", r.image.max_error},
        {"max_at", {r.image.max_x, r.image.max_y}},
        {"warn", r.image.warn},
        {"fail", r.image.fail},
        {"perceptual", r.image.perceptual_measured ? json(r.image.perceptual) : json(nullptr)}}},
      {"steps", stats(r.steps)},
      {"reference_steps", stats(r.reference_steps)},
      {"steps_ks", r.steps_ks},
      {"traces", traces},
      {"trace_failures", trace_failures},
      {"checks", checks},
      {"colour", colour},
      {"warnings", r.warnings},
      {"unmeasured", unmeasured_json(r)},
      {"external", r.external ? external_json(*r.external) : json(nullptr)},
      {"thresholds", to_json(r.thresholds)}};
}

}  // namespace flatmarch::conformance
