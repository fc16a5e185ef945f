#include "reports/estimate.hpp"

#include <algorithm>
#include <stdexcept>

namespace flatmarch::reports {

namespace {

std::vector<std::string> split(const std::string& key) {
  std::vector<std::string> parts;
  size_t from = 0;
  while (true) {
    const size_t slash = key.find('/', from);
    parts.push_back(
        key.substr(from, slash == std::string::npos ? std::string::npos : slash - from));
    if (slash == std::string::npos) return parts;
    from = slash + 1;
  }
}

}  // namespace

CaseGroups case_groups(const std::string& key) {
  const std::vector<std::string> p = split(key);
  if (p[0] == "matrix" && p.size() == 4) return {p[0], p[1], p[1] + "/" + p[2]};  // B/M/S
  if (p[0] == "sweep" && p.size() == 3) return {p[0], p[2], p[2]};                // T/M
  // A scaling series' family decides its cost more than its backend does.
  if (p[0] == "scaling" && p.size() == 4) return {p[0], p[1], p[1] + "/" + p[2]};  // F/B/M
  // Another kind of case (a conformance case, BACKEND/METHOD/SCENE/...): its first two words.
  return {"cases", p[0], p.size() > 1 ? p[0] + "/" + p[1] : p[0]};
}

std::vector<std::pair<std::string, double>> calibrating_order(
    const std::vector<std::pair<std::string, double>>& cases) {
  std::vector<std::string> stages;
  // Per stage, its groups in order of first appearance, each with its cases in order.
  std::map<std::string, std::vector<std::pair<std::string, std::vector<size_t>>>> groups;
  for (size_t k = 0; k < cases.size(); ++k) {
    const CaseGroups g = case_groups(cases[k].first);
    auto& in_stage = groups[g.stage];
    if (in_stage.empty()) stages.push_back(g.stage);
    auto it = std::find_if(in_stage.begin(), in_stage.end(),
                           [&](const auto& entry) { return entry.first == g.group; });
    if (it == in_stage.end()) it = in_stage.insert(in_stage.end(), {g.group, {}});
    it->second.push_back(k);
  }
  // Each group's cases spread evenly over its stage: the j-th of a group of n at (j + 1/2) / n,
  // so that any first part of the stage holds that part of every group's cases.
  std::vector<std::pair<std::string, double>> order;
  order.reserve(cases.size());
  for (const std::string& stage : stages) {
    std::vector<std::pair<double, size_t>> at;
    for (const auto& [group, members] : groups[stage])
      for (size_t j = 0; j < members.size(); ++j)
        at.emplace_back((static_cast<double>(j) + 0.5) / static_cast<double>(members.size()),
                        members[j]);
    std::stable_sort(at.begin(), at.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [position, k] : at) order.push_back(cases[k]);
  }
  return order;
}

StageEstimate::StageEstimate(const std::vector<std::pair<std::string, double>>& cases) {
  for (const auto& [key, cost] : cases) {
    if (!(cost >= 0.0)) throw std::invalid_argument("StageEstimate: a cost that is not >= 0");
    cost_[key] = cost;
  }
}

void StageEstimate::finished(const std::string& key, double seconds) {
  const auto it = cost_.find(key);
  if (it == cost_.end() || done_.count(key) || !(seconds >= 0.0)) return;
  done_[key] = seconds;
  spent_ += seconds;
  const CaseGroups g = case_groups(key);
  for (Rate* r : {&groups_[g.group], &subgroups_[g.subgroup], &stage_}) {
    r->seconds += seconds;
    r->cost += it->second;
  }
}

void StageEstimate::drop(const std::string& key) {
  if (!done_.count(key)) cost_.erase(key);
}

double StageEstimate::rate_of(const std::string& key) const {
  const CaseGroups g = case_groups(key);
  if (const auto it = subgroups_.find(g.subgroup); it != subgroups_.end() && it->second.known())
    return it->second.value();
  if (const auto it = groups_.find(g.group); it != groups_.end() && it->second.known())
    return it->second.value();
  if (stage_.known()) return stage_.value();
  return 1.0;  // the model's seconds
}

double StageEstimate::seconds_left() const {
  double left = 0.0;
  for (const auto& [key, cost] : cost_)
    if (!done_.count(key)) left += cost * rate_of(key);
  return left;
}

double StageEstimate::fraction_done() const {
  const double left = seconds_left();
  if (spent_ + left <= 0.0) return total() == 0 ? 1.0 : static_cast<double>(done()) / total();
  return spent_ / (spent_ + left);
}

}  // namespace flatmarch::reports
