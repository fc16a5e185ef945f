// How long the rest of a stage of cases will take, from the cost model (shard.hpp: each case's
// expected seconds, set on one machine) calibrated on this run. The model's seconds are off in
// two ways that matter: by backend and method (a backend twice as fast here as where the model
// was set), and by item (a scene, a surface type, a family of a scaling series that costs more
// or less than the model says, and differently for each method and on each backend: a prism
// costs the scalar backend's sphere tracing ten times a torus, its analytic method twice). So a
// case's seconds are taken as its cost x a rate of its backend and method x a factor of its item
// with its method x a factor of its item on its backend, fitted to the cases that have finished.
// A rate not yet seen falls back to the backend's, then to the stage's; a factor not yet seen is
// 1, and each is drawn toward 1 by a pseudo-case (of the stage's mean seconds so far) until
// cases of its own outweigh it. Before any case has finished, the model's own seconds stand.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace flatmarch::reports {

// A case's place in the calibration: its stage ("compile", "matrix", "sweep", "scaling"), its
// group (the backend; "" for a sweep, which has one), its method, its subgroup (backend/method)
// and its item (the scene of a matrix case, the surface type of a sweep group, the family of a
// scaling series). From the case keys of matrix.hpp, sweep.hpp and scaling.hpp. A compile case
// (matrix.hpp) has no method: its programs' cost is the scene's on the backend.
struct CaseGroups {
  std::string stage, group, method, subgroup, item;
};
CaseGroups case_groups(const std::string& key);

// The order to run cases in so that every part of a stage is measured early and evenly, and
// the cases left at any time are like those done: the stages in their order; within a stage the
// groups' cases spread evenly over it, within a group its subgroups' spread evenly over the
// group's, and within a subgroup its items in a bit-reversed order (any first part of it spans
// the items' whole list), turned by a different amount for each subgroup so that subgroups run
// different items at the same time. `cases` are (key, cost); so are the result's.
std::vector<std::pair<std::string, double>> calibrating_order(
    const std::vector<std::pair<std::string, double>>& cases);

// `order` with the matrix cases of each of `backends` after its first moved to run one after
// another where its second falls, the other cases in their order: a backend whose every case
// would otherwise start what it keeps between cases anew (webgl's browser,
// Backend::runs_back_to_back). Its first case stays where the calibrating order put it, so that
// its rate is known early, and the cases before its second calibrate the other backends as
// before: its cases all at its first (within the first tenth of the matrix on a 2-core machine)
// left the others fewer cases there, and the matrix's estimate 55% over after that tenth.
std::vector<std::pair<std::string, double>> back_to_back(
    const std::vector<std::pair<std::string, double>>& order,
    const std::vector<std::string>& backends);

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
  // The model's expected seconds of a case of the stage (0 for one not in it).
  double cost_of(const std::string& key) const;
  // Seconds the cases not yet finished are expected to take.
  double seconds_left() const { return left_; }
  // The share of the stage's expected time done: spent / (spent + left).
  double fraction_done() const;
  double seconds_spent() const { return spent_; }

 private:
  void refit();  // left_ from the cases done

  std::map<std::string, double> cost_;
  std::map<std::string, double> done_;
  double spent_ = 0.0, left_ = 0.0;
};

}  // namespace flatmarch::reports
