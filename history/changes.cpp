#include "history/changes.hpp"

#include <algorithm>
#include <cmath>

namespace flatmarch::history {

namespace {

struct Segmenter {
  const std::vector<double>& y;  // log values
  const std::vector<double>& w;  // weights
  const ChangeOptions& o;
  double centre;  // taken from the logs: the levels found are exp(centre + mean)
  std::vector<TimingChange> found;

  // Weighted sum and weight of y[lo, hi).
  std::pair<double, double> sums(size_t lo, size_t hi) const {
    double s = 0.0, ws = 0.0;
    for (size_t i = lo; i < hi; ++i) {
      s += w[i] * y[i];
      ws += w[i];
    }
    return {s, ws};
  }

  // Splits y[lo, hi) where the two sides differ most, while a split is a change; depth-first
  // from the left, so that changes come out in order.
  void split(size_t lo, size_t hi) {
    if (hi - lo < 2 * o.min_runs || found.size() >= o.max_changes) return;
    const auto [total, total_w] = sums(lo, hi);
    double total_sq = 0.0, left_sq = 0.0;
    for (size_t i = lo; i < hi; ++i) total_sq += w[i] * y[i] * y[i];
    double left = 0.0, left_w = 0.0, best_z = 0.0;
    size_t best = 0;
    double best_before = 0.0, best_after = 0.0;
    for (size_t k = lo; k + 1 < hi; ++k) {
      left += w[k] * y[k];
      left_w += w[k];
      left_sq += w[k] * y[k] * y[k];
      const size_t at = k + 1;  // the first run of the right side
      if (at - lo < o.min_runs || hi - at < o.min_runs) continue;
      const double right_w = total_w - left_w;
      const double m1 = left / left_w, m2 = (total - left) / right_w;
      // The weights' scale checked against the residuals either side: where they scatter more
      // than the weights say, the z is shrunk by as much (never grown).
      const double residual = (left_sq - left * m1) + (total_sq - left_sq - (total - left) * m2);
      const double scale =
          std::max(1.0, residual / std::max<double>(static_cast<double>(hi - lo) - 2.0, 1.0));
      const double z = std::abs(m2 - m1) / std::sqrt((1.0 / left_w + 1.0 / right_w) * scale);
      if (z > best_z) {
        best_z = z;
        best = at;
        best_before = m1;
        best_after = m2;
      }
    }
    if (best == 0 || best_z < o.threshold ||
        std::abs(std::exp(best_after - best_before) - 1.0) < o.min_change)
      return;
    split(lo, best);
    if (found.size() < o.max_changes)
      found.push_back(
          {best, std::exp(centre + best_before), std::exp(centre + best_after), best_z});
    split(best, hi);
  }
};

}  // namespace

std::vector<TimingChange> timing_changes(std::span<const TimingSample> series,
                                         const ChangeOptions& o) {
  const size_t n = series.size();
  if (n < 2 * std::max<size_t>(o.min_runs, 1)) return {};
  std::vector<double> y(n), own(n);
  for (size_t i = 0; i < n; ++i) {
    if (!(series[i].value > 0.0) || !std::isfinite(series[i].value)) return {};
    y[i] = std::log(series[i].value);  // centred below, for the sums of squares
    const double s = std::isfinite(series[i].spread) ? series[i].spread : 0.0;
    own[i] = s * s / std::max(series[i].repetitions, 1);
  }
  double centre = 0.0;
  for (double v : y) centre += v / static_cast<double>(n);
  for (double& v : y) v -= centre;
  // Each run's own variance, known from a few repetitions only, moderated towards the series'
  // mean as limma moderates gene-wise variances (Smyth 2004): a run whose repetitions happen to
  // agree closely is not trusted without bound, one whose repetitions scatter widely weighs
  // less, a run of one repetition has the mean.
  double typical = 0.0, within_df = 0.0;
  for (size_t i = 0; i < n; ++i) {
    typical += own[i] / static_cast<double>(n);
    within_df += std::max(series[i].repetitions, 1) - 1.0;
  }
  constexpr double kPriorRuns = 4.0;  // the mean's weight, in degrees of freedom
  for (size_t i = 0; i < n; ++i) {
    const double df = std::max(series[i].repetitions, 1) - 1.0;
    own[i] = (df * own[i] + kPriorRuns * typical) / (df + kPriorRuns);
  }
  // The wander between runs beyond that: half the variance of successive differences (each
  // holds two runs' noise), less the runs' own.
  double mean_diff = 0.0, var_diff = 0.0;
  for (size_t i = 0; i + 1 < n; ++i) mean_diff += (y[i + 1] - y[i]) / static_cast<double>(n - 1);
  for (size_t i = 0; i + 1 < n; ++i)
    var_diff += (y[i + 1] - y[i] - mean_diff) * (y[i + 1] - y[i] - mean_diff) /
                std::max(static_cast<double>(n) - 2.0, 1.0);
  const double between = std::max(0.0, var_diff / 2.0 - typical);
  // A floor under each run's variance: a series of identical values (a clock's resolution)
  // would otherwise weigh infinitely; 0.1% is below any timing the reports print.
  constexpr double kFloor = 1e-3 * 1e-3;
  std::vector<double> w(n);
  for (size_t i = 0; i < n; ++i) w[i] = 1.0 / std::max(own[i] + between, kFloor);
  // The variances are estimated, from the repetitions (their degrees of freedom) where they
  // say more than the runs' scatter does, else from the n - 2 of the differences: the threshold
  // is the t distribution's quantile of as many degrees of freedom at the normal's tail
  // probability (Cornish-Fisher), so that a short series of single runs is not overtrusted.
  const double nu =
      within_df >= static_cast<double>(n) ? within_df : std::max(static_cast<double>(n) - 2.0, 1.0);
  const double t = o.threshold;
  ChangeOptions at_t = o;
  at_t.threshold = t + (t * t * t + t) / (4.0 * nu) +
                   (5 * std::pow(t, 5) + 16 * t * t * t + 3 * t) / (96.0 * nu * nu);
  Segmenter s{y, w, at_t, centre, {}};
  s.split(0, n);
  return s.found;
}

std::vector<size_t> deterministic_changes(std::span<const double> values, double relative) {
  std::vector<size_t> out;
  for (size_t i = 1; i < values.size(); ++i) {
    const double a = values[i - 1], b = values[i];
    if (std::isnan(a) != std::isnan(b) ||
        std::abs(b - a) > relative * std::max({std::abs(a), std::abs(b), 1e-300}))
      out.push_back(i);
  }
  return out;
}

std::vector<size_t> deterministic_changes(std::span<const std::string> texts) {
  std::vector<size_t> out;
  for (size_t i = 1; i < texts.size(); ++i)
    if (texts[i] != texts[i - 1]) out.push_back(i);
  return out;
}

}  // namespace flatmarch::history
