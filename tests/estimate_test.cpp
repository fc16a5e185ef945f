// The time left in a stage of a report (reports/estimate.hpp): the cost model calibrated on the
// cases that have finished, and the order that calibrates every backend early.
#include "reports/estimate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace flatmarch::reports {
namespace {

using Cases = std::vector<std::pair<std::string, double>>;

TEST(CaseGroups, NameTheBackendAndItsMethodOfEachKindOfCase) {
  const CaseGroups m = case_groups("matrix/simd/analytic/l_shape");
  EXPECT_EQ(m.stage, "matrix");
  EXPECT_EQ(m.group, "simd");
  EXPECT_EQ(m.subgroup, "simd/analytic");
  const CaseGroups s = case_groups("sweep/translation/sphere");
  EXPECT_EQ(s.stage, "sweep");
  EXPECT_EQ(s.group, "sphere");
  const CaseGroups c = case_groups("scaling/polygon_n/scalar/relaxed");
  EXPECT_EQ(c.stage, "scaling");
  EXPECT_EQ(c.group, "polygon_n");
  EXPECT_EQ(c.subgroup, "polygon_n/scalar");
}

TEST(CalibratingOrder, SpreadsEachBackendsCasesEvenlyOverItsStage) {
  const Cases cases = {{"matrix/a/x/1", 1}, {"matrix/a/x/2", 2}, {"matrix/a/y/1", 3},
                       {"matrix/a/y/2", 4}, {"matrix/b/x/1", 5}, {"sweep/t/sphere", 6},
                       {"matrix/b/x/2", 7}};
  const Cases order = calibrating_order(cases);
  std::vector<std::string> keys;
  for (const auto& [key, cost] : order) keys.push_back(key);
  // The matrix first (its first case came first): a's four at 1/8, 3/8, 5/8, 7/8 of the stage,
  // b's two at 1/4 and 3/4; then the sweep.
  EXPECT_EQ(keys, (std::vector<std::string>{"matrix/a/x/1", "matrix/b/x/1", "matrix/a/x/2",
                                            "matrix/a/y/1", "matrix/b/x/2", "matrix/a/y/2",
                                            "sweep/t/sphere"}));
  EXPECT_EQ(order[1].second, 5);  // costs go with their keys
}

TEST(StageEstimate, BeforeAnyCaseTheModelsSecondsStand) {
  const StageEstimate e({{"matrix/a/x/1", 2.0}, {"matrix/b/x/1", 3.5}});
  EXPECT_DOUBLE_EQ(e.seconds_left(), 5.5);
  EXPECT_DOUBLE_EQ(e.fraction_done(), 0.0);
  EXPECT_EQ(e.total(), 2);
}

TEST(StageEstimate, ScalesEachBackendsCasesByItsOwnRate) {
  StageEstimate e({{"matrix/a/x/1", 1.0},
                   {"matrix/a/x/2", 1.0},
                   {"matrix/a/x/3", 2.0},
                   {"matrix/b/x/1", 1.0},
                   {"matrix/b/x/2", 3.0}});
  e.finished("matrix/a/x/1", 2.0);   // a takes twice its model's time
  e.finished("matrix/b/x/1", 10.0);  // b ten times
  // a: (1 + 2) x 2; b: 3 x 10.
  EXPECT_DOUBLE_EQ(e.seconds_left(), 6.0 + 30.0);
  EXPECT_DOUBLE_EQ(e.fraction_done(), 12.0 / (12.0 + 36.0));
  EXPECT_EQ(e.done(), 2);
  e.finished("matrix/a/x/1", 100.0);  // a case counts once
  EXPECT_EQ(e.done(), 2);
}

TEST(StageEstimate, FallsBackFromTheMethodToTheBackendToTheStage) {
  StageEstimate e(
      {{"matrix/a/x/1", 1.0}, {"matrix/a/x/2", 1.0}, {"matrix/a/y/1", 1.0}, {"matrix/b/x/1", 1.0}});
  e.finished("matrix/a/x/1", 4.0);
  // a/x: 4 (its own); a/y: a's rate, 4; b, unseen: the stage's rate, 4.
  EXPECT_DOUBLE_EQ(e.seconds_left(), 12.0);
  e.finished("matrix/a/y/1", 1.0);
  // a/x still 4; b: the stage's (4 + 1) / 2.
  EXPECT_DOUBLE_EQ(e.seconds_left(), 4.0 + 2.5);
}

TEST(StageEstimate, ADroppedCaseLeavesTheTotalAndTheTimeLeft) {
  StageEstimate e({{"matrix/a/x/1", 1.0}, {"matrix/a/x/2", 5.0}});
  e.drop("matrix/a/x/2");
  EXPECT_EQ(e.total(), 1);
  EXPECT_DOUBLE_EQ(e.seconds_left(), 1.0);
}

TEST(StageEstimate, RefusesANegativeCost) {
  EXPECT_THROW(StageEstimate({{"matrix/a/x/1", -1.0}}), std::invalid_argument);
}

// A matrix stage whose backends run far from the model (0.3x to 20x, as a browser drawing in
// software did), with each case's time off its backend's rate by up to 15%: run in the
// calibrating order, after the first 10% of the cases every estimate of the time left is within
// 30% of the time that was left; run in the stage's own order (every case of one backend, then
// the next), the same estimates are off by more than half.
TEST(StageEstimate, CalibratedOnTheFirstTenthOfAStageItsEstimatesHoldToThirtyPercent) {
  const std::map<std::string, double> rate = {
      {"scalar", 1.4}, {"simd", 0.3}, {"opengl", 2.0}, {"vulkan", 0.8}, {"webgl", 20.0}};
  Cases stage;
  for (const auto& [backend, r] : rate)
    for (int scene = 0; scene < 25; ++scene)
      for (const char* method : {"analytic", "sphere", "relaxed"}) {
        const double cost = (std::string(method) == "analytic" ? 0.1 : 1.0) * (1 + scene % 4);
        stage.emplace_back("matrix/" + backend + "/" + method + "/s" + std::to_string(scene), cost);
      }
  // Each case's true seconds: its cost at its backend's rate, off by a fixed pseudo-random
  // factor in [0.85, 1.15].
  std::map<std::string, double> truth;
  unsigned state = 12345u;
  for (const auto& [key, cost] : stage) {
    state = state * 1103515245u + 12345u;
    const double noise = 0.85 + 0.3 * ((state >> 16) % 1000) / 999.0;
    truth[key] = cost * rate.at(case_groups(key).group) * noise;
  }
  const auto worst_error = [&](const Cases& order) {
    StageEstimate e(order);
    double left = 0.0;
    for (const auto& [key, cost] : order) left += truth[key];
    double worst = 0.0;
    for (size_t k = 0; k + 1 < order.size(); ++k) {
      e.finished(order[k].first, truth[order[k].first]);
      left -= truth[order[k].first];
      if (10 * (k + 1) >= order.size())
        worst = std::max(worst, std::abs(e.seconds_left() - left) / left);
    }
    return worst;
  };
  EXPECT_LE(worst_error(calibrating_order(stage)), 0.30);
  EXPECT_GT(worst_error(stage), 0.5);
}

}  // namespace
}  // namespace flatmarch::reports
