// Progress of a run of cases in stages (`flatmarch report`'s matrix, sweep and scaling), on
// stderr. On a terminal: one line per stage with a bar, redrawn in place while the stage runs and
// left behind when it ends. In a log: a line every few seconds. The time left is each stage's
// reports::StageEstimate: the cost model calibrated on the cases this run has finished.
#pragma once

#include <condition_variable>
#include <cstdio>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "reports/estimate.hpp"

namespace flatmarch::cli {

class CaseProgress {
 public:
  // `cases` in the order they run, (key, expected seconds). `log_file`, when given, gets a JSON
  // line per finished case: {"stage", "key", "t" (seconds since the start), "seconds", "cost"
  // (the model's seconds), "left" (the stage's estimate then), "done", "total"}: what
  // bench/eta_check.py judges the estimates by.
  CaseProgress(std::string command, const std::vector<std::pair<std::string, double>>& cases,
               bool quiet, const std::string& log_file = "");
  ~CaseProgress();
  CaseProgress(const CaseProgress&) = delete;
  CaseProgress& operator=(const CaseProgress&) = delete;

  // A case of an earlier run (a resumed journal's): out of the estimate, counted as done.
  void resumed(const std::string& key);
  // A case finished now; its seconds are those since the previous one finished (cases run one
  // at a time).
  void finished(const std::string& key);
  // Lines to print between the bars (a case that did not finish).
  void say(const std::string& lines);
  // The last stage's line finished; the ticker stopped. Called by the destructor too.
  void close();

 private:
  struct Stage {
    std::string name;
    reports::StageEstimate estimate;
    int resumed = 0;
    double started = -1.0;  // when its first case began
  };
  void draw(bool final);  // the current stage's line; under mutex_
  // Moves on to the first stage with cases left, which starts at `now` if it has not.
  void advance(double now);
  void tick();

  std::string command_;
  bool quiet_, tty_;
  std::FILE* log_ = nullptr;
  std::vector<Stage> stages_;
  std::map<std::string, size_t> stage_of_;
  std::set<std::string> resumed_;
  size_t current_ = 0;
  double start_, last_finish_, last_line_ = -1.0;
  bool drawn_ = false, closed_ = false;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::thread ticker_;
};

// "2 min 10 s", "45 s".
std::string duration_words(double seconds);

}  // namespace flatmarch::cli
