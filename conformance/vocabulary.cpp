#include "conformance/vocabulary.hpp"

#include <algorithm>
#include <cstdio>
#include <iterator>
#include <vector>

#include "conformance/compare.hpp"
#include "conformance/suite.hpp"

namespace flatmarch::conformance {

namespace {

// Loud colours apart from the dimmed grey of agreement, each class its own.
constexpr PixelClassWord kPixelClasses[] = {
    {"agree",
     "",
     {128, 128, 128},
     "grey",
     false,
     "hit, crossings and colour as the oracle's (the oracle's image, dimmed to grey)"},
    {"ambiguous",
     "",
     {30, 40, 110},
     "dark blue",
     false,
     "the ambiguity mask leaves the pixel undecided: left out of every check"},
    {"colour",
     "",
     {255, 220, 0},
     "yellow",
     false,
     "the ray ended as the oracle's, but its colour differs from the oracle's beyond its region's "
     "tolerance (CIE Delta E)"},
    {"stuck",
     "st",
     {255, 0, 255},
     "magenta",
     false,
     "ran out of steps (max_steps) where the oracle's ray ended"},
    {"wrong_edge",
     "we",
     {255, 128, 0},
     "orange",
     false,
     "crossed another edge than the oracle's ray (at corners), or another number of edges"},
    {"missed_object",
     "mo",
     {255, 0, 0},
     "red",
     false,
     "the oracle's ray hit an object; this one did not, or hit another"},
    {"phantom_hit", "ph", {0, 255, 255}, "cyan", false, "hit an object the oracle's ray did not"},
    {"early_escape",
     "ee",
     {0, 220, 0},
     "green",
     false,
     "escaped (or ran out of distance) where the oracle's ray met a wall or the floor"},
    {"late_escape",
     "le",
     {80, 160, 255},
     "light blue",
     false,
     "met a wall or the floor where the oracle's ray escaped"},
    {"leak",
     "lk",
     {255, 255, 255},
     "white",
     true,
     "a push after a crossing landed outside the destination room (probe-ray traces only)"},
};
constexpr size_t kFirstFailure = kPixelFailure;
static_assert(std::size(kPixelClasses) == kFirstFailure + kFailureClasses,
              "a word for every failure class of compare.hpp, in its order");

// The checks of suite.cpp's Suite::run, in its order, the per-class ones after them (made from
// kPixelClasses).
constexpr Word kChecks[] = {
    {"hit_rate", "hr",
     "decided pixels whose hit (what ended the ray) is the oracle's, of the decided pixels"},
    {"crossings_rate", "cr",
     "decided pixels whose number of crossings is the oracle's, of the decided pixels"},
    {"ambiguous", "am", "pixels the ambiguity mask leaves undecided, of all the frame's pixels"},
    {"t.exceeded", "t",
     "decided pixels ending as the oracle's whose path length t is off by more than the method's "
     "slack, of those compared"},
    {"most_steps", "ms", "the most steps any ray of the frame took"},
    {"image.failpercent", "im",
     "% of the frame's pixels whose colour differs from the oracle's by more than 0.05 in a "
     "channel (undecided pixels left out)"},
    {"image.max_error", "mx", "the largest difference of a colour channel over the decided pixels"},
    {"image.perceptual_failpercent", "pe",
     "% of the frame's pixels Yee's perceptual metric tells apart from the oracle's (undecided "
     "pixels left out)"},
    {"steps.ks", "ks",
     "Kolmogorov-Smirnov distance between the frame's step counts and the scalar float64 "
     "reference's"},
    {"steps.mean_ratio", "sr",
     "mean steps against the scalar float64 reference's (the larger of the ratio and its "
     "inverse)"},
    {"traces.diverged", "tr", "probe rays whose list of events differs from the oracle's, a count"},
    {"traces.error", "te",
     "the largest position or t error over the probe rays' agreeing events, over the scene's "
     "scale"},
};

constexpr Word kCheckPrefixes[] = {
    {"colour.", "col",
     "% of the region's compared pixels (an object, a vertex marker, the walls, the floor or the "
     "sky; decided pixels whose ray ended as the oracle's) whose colour differs from the oracle's "
     "at that pixel and at its neighbours of the region by more than the CIE Delta E tolerance"},
};

constexpr Word kOtherCauses[] = {
    {"error", "err", "the backend failed to render"},
    {"confirmation", "rc", "passes at the sweep's size but fails its re-check at the larger size"},
};

constexpr VerdictWord kVerdicts[] = {
    {kVerdictPass, false, false, "every check within its threshold"},
    {kVerdictLimit, false, false,
     "fails the thresholds only through a documented failure mode of its method (rays out of "
     "max_steps, offset <= eps), by no more than that mode accounts for: never counted as a pass; "
     "ctest expects it and the regression gate holds it from getting worse"},
    {kVerdictFail, true, false, "beyond a threshold in any other way"},
    {kVerdictError, true, false, "the backend could not render or time the case"},
    {kVerdictCrash, true, true,
     "its worker process died while it ran (a signal, or an exit part way): the run went on in a "
     "fresh worker"},
    {kVerdictTimeout, true, true,
     "it overran its deadline (the cost model's time times --deadline-scale, at least "
     "--deadline-floor seconds) and its worker was ended"},
    {kVerdictOutOfMemory, true, true,
     "it ran out of the worker's address-space limit (--worker-memory)"},
};

constexpr double kNoGoal = -1.0;
constexpr AmbiguityGoal kAmbiguityGoals[] = {
    {"analytic", 0.05, 0.05},
    {"sphere", kNoGoal, 0.12},
    {"relaxed", kNoGoal, 0.12},
};

// The checks with the per-class ones after them, made once (their strings owned here).
struct Checks {
  std::vector<std::string> names, meanings;
  std::vector<Word> words;
  Checks() : words(std::begin(kChecks), std::end(kChecks)) {
    for (const PixelClassWord& c : failure_words()) {
      names.push_back(std::string("failures.") + c.name);
      meanings.push_back(c.traces_only ? std::string("always 0: ") + c.name +
                                             " is a class of the probe rays' traces, which no "
                                             "pixel has (traces.diverged counts them)"
                                       : std::string("decided pixels that ") + c.meaning +
                                             ", of the decided pixels");
    }
    for (size_t k = 0; k < names.size(); ++k)
      words.push_back({names[k].c_str(), "", meanings[k].c_str()});
  }
};

const std::vector<Word>& all_checks() {
  static const Checks checks;
  return checks.words;
}

const VerdictWord* find_verdict(const std::string& name) {
  for (const VerdictWord& v : kVerdicts)
    if (name == v.name) return &v;
  return nullptr;
}

nlohmann::json words_json(std::span<const Word> words, const char* key = "name") {
  nlohmann::json out = nlohmann::json::array();
  for (const Word& w : words)
    out.push_back({{key, w.name}, {"code", w.code}, {"meaning", w.meaning}});
  return out;
}

}  // namespace

std::span<const PixelClassWord> pixel_class_words() {
  return kPixelClasses;
}

std::span<const PixelClassWord> failure_words() {
  return std::span<const PixelClassWord>(kPixelClasses).subspan(kFirstFailure);
}

std::span<const Word> check_words() {
  return all_checks();
}
std::span<const Word> check_prefix_words() {
  return kCheckPrefixes;
}
std::span<const Word> other_cause_words() {
  return kOtherCauses;
}

const char* check_meaning(const std::string& name) {
  for (const Word& w : all_checks())
    if (name == w.name) return w.meaning;
  for (const Word& w : kCheckPrefixes)
    if (name.rfind(w.name, 0) == 0) return w.meaning;
  return nullptr;
}

std::span<const VerdictWord> verdict_words() {
  return kVerdicts;
}

bool is_bad_verdict(const std::string& verdict) {
  const VerdictWord* v = find_verdict(verdict);
  return v && v->bad;
}

bool is_unfinished_verdict(const std::string& verdict) {
  const VerdictWord* v = find_verdict(verdict);
  return v && v->unfinished;
}

std::span<const AmbiguityGoal> ambiguity_goals() {
  return kAmbiguityGoals;
}

nlohmann::json vocabulary_json() {
  using nlohmann::json;
  json classes = json::array();
  for (size_t k = 0; k < std::size(kPixelClasses); ++k) {
    const PixelClassWord& c = kPixelClasses[k];
    char hex[8];
    std::snprintf(hex, sizeof hex, "#%02x%02x%02x", c.srgb[0], c.srgb[1], c.srgb[2]);
    classes.push_back({{"name", c.name},
                       {"code", c.code},
                       {"colour", hex},
                       {"colour_name", c.colour},
                       {"failure", k >= kFirstFailure},
                       {"traces_only", c.traces_only},
                       {"meaning", c.meaning}});
  }
  json verdicts = json::array();
  for (const VerdictWord& v : kVerdicts)
    verdicts.push_back(
        {{"name", v.name}, {"bad", v.bad}, {"unfinished", v.unfinished}, {"meaning", v.meaning}});
  json goals = json::object();
  const auto goal = [](double g) { return g < 0.0 ? json(nullptr) : json(g); };
  for (const AmbiguityGoal& g : kAmbiguityGoals)
    goals[g.method] = {{"prism", goal(g.prism)}, {"other", goal(g.other)}};
  return {{"pixel_classes", classes},
          {"checks", words_json(check_words())},
          {"check_prefixes", words_json(kCheckPrefixes, "prefix")},
          {"other_causes", words_json(kOtherCauses)},
          {"verdicts", verdicts},
          {"ambiguity_goals", goals}};
}

}  // namespace flatmarch::conformance
