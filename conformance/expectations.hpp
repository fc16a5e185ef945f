// Expectation files (docs/external.md), as Mesa's CI keeps them for deqp-runner: what a renderer
// is known to do, case by case, so that a run reports what changed rather than what is known.
// One line a case, `KEY,STATUS` (the case's renderer/method/scene and a verdict: Fail, Limit,
// Error, Crash, Timeout, Skip, ...); `flake REGEX` for cases whose result varies; `skip REGEX`
// for cases not to run; `#` starts a comment.
#pragma once

#include <filesystem>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace flatmarch::conformance {

// A case's key in an expectation file: RENDERER/METHOD/SCENE.
inline std::string case_key(const std::string& renderer, const std::string& method,
                            const std::string& scene) {
  return renderer + "/" + method + "/" + scene;
}

class Expectations {
 public:
  Expectations() = default;
  // Throws std::invalid_argument "FILE:LINE: what is wrong".
  static Expectations read(const std::filesystem::path& file);

  // The verdict expected of a case ("pass" where the file does not list it).
  std::string expected(const std::string& key) const;
  bool flaky(const std::string& key) const;
  bool skipped(const std::string& key) const;
  // How a case's verdict (or "skip") stands against the file: "expected", "flake" (a flaky case,
  // whatever its verdict), "unexpected pass" (listed as not passing, and passes), "unexpected
  // fail" (expected to pass, and does not) or "unexpected VERDICT" (another status than the
  // listed one).
  std::string outcome(const std::string& key, const std::string& verdict) const;
  // Whether an outcome is a change to report.
  static bool change(const std::string& outcome) {
    return outcome != "expected" && outcome != "flake";
  }
  const std::string& file() const { return file_; }
  // The listed cases no case of the run had: a stale line, to say.
  std::vector<std::string> unseen(const std::vector<std::string>& keys) const;

 private:
  std::string file_;
  std::map<std::string, std::string> statuses_;
  std::vector<std::pair<std::string, std::regex>> flakes_, skips_;
};

// A run's cases of one renderer (key and verdict, "skip" for a case it could not render) against
// its file: {"file", "cases": {KEY: {"expected", "outcome"}}, "changes": ["KEY: OUTCOME (expected
// VERDICT)"], "unseen": [listed keys the run did not have]}.
nlohmann::json expectation_outcomes(const Expectations& e,
                                    const std::vector<std::pair<std::string, std::string>>& run);

}  // namespace flatmarch::conformance
