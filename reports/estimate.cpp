#include "reports/estimate.hpp"

#include <algorithm>
#include <map>
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

// 0 .. n-1 in bit-reversed order (that of 0 .. 2^k-1 for the least 2^k >= n, less those >= n):
// every first part of it is spread over the whole range.
std::vector<size_t> bit_reversed(size_t n) {
  int bits = 0;
  while ((size_t{1} << bits) < n) ++bits;
  std::vector<size_t> order;
  order.reserve(n);
  for (size_t i = 0; i < (size_t{1} << bits); ++i) {
    size_t r = 0;
    for (int b = 0; b < bits; ++b)
      if (i & (size_t{1} << b)) r |= size_t{1} << (bits - 1 - b);
    if (r < n) order.push_back(r);
  }
  return order;
}

// Lists, each spread evenly over the result: the j-th of a list of n at (j + 1/2) / n; at
// equal places, the earlier list first.
template <typename T>
std::vector<T> interleave(const std::vector<std::vector<T>>& lists) {
  std::vector<std::pair<double, std::pair<size_t, const T*>>> at;
  for (size_t l = 0; l < lists.size(); ++l)
    for (size_t j = 0; j < lists[l].size(); ++j)
      at.push_back({(static_cast<double>(j) + 0.5) / static_cast<double>(lists[l].size()),
                    {l, &lists[l][j]}});
  std::stable_sort(at.begin(), at.end(), [](const auto& a, const auto& b) {
    return a.first < b.first || (a.first == b.first && a.second.first < b.second.first);
  });
  std::vector<T> out;
  out.reserve(at.size());
  for (const auto& entry : at) out.push_back(*entry.second.second);
  return out;
}

// A list's position in another, by name, added at the end when new.
template <typename T>
T& named(std::vector<std::pair<std::string, T>>& list, const std::string& name) {
  auto it = std::find_if(list.begin(), list.end(), [&](const auto& e) { return e.first == name; });
  if (it == list.end()) it = list.insert(list.end(), {name, T{}});
  return it->second;
}

}  // namespace

CaseGroups case_groups(const std::string& key) {
  const std::vector<std::string> p = split(key);
  if (p[0] == "matrix" && p.size() == 4)  // B/M/S
    return {p[0], p[1], p[2], p[1] + "/" + p[2], p[3]};
  if (p[0] == "compile" && p.size() == 4) return {p[0], p[1], "", p[1], p[3]};  // B/M/S
  if (p[0] == "sweep" && p.size() == 3) return {p[0], "", p[2], p[2], p[1]};    // T/M
  if (p[0] == "scaling" && p.size() == 4)                                       // F/B/M
    return {p[0], p[2], p[3], p[2] + "/" + p[3], p[1]};
  // Another kind of case (a conformance case, BACKEND/METHOD/SCENE/...): its first three words.
  const std::string method = p.size() > 1 ? p[1] : "";
  return {"cases", p[0], method, p.size() > 1 ? p[0] + "/" + method : p[0],
          p.size() > 2 ? p[2] : ""};
}

std::vector<std::pair<std::string, double>> calibrating_order(
    const std::vector<std::pair<std::string, double>>& cases) {
  using Case = std::pair<std::string, double>;
  using Subgroups = std::vector<std::pair<std::string, std::vector<Case>>>;
  // Stages, their groups and the groups' subgroups in order of first appearance; each
  // subgroup's cases in the order given.
  std::vector<std::pair<std::string, std::vector<std::pair<std::string, Subgroups>>>> stages;
  for (const Case& c : cases) {
    const CaseGroups g = case_groups(c.first);
    named(named(named(stages, g.stage), g.group), g.subgroup).push_back(c);
  }
  std::vector<Case> order;
  order.reserve(cases.size());
  for (const auto& [stage, groups] : stages) {
    size_t subgroups = 0, s = 0;
    for (const auto& group : groups) subgroups += group.second.size();
    std::vector<std::vector<Case>> spread_groups;
    for (const auto& [group, members] : groups) {
      std::vector<std::vector<Case>> spread_subgroups;
      for (const auto& [subgroup, items] : members) {
        // The s-th subgroup of the stage starts s / subgroups of the way along its items.
        const size_t n = items.size(), turn = s++ * n / subgroups;
        std::vector<Case> spread;
        for (const size_t k : bit_reversed(n)) spread.push_back(items[(k + turn) % n]);
        spread_subgroups.push_back(std::move(spread));
      }
      spread_groups.push_back(interleave(spread_subgroups));
    }
    for (Case& c : interleave(spread_groups)) order.push_back(std::move(c));
  }
  return order;
}

std::vector<std::pair<std::string, double>> back_to_back(
    const std::vector<std::pair<std::string, double>>& order,
    const std::vector<std::string>& backends) {
  using Case = std::pair<std::string, double>;
  const auto together = [&](const Case& c) -> std::string {
    const CaseGroups g = case_groups(c.first);
    if (g.stage != "matrix" ||
        std::find(backends.begin(), backends.end(), g.group) == backends.end())
      return "";
    return g.group;
  };
  // Each backend's cases after its first, in their order.
  std::map<std::string, std::vector<Case>> later;
  std::map<std::string, int> seen;
  for (const Case& c : order)
    if (const std::string b = together(c); !b.empty() && seen[b]++ > 0) later[b].push_back(c);
  std::vector<Case> out;
  out.reserve(order.size());
  seen.clear();
  for (const Case& c : order) {
    const std::string b = together(c);
    if (b.empty() || seen[b]++ == 0) {
      out.push_back(c);
    } else if (auto run = later.find(b); run != later.end()) {  // its second: all the later ones
      out.insert(out.end(), run->second.begin(), run->second.end());
      later.erase(run);
    }
  }
  return out;
}

StageEstimate::StageEstimate(const std::vector<std::pair<std::string, double>>& cases) {
  for (const auto& [key, cost] : cases) {
    if (!(cost >= 0.0)) throw std::invalid_argument("StageEstimate: a cost that is not >= 0");
    cost_[key] = cost;
  }
  refit();
}

double StageEstimate::cost_of(const std::string& key) const {
  const auto it = cost_.find(key);
  return it == cost_.end() ? 0.0 : it->second;
}

void StageEstimate::finished(const std::string& key, double seconds) {
  const auto it = cost_.find(key);
  if (it == cost_.end() || done_.count(key) || !(seconds >= 0.0)) return;
  done_[key] = seconds;
  spent_ += seconds;
  refit();
}

void StageEstimate::drop(const std::string& key) {
  if (!done_.count(key)) cost_.erase(key);
  refit();
}

void StageEstimate::refit() {
  struct Done {
    CaseGroups g;
    double seconds, cost;
  };
  std::vector<Done> done;
  for (const auto& [key, seconds] : done_) done.push_back({case_groups(key), seconds, cost_[key]});
  struct Sum {  // seconds taken against seconds expected
    double seconds = 0.0, expected = 0.0;
  };
  std::map<std::string, Sum> subgroups, groups;
  Sum stage;
  std::map<std::string, double> item_with_method, item_on_group;  // the factors; 1 when absent
  const auto factor = [](const std::map<std::string, double>& f, const std::string& name) {
    const auto it = f.find(name);
    return it == f.end() ? 1.0 : it->second;
  };
  const auto with_method = [](const CaseGroups& g) { return g.method + "\n" + g.item; };
  const auto on_group = [](const CaseGroups& g) { return g.group + "\n" + g.item; };
  const auto rate = [&](const CaseGroups& g) {
    for (const Sum* s : {&subgroups[g.subgroup], &groups[g.group], &stage})
      if (s->expected > 0.0) return s->seconds / s->expected;
    return 1.0;  // the model's seconds
  };
  if (!done.empty()) {
    // A factor's pseudo-case: a case of the mean seconds taken, at factor 1.
    const double prior = spent_ / static_cast<double>(done.size());
    // Each fit in turn, given the others; three rounds settle them.
    for (int round = 0; round < 3; ++round) {
      subgroups.clear();
      groups.clear();
      stage = {};
      for (const Done& d : done) {
        const double expected = d.cost * factor(item_with_method, with_method(d.g)) *
                                factor(item_on_group, on_group(d.g));
        for (Sum* s : {&subgroups[d.g.subgroup], &groups[d.g.group], &stage}) {
          s->seconds += d.seconds;
          s->expected += expected;
        }
      }
      std::map<std::string, Sum> by_item_with_method;
      for (const Done& d : done) {
        Sum& s = by_item_with_method[with_method(d.g)];
        s.seconds += d.seconds;
        s.expected += d.cost * rate(d.g) * factor(item_on_group, on_group(d.g));
      }
      item_with_method.clear();
      for (const auto& [name, s] : by_item_with_method)
        item_with_method[name] = (s.seconds + prior) / (s.expected + prior);
      std::map<std::string, Sum> by_item_on_group;
      for (const Done& d : done) {
        Sum& s = by_item_on_group[on_group(d.g)];
        s.seconds += d.seconds;
        s.expected += d.cost * rate(d.g) * factor(item_with_method, with_method(d.g));
      }
      item_on_group.clear();
      for (const auto& [name, s] : by_item_on_group)
        item_on_group[name] = (s.seconds + prior) / (s.expected + prior);
    }
  }
  left_ = 0.0;
  for (const auto& [key, cost] : cost_) {
    if (done_.count(key)) continue;
    const CaseGroups g = case_groups(key);
    left_ += cost * rate(g) * factor(item_with_method, with_method(g)) *
             factor(item_on_group, on_group(g));
  }
}

double StageEstimate::fraction_done() const {
  if (spent_ + left_ <= 0.0) return total() == 0 ? 1.0 : static_cast<double>(done()) / total();
  return spent_ / (spent_ + left_);
}

}  // namespace flatmarch::reports
