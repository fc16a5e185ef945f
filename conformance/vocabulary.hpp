// The suite's words, each with its one meaning: what a pixel of a case shows against the oracle
// (agreement, doubt, a colour off, or the failure class of its ray) and the colour every image
// of it takes, the checks a case is held to, the other causes a sweep names, the verdicts, and
// the goals for the ambiguous share. The error images (suite.hpp), the report's difference maps
// (reports/gallery.cpp) and the page (its tables, reports/page.cpp, and through them the
// template and charts) read them here; none restates them.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include <nlohmann/json.hpp>

namespace flatmarch::conformance {

// A class of pixel, in PixelClass's order (suite.hpp): agrees, ambiguous, colour, then the
// failure classes of rays in Failure's (compare.hpp).
struct PixelClassWord {
  const char* name;
  const char* code;             // in a sweep heatmap's cell where the class is a point's cause
  std::array<uint8_t, 3> srgb;  // its colour in error images and difference maps
  const char* colour;           // that colour's name, for a legend in words
  bool traces_only;             // a class of probe rays' traces, never of a frame's pixel
  const char* meaning;
};
std::span<const PixelClassWord> pixel_class_words();
// The failure classes alone (the entries after kPixelFailure), in Failure's order.
std::span<const PixelClassWord> failure_words();

// A check of a case (suite.cpp's add_check), or a family of them by its prefix ("colour." per
// region of the frame), or a cause of an unstable sweep point that is not a check ("error").
struct Word {
  const char* name;
  const char* code;
  const char* meaning;
};
// Every check a case can have, the per-class ones ("failures.stuck") among them, in order.
std::span<const Word> check_words();
std::span<const Word> check_prefix_words();
std::span<const Word> other_cause_words();
// The meaning of a check by its name or prefix; null where the name is none of them.
const char* check_meaning(const std::string& name);

// A case's verdict: the suite's three (Verdict), an error of the backend, or how a supervised
// case ended without finishing (reports/supervise.hpp).
inline constexpr const char* kVerdictPass = "pass";
inline constexpr const char* kVerdictLimit = "limit";
inline constexpr const char* kVerdictFail = "fail";
inline constexpr const char* kVerdictError = "error";
inline constexpr const char* kVerdictCrash = "crash";
inline constexpr const char* kVerdictTimeout = "timeout";
inline constexpr const char* kVerdictOutOfMemory = "out_of_memory";
struct VerdictWord {
  const char* name;
  bool bad;         // counted against a backend: fail, error and the unfinished
  bool unfinished;  // the case's worker did not finish it
  const char* meaning;
};
std::span<const VerdictWord> verdict_words();
// Whether `verdict` is a name of verdict_words() that is bad (or unfinished).
bool is_bad_verdict(const std::string& verdict);
bool is_unfinished_verdict(const std::string& verdict);

// The goal for the share of ambiguous pixels at the default parameters, per method, in
// translation prisms and elsewhere (negative: none), issue 22's.
struct AmbiguityGoal {
  const char* method;
  double prism, other;
};
std::span<const AmbiguityGoal> ambiguity_goals();

// All of the above, for results.json's "vocabulary": colours as "#rrggbb".
nlohmann::json vocabulary_json();

}  // namespace flatmarch::conformance
