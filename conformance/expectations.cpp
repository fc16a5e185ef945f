#include "conformance/expectations.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <stdexcept>

#include "conformance/vocabulary.hpp"

namespace flatmarch::conformance {

namespace {

std::string trimmed(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

Expectations Expectations::read(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::invalid_argument(file.string() + ": cannot read the expectation file");
  Expectations e;
  e.file_ = file.string();
  const std::vector<std::string> statuses = {kVerdictPass,        kVerdictLimit, kVerdictFail,
                                             kVerdictError,       kVerdictCrash, kVerdictTimeout,
                                             kVerdictOutOfMemory, "skip"};
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const std::string where = file.string() + ":" + std::to_string(number) + ": ";
    line = trimmed(line.substr(0, line.find('#')));
    if (line.empty()) continue;
    for (const char* kind : {"flake ", "skip "})
      if (line.rfind(kind, 0) == 0) {
        const std::string pattern = trimmed(line.substr(std::string(kind).size()));
        try {
          (kind[0] == 'f' ? e.flakes_ : e.skips_).emplace_back(pattern, std::regex(pattern));
        } catch (const std::regex_error& error) {
          throw std::invalid_argument(where + "\"" + pattern + "\" is not a regular expression (" +
                                      error.what() + ")");
        }
        line.clear();
      }
    if (line.empty()) continue;
    const size_t comma = line.rfind(',');
    if (comma == std::string::npos)
      throw std::invalid_argument(where + "\"" + line +
                                  "\": expected KEY,STATUS, flake REGEX or skip REGEX");
    const std::string key = trimmed(line.substr(0, comma));
    const std::string status = lower(trimmed(line.substr(comma + 1)));
    if (std::find(statuses.begin(), statuses.end(), status) == statuses.end())
      throw std::invalid_argument(where + "\"" + status +
                                  "\" is no status (pass, limit, fail, error, crash, timeout, "
                                  "out_of_memory, skip)");
    if (key.empty()) throw std::invalid_argument(where + "no case before the comma");
    if (!e.statuses_.emplace(key, status).second)
      throw std::invalid_argument(where + key + " is listed twice");
  }
  return e;
}

std::string Expectations::expected(const std::string& key) const {
  const auto it = statuses_.find(key);
  return it == statuses_.end() ? kVerdictPass : it->second;
}

bool Expectations::flaky(const std::string& key) const {
  return std::any_of(flakes_.begin(), flakes_.end(),
                     [&](const auto& f) { return std::regex_search(key, f.second); });
}

bool Expectations::skipped(const std::string& key) const {
  return std::any_of(skips_.begin(), skips_.end(),
                     [&](const auto& s) { return std::regex_search(key, s.second); });
}

std::string Expectations::outcome(const std::string& key, const std::string& verdict) const {
  if (flaky(key)) return "flake";
  const std::string want = expected(key);
  if (verdict == want) return "expected";
  return "unexpected " + verdict;  // "unexpected pass" where it was listed as failing
}

std::vector<std::string> Expectations::unseen(const std::vector<std::string>& keys) const {
  std::vector<std::string> stale;
  for (const auto& [key, status] : statuses_)
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) stale.push_back(key);
  return stale;
}

nlohmann::json expectation_outcomes(const Expectations& e,
                                    const std::vector<std::pair<std::string, std::string>>& run) {
  nlohmann::json cases = nlohmann::json::object(), changes = nlohmann::json::array();
  std::vector<std::string> keys;
  for (const auto& [key, verdict] : run) {
    keys.push_back(key);
    const std::string outcome = e.outcome(key, verdict);
    cases[key] = {{"expected", e.expected(key)}, {"outcome", outcome}};
    if (Expectations::change(outcome))
      changes.push_back(key + ": " + outcome + " (expected " + e.expected(key) + ")");
  }
  return {{"file", e.file()}, {"cases", cases}, {"changes", changes}, {"unseen", e.unseen(keys)}};
}

}  // namespace flatmarch::conformance
