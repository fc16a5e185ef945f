// The results database and its change points: adds that are idempotent, files refused with why,
// the migration from the first schema, and change points on synthetic series whose steps are
// known.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include "history/analysis.hpp"
#include "history/changes.hpp"
#include "history/database.hpp"
#include "history/runs.hpp"
#include "tests/process.hpp"

namespace flatmarch::history {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// A file of the test's own folder, removed at exit (test::make_temp_dir).
fs::path scratch(const std::string& name) {
  static const fs::path dir = test::make_temp_dir();
  const fs::path p = dir / name;
  fs::remove(p);
  return p;
}

void write(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

// A report's results with one case: its rays a second over three repetitions, its steps.
json report(double rays_per_s, double steps_mean, const std::string& verdict = "pass") {
  const double ms = 1e3 * 160 * 90 / rays_per_s;
  return {
      {"format", "flatmarch-report/1"},
      {"created", "2026-12-05T10:00:00Z"},
      {"fingerprint",
       {{"cpu", {{"model", "Test CPU"}, {"logical_cores", 2}, {"isa", "avx2"}, {"isas", {"avx2"}}}},
        {"build", {{"type", "Release"}}}}},
      {"options", {{"size", "160x90"}, {"eps", 1e-4}}},
      {"ranking", json::array()},
      {"matrix",
       {{"cases",
         {{{"name", "scalar/sphere/torus/160x90"},
           {"counters",
            {{"rays_per_s", rays_per_s}, {"steps_mean", steps_mean}, {"crossings_mean", 1.5}}},
           {"time_samples_ms", {ms * 0.99, ms, ms * 1.01}},
           {"accuracy", {{"verdict", verdict}, {"hit_mismatch", 0.0}}}}}}}}};
}

TEST(HistoryDatabase, AddingTheSameRunTwiceKeepsOne) {
  const fs::path db_file = scratch("twice.db"), results = scratch("results.json");
  write(results, report(1e6, 10.0).dump());
  Database db(db_file);
  const history::Run run = read_run(results, "c1");
  EXPECT_EQ(run.kind, "report");
  // rays_per_s; steps_mean and crossings_mean; hit_mismatch; the verdict.
  EXPECT_EQ(run.measurements.size(), 5u);
  ASSERT_TRUE(db.add(run).has_value());
  EXPECT_FALSE(db.add(read_run(results, "c1")).has_value());
  EXPECT_FALSE(db.add(read_run(results, "another commit")).has_value());  // same content
  EXPECT_EQ(db.runs().size(), 1u);
  const auto keys = db.find_series("report/scalar/sphere/torus/160x90", "rays_per_s");
  ASSERT_EQ(keys.size(), 1u);
  EXPECT_EQ(keys[0].judged, Judged::kHigherIsBetter);
  const std::vector<Point> points = db.series(keys[0]);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_DOUBLE_EQ(points[0].value, 1e6);
  EXPECT_EQ(points[0].repetitions, 3);
  // The samples' sample standard deviation over their median: 0.01 of it, by hand.
  EXPECT_NEAR(points[0].spread, 0.01, 1e-9);
}

TEST(HistoryDatabase, KeepsTheCpusCountOfTheWorkAsASeries) {
  // Where the machine counts instructions (reports/work_count.hpp) a case carries them a ray.
  json r = report(1e6, 10.0);
  r["matrix"]["cases"][0]["counters"]["instructions_per_ray"] = 5123.0;
  const fs::path results = scratch("work.json");
  write(results, r.dump());
  const history::Run run = read_run(results, "c1");
  const auto at =
      std::find_if(run.measurements.begin(), run.measurements.end(),
                   [](const Measurement& m) { return m.figure == "instructions_per_ray"; });
  ASSERT_NE(at, run.measurements.end());
  EXPECT_EQ(at->judged, Judged::kLowerIsBetter);
  EXPECT_DOUBLE_EQ(at->value, 5123.0);
}

TEST(HistoryDatabase, RefusesFilesItCannotKeepSayingWhy) {
  const fs::path bad = scratch("bad.json");
  const auto why = [&](const std::string& text) {
    write(bad, text);
    try {
      read_run(bad, "c");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(why("{\"format\": \"flatmarch-report/1\", \"matr").find("not JSON"), std::string::npos);
  EXPECT_NE(why("[1, 2, 3]").find("no object"), std::string::npos);
  EXPECT_NE(why("{\"name\": \"package.json\"}").find("not a results file"), std::string::npos);
  json empty = report(1e6, 10);
  empty["matrix"]["cases"] = json::array();
  EXPECT_NE(why(empty.dump()).find("holds no case"), std::string::npos);
  json broken = report(1e6, 10);
  broken.erase("fingerprint");
  EXPECT_NE(why(broken.dump()).find("missing"), std::string::npos);

  // A database file that is not SQLite, and another program's SQLite database.
  const fs::path text = scratch("notes.db");
  write(text, "these are my notes, not a database, and they are long enough to be read");
  EXPECT_THROW(Database{text}, std::runtime_error);
  const fs::path foreign = scratch("foreign.db");
  sqlite3* other = nullptr;
  ASSERT_EQ(sqlite3_open(foreign.c_str(), &other), SQLITE_OK);
  sqlite3_exec(other, "CREATE TABLE photos(id INTEGER)", nullptr, nullptr, nullptr);
  sqlite3_close(other);
  try {
    Database d(foreign);
    ADD_FAILURE() << "another program's database was opened";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("another program"), std::string::npos) << e.what();
  }
}

TEST(HistoryDatabase, MigratesFromTheFirstSchemaKeepingEveryRun) {
  const fs::path file = scratch("v1.db");
  sqlite3* v1 = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &v1), SQLITE_OK);
  const std::string made =
      std::string(kSchemaV1) + "PRAGMA application_id = " + std::to_string(kApplicationId) +
      "; PRAGMA user_version = 1;" +
      "INSERT INTO runs VALUES (1, 'd1', 'report', 'old', '2026-01-01T00:00:00Z', "
      "'2026-01-01T00:00:00Z', 'm', 'Old CPU', '{}', '{}', 'r.json', '');"
      "INSERT INTO measurements VALUES (1, 'report/x', 'rays_per_s', 2e6, NULL, 0.02, 3);"
      "INSERT INTO measurements VALUES (1, 'report/x', 'steps_mean', 12.5, NULL, 0, 1);";
  ASSERT_EQ(sqlite3_exec(v1, made.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(v1);

  Database db(file);
  EXPECT_EQ(db.schema_version(), kSchemaVersion);
  ASSERT_EQ(db.runs().size(), 1u);
  EXPECT_EQ(db.runs()[0].commit, "old");
  const auto rays = db.find_series("report/x", "rays_per_s");
  ASSERT_EQ(rays.size(), 1u);
  EXPECT_EQ(rays[0].judged, Judged::kHigherIsBetter);  // set by the migration, by figure
  EXPECT_EQ(db.find_series("report/x", "steps_mean").at(0).judged, Judged::kDeterministic);
  EXPECT_DOUBLE_EQ(db.series(rays[0]).at(0).value, 2e6);
  // And it takes new runs in the new schema.
  const fs::path results = scratch("new.json");
  write(results, report(1e6, 10).dump());
  EXPECT_TRUE(db.add(read_run(results, "new")).has_value());
  EXPECT_EQ(db.runs().size(), 2u);
}

TEST(HistoryDatabase, RefusesASchemaNewerThanItKnows) {
  const fs::path file = scratch("newer.db");
  { Database made(file); }
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &raw), SQLITE_OK);
  sqlite3_exec(raw, "PRAGMA user_version = 99", nullptr, nullptr, nullptr);
  sqlite3_close(raw);
  try {
    Database d(file);
    ADD_FAILURE() << "a newer schema was opened";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("newer"), std::string::npos) << e.what();
  }
}

// A timing series: `before` runs at 1, then `after` runs at 1 + step, each run the mean of
// `repetitions` repetitions with relative noise `noise`, its spread their sample deviation.
std::vector<TimingSample> series(std::mt19937& rng, size_t before, size_t after, double step,
                                 double noise, int repetitions) {
  std::normal_distribution<double> z(0.0, 1.0);
  std::vector<TimingSample> out;
  for (size_t i = 0; i < before + after; ++i) {
    const double level = i < before ? 1.0 : 1.0 + step;
    std::vector<double> reps;
    double mean = 0.0;
    for (int r = 0; r < repetitions; ++r) {
      reps.push_back(level * (1.0 + noise * z(rng)));
      mean += reps.back() / repetitions;
    }
    double var = 0.0;
    for (double x : reps) var += (x - mean) * (x - mean) / std::max(repetitions - 1, 1);
    out.push_back({mean, repetitions > 1 ? std::sqrt(var) / mean : 0.0, repetitions});
  }
  return out;
}

// How many of `trials` series of `before` runs, a step of `step` and `after` runs show that step
// alone, placed within one run of where it is.
int found_alone(std::mt19937& rng, int trials, size_t before, size_t after, double step,
                int repetitions) {
  int found = 0;
  for (int t = 0; t < trials; ++t) {
    const auto c = timing_changes(series(rng, before, after, step, 0.03, repetitions));
    found += c.size() == 1 &&
             std::abs(static_cast<double>(c[0].at) - static_cast<double>(before)) <= 1.0 &&
             c[0].after > c[0].before;
  }
  std::printf(
      "a %g%% step, %zu runs before and %zu after, %d repetitions a run: found in %d of %d\n",
      100 * step, before, after, repetitions, found, trials);
  return found;
}

TEST(ChangePoints, AFivePercentStepInThreePercentNoiseIsFoundWithinFiveRuns) {
  // Repetitions of 3% noise, 20 runs before the step, 5 after it (docs/history.md states the
  // rates these measure): with 5 repetitions a run the step is found nearly always ...
  std::mt19937 rng(77);
  EXPECT_GE(found_alone(rng, 100, 20, 5, 0.05, 5), 90);
  // ... with 3 (the report's default) in two series of three by the 5th run after it, and by
  // the 8th in nine of ten.
  EXPECT_GE(found_alone(rng, 100, 20, 5, 0.05, 3), 60);
  EXPECT_GE(found_alone(rng, 100, 20, 8, 0.05, 3), 85);
}

TEST(ChangePoints, PureNoiseRaisesNoAlarmInAHundredSeries) {
  std::mt19937 rng(78);
  for (int trial = 0; trial < 100; ++trial)
    EXPECT_TRUE(timing_changes(series(rng, 40, 0, 0.0, 0.03, 3)).empty()) << "trial " << trial;
  // With one repetition a run (no spread to weigh by) as well.
  for (int trial = 0; trial < 100; ++trial)
    EXPECT_TRUE(timing_changes(series(rng, 40, 0, 0.0, 0.03, 1)).empty()) << "trial " << trial;
}

TEST(ChangePoints, TheFalseAlarmRateIsAsDocumented) {
  // docs/history.md and changes.hpp state about 0.1% a series of 40 runs at the default
  // threshold: measured here over 2,000 series of 3% noise, under 0.25%.
  std::mt19937 rng(79);
  int alarms = 0;
  for (int trial = 0; trial < 2000; ++trial)
    alarms += !timing_changes(series(rng, 40, 0, 0.0, 0.03, 3)).empty();
  std::printf("pure 3%% noise, 40 runs of 3 repetitions: a change in %d of 2000 series\n", alarms);
  EXPECT_LT(alarms, 5) << alarms << " of 2000";
}

TEST(ChangePoints, OneRepetitionARunTakesLongerToFindTheStep) {
  // Without repetitions only the runs' scatter, from fewer degrees of freedom, says how sure a
  // step is: z = 0.05 / (0.03 x sqrt(1/20 + 1/15)) is 4.9 at 15 runs after it, against a
  // threshold of 4.5 for 33 degrees of freedom, so fewer than half the series show it by then.
  std::mt19937 rng(80);
  EXPECT_GE(found_alone(rng, 100, 20, 15, 0.05, 1), 30);
  // A 10% step in the same noise in most series by the 5th run.
  EXPECT_GE(found_alone(rng, 100, 20, 5, 0.10, 1), 60);
}

TEST(ChangePoints, RunsWithAWideSpreadWeighLittle) {
  // The last three runs 8% off the rest, but each measured with a spread of 40% over 3
  // repetitions: their own variance swamps them, no change.
  std::vector<TimingSample> s(30, {1.0, 0.01, 3});
  for (size_t i = 0; i < s.size(); ++i) s[i].value = 1.0 + 0.004 * std::sin(static_cast<double>(i));
  for (size_t i = 27; i < 30; ++i) s[i] = {1.08, 0.4, 3};
  EXPECT_TRUE(timing_changes(s).empty());
  // The same runs measured tightly are a change, at the first of them.
  for (size_t i = 27; i < 30; ++i) s[i].spread = 0.01;
  const auto c = timing_changes(s);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].at, 27u);
  EXPECT_NEAR(c[0].after / c[0].before, 1.08, 0.005);
}

TEST(ChangePoints, DeterministicFiguresChangeAtTheirFirstRun) {
  const std::vector<double> steps = {10.0, 10.0, 10.0 * (1 + 1e-12), 11.0, 11.0, 10.0};
  EXPECT_EQ(deterministic_changes(steps), (std::vector<size_t>{3, 5}));
  const std::vector<std::string> verdicts = {"pass", "pass", "fail", "fail"};
  EXPECT_EQ(deterministic_changes(verdicts), (std::vector<size_t>{2}));
}

TEST(HistoryAnalysis, ABaselineCommitAcceptsADeterministicChange) {
  const fs::path file = scratch("accept.db"), results = scratch("r.json"), base = scratch("b.json");
  Database db(file);
  const auto add = [&](int k, double steps, const std::string& baseline_text) {
    json r = report(1e6 * (1 + 1e-3 * k), steps);
    r["created"] = "2026-12-05T10:0" + std::to_string(k) + ":00Z";
    write(results, r.dump());
    write(base, baseline_text);
    ASSERT_TRUE(db.add(read_run(results, "c" + std::to_string(k), base)).has_value());
  };
  add(0, 10.0, "baseline one");
  add(1, 12.0, "baseline one");  // more steps, same baseline: a regression
  json changes = newest_changes(analyse(db));
  ASSERT_EQ(changes["deterministic"].size(), 1u);
  EXPECT_EQ(changes["deterministic"][0]["figure"], "steps_mean");
  EXPECT_TRUE(changes["deterministic"][0]["worse"].get<bool>());
  EXPECT_EQ(changes["deterministic"][0]["commits"], json({"c0", "c1"}));
  add(2, 11.0, "baseline two");  // fewer again, with the baseline rewritten: accepted
  changes = newest_changes(analyse(db));
  EXPECT_TRUE(changes["deterministic"].empty());
  ASSERT_EQ(changes["accepted"].size(), 1u);
  EXPECT_EQ(changes["accepted"][0]["commits"], json({"c1", "c2"}));
}

}  // namespace
}  // namespace flatmarch::history
