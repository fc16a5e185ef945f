// Change points in a series of runs.
//
// Deterministic figures (steps, crossings, accuracy, verdicts) change only with the code: any
// change is flagged at the first run that shows it.
//
// Timings wander with the machine, so a timing series is judged as a whole, by binary
// segmentation (Scott & Knott 1974; Vostrikova 1981) of its logarithm: the split that best
// separates the runs before from the runs after, by the weighted difference of their means in
// standard errors, is a change point when that z reaches the threshold and the change is at
// least `min_change`; each side is then split again. A run's weight is 1 / (v_i + s_b^2): v_i
// its own mean's variance from its repetitions' spread (spread^2 / repetitions), moderated
// towards the series' mean as limma moderates variances (Smyth 2004), and s_b^2 the variance
// between runs beyond that, from the series' successive differences, as a random-effects
// meta-analysis weighs studies (DerSimonian & Laird 1986). Where the residuals scatter more than
// the weights say, z shrinks by as much; and as the variances are estimated, the threshold is
// the t distribution's quantile at the normal's tail probability of `threshold`, for the degrees
// of freedom they come from (Cornish-Fisher expansion).
//
// Measured on synthetic series of 3% noise (history_test, fixed seeds; docs/history.md): pure
// noise, 40 runs of 3 repetitions, raises a change in 2 of 2,000 series (0.1%); a 5% step after 20
// runs is found within 5 runs of it in 95 of 100 series with 5 repetitions a run, 71 with 3 (88
// by the 8th run), and with single runs 46 of 100 by the 15th.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace flatmarch::history {

struct TimingSample {
  double value = 0.0;   // > 0: a time or a rate
  double spread = 0.0;  // the relative standard deviation of its repetitions, 0 where unknown
  int repetitions = 1;
};

struct ChangeOptions {
  double threshold = 4.0;    // z, in standard errors of the difference of the two sides' means
  double min_change = 0.02;  // relative: smaller steps are not reported however sure
  size_t min_runs = 2;       // on each side of a split
  size_t max_changes = 16;
};

struct TimingChange {
  size_t at = 0;                     // the first run after the change
  double before = 0.0, after = 0.0;  // the geometric means of the segments either side
  double z = 0.0;
};

// The change points of a timing series, in order of `at`. Series of fewer than 2 x min_runs
// runs, or with a value <= 0, have none.
std::vector<TimingChange> timing_changes(std::span<const TimingSample> series,
                                         const ChangeOptions& options = {});

// The runs (indices from 1) whose deterministic figure differs from the run before: numbers by
// more than `relative` of their size (rounding of the JSON), texts at all.
std::vector<size_t> deterministic_changes(std::span<const double> values, double relative = 1e-9);
std::vector<size_t> deterministic_changes(std::span<const std::string> texts);

}  // namespace flatmarch::history
