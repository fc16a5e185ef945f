// How long the rest of a stage of cases will take, from the cost model (shard.hpp: each case's
// expected seconds, set on one machine) calibrated on this run: the seconds each finished case
// took against its expected cost give a rate per group of cases (a backend, and a backend's
// method), which scales the expected cost of the cases still to run. A group no case of which
// has finished takes the stage's rate so far; before any case has finished, the model's own
// seconds stand.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace flatmarch::reports {

// A case's place in the calibration: its stage ("matrix", "sweep", "scaling"), its group (the
// backend of a matrix case, the method of a sweep group, the family of a scaling series) and its
// subgroup (the backend's method; a scaling series' family and backend). From the case keys of
// matrix.hpp, sweep.hpp and scaling.hpp.
struct CaseGroups {
  std::string stage, group, subgroup;
};
CaseGroups case_groups(const std::string& key);

// The order to run cases in so that every group is measured early and evenly: the stages in
// their order, and within a stage each group's cases (in the order given) spread evenly over the
// stage, so that its first tenth holds a tenth of every group's cases. `cases` are (key, cost); so
// are the result's.
std::vector<std::pair<std::string, double>> calibrating_order(
    const std::vector<std::pair<std::string, double>>& cases);

class StageEstimate {
 public:
  // The stage's cases, (key, expected seconds), all of one stage.
  explicit StageEstimate(const std::vector<std::pair<std::string, double>>& cases);

  // A case that finished (or did not: its seconds count all the same) after `seconds`.
  void finished(const std::string& key, double seconds);
  // A case not to be counted (done by an earlier run): out of the total and of the time left.
  void drop(const std::string& key);

  int total() const { return static_cast<int>(cost_.size()); }
  int done() const { return static_cast<int>(done_.size()); }
  // Seconds the cases not yet finished are expected to take.
  double seconds_left() const;
  // The share of the stage's expected time done: spent / (spent + left).
  double fraction_done() const;
  double seconds_spent() const { return spent_; }

 private:
  struct Rate {
    double seconds = 0.0, cost = 0.0;
    bool known() const { return cost > 0.0; }
    double value() const { return seconds / cost; }
  };
  double rate_of(const std::string& key) const;

  std::map<std::string, double> cost_;
  std::map<std::string, double> done_;
  std::map<std::string, Rate> groups_, subgroups_;
  Rate stage_;
  double spent_ = 0.0;
};

}  // namespace flatmarch::reports
