// Sharded runs (issue 24): the split of a run's cases among N shards, and `flatmarch merge`
// putting `conform --shard I/N` and `report --shard I/N` results back together as one unsharded
// run writes them.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <numeric>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "reports/report.hpp"
#include "reports/shard.hpp"
#include "scene/load.hpp"
#include "tests/process.hpp"
#include "tests/report_figures.hpp"

namespace flatmarch {
namespace {

using nlohmann::json;
using reports::assign_shards;
using reports::parse_shard;
using test::deterministic_report;

TEST(Shards, ParseIOfN) {
  ASSERT_TRUE(parse_shard("2/7"));
  EXPECT_EQ(parse_shard("2/7")->index, 2);
  EXPECT_EQ(parse_shard("2/7")->count, 7);
  for (const char* bad : {"0/3", "4/3", "1/0", "3", "1/3x", "-1/3", "1/1001", ""})
    EXPECT_FALSE(parse_shard(bad)) << bad;
}

TEST(Shards, EveryCaseInOneShardBalancedByCost) {
  std::vector<double> costs;
  for (int k = 0; k < 40; ++k) costs.push_back(1.0 + (k * 7919 % 13));
  for (const int n : {1, 2, 3, 7}) {
    const std::vector<int> shard = assign_shards(costs, n);
    ASSERT_EQ(shard.size(), costs.size());
    EXPECT_EQ(assign_shards(costs, n), shard) << "not deterministic";
    std::vector<double> load(static_cast<size_t>(n), 0.0);
    for (size_t k = 0; k < costs.size(); ++k) {
      ASSERT_GE(shard[k], 1);
      ASSERT_LE(shard[k], n);
      load[static_cast<size_t>(shard[k] - 1)] += costs[k];
    }
    // Longest first, each to the least loaded: no shard more than the largest case above
    // another.
    const auto [lo, hi] = std::minmax_element(load.begin(), load.end());
    EXPECT_LE(*hi - *lo, *std::max_element(costs.begin(), costs.end())) << n;
    EXPECT_DOUBLE_EQ(std::accumulate(load.begin(), load.end(), 0.0),
                     std::accumulate(costs.begin(), costs.end(), 0.0));
  }
  EXPECT_THROW(assign_shards({1.0, -1.0}, 2), std::invalid_argument);
}

json read_json(const std::string& file) {
  std::ifstream in(file);
  return json::parse(in);
}

// The cases without the time each took, the one field a rerun changes.
json deterministic(json cases) {
  for (json& c : cases) c.erase("seconds");
  return cases;
}

class ShardedConform : public testing::Test {
 protected:
  // Four scenes of different kinds, two methods: eight cases on the scalar backend, small.
  test::ProcessResult conform(const std::string& json_file, const std::vector<std::string>& more) {
    std::vector<std::string> args = {
        "conform", "--backend", "scalar",    "--method",
        "sphere",  "--method",  "analytic",  "--size",
        "48x27",   "-q",        "--gallery", std::string(FLATMARCH_SOURCE_DIR) + "/scenes",
        "--json",  json_file};
    for (const char* s : {"torus", "l_shape", "mirror_pentagon", "cone_pi"})
      args.insert(args.end(), {"--scene", s});
    args.insert(args.end(), more.begin(), more.end());
    return test::run_flatmarch(args, 300.0);
  }
  std::string dir_ = test::make_temp_dir();
};

TEST_F(ShardedConform, MergedShardsEqualAnUnshardedRun) {
  ASSERT_EQ(conform(dir_ + "/whole.json", {}).exit_code, 0);
  const json whole = read_json(dir_ + "/whole.json");
  ASSERT_EQ(whole["cases"].size(), 8u);
  for (const int n : {1, 2, 3, 7}) {
    std::vector<std::string> merge = {"merge"};
    for (int i = 1; i <= n; ++i) {
      const std::string file = dir_ + "/s" + std::to_string(i) + "of" + std::to_string(n) + ".json";
      const auto r = conform(file, {"--shard", std::to_string(i) + "/" + std::to_string(n)});
      ASSERT_EQ(r.exit_code, 0) << r.err;
      // Each shard says what it holds before it starts.
      EXPECT_NE(
          r.err.find("conform: shard " + std::to_string(i) + "/" + std::to_string(n) + " holds"),
          std::string::npos)
          << r.err;
      merge.push_back(file);
    }
    std::reverse(merge.begin() + 1, merge.end());  // any order
    merge.insert(merge.end(), {"-o", dir_ + "/merged.json"});
    const auto r = test::run_flatmarch(merge);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const json merged = read_json(dir_ + "/merged.json");
    EXPECT_EQ(deterministic(merged["cases"]), deterministic(whole["cases"])) << n << " shards";
    EXPECT_EQ(merged["options"], whole["options"]);
    EXPECT_EQ(merged["fingerprint"], whole["fingerprint"]);
  }
}

TEST_F(ShardedConform, AWrongSetFailsNamingTheFileAndWhy) {
  const auto shard = [&](const std::string& name, const std::string& i_of_n,
                         std::vector<std::string> more = {}) {
    more.insert(more.end(), {"--shard", i_of_n});
    EXPECT_EQ(conform(dir_ + "/" + name, more).exit_code, 0);
    return dir_ + "/" + name;
  };
  const std::string a = shard("a.json", "1/2"), b = shard("b.json", "2/2");
  const std::string other = shard("other.json", "2/2", {"--omega", "1.5"});
  const std::string third = shard("third.json", "1/3");
  const auto merge = [&](std::vector<std::string> files) {
    files.insert(files.begin(), "merge");
    files.insert(files.end(), {"-o", dir_ + "/out.json"});
    return test::run_flatmarch(files);
  };
  struct Wrong {
    std::vector<std::string> files;
    std::string says;
  };
  // Another build: the same file with another version of flatmarch in its fingerprint; another
  // kind of machine: another CPU.
  json doc = read_json(b);
  doc["fingerprint"]["build"]["flatmarch"] = "0.0.0-other";
  const std::string old = dir_ + "/old.json";
  std::ofstream(old) << doc.dump();
  doc = read_json(b);
  doc["fingerprint"]["cpu"]["model"] = "another CPU";
  const std::string elsewhere = dir_ + "/elsewhere.json";
  std::ofstream(elsewhere) << doc.dump();
  // Another node of the same kind, as a job array spreads its tasks: it merges.
  doc = read_json(b);
  doc["fingerprint"]["host"] = "node2";
  const std::string node2 = dir_ + "/node2.json";
  std::ofstream(node2) << doc.dump();
  const auto merged = merge({a, node2});
  EXPECT_EQ(merged.exit_code, 0) << merged.err;
  EXPECT_EQ(read_json(dir_ + "/out.json")["hosts"].size(), 2u);
  for (const Wrong& w : std::vector<Wrong>{
           {{a}, "shard 2/2 is missing"},
           {{a, b, b}, b + ": shard 2/2 again (also " + b + ")"},
           {{a, other}, other + ": its parameters differ from " + a + "'s"},
           {{a, third}, third + ": is a shard of 3, " + a + " of 2"},
           {{a, old}, old + ": made by another flatmarch build"},
           {{a, elsewhere}, elsewhere + ": measured on another kind of machine than " + a},
           {{dir_ + "/../nothing.json"}, "nothing.json"}}) {
    const auto r = merge(w.files);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(w.says), std::string::npos) << r.err;
  }
}

// --- Sharded reports.

// A small report: the CPU backends this build has (the scalar one, and the SIMD one where
// built), two methods, four scenes of three surface types, a coarse sweep with its re-checks,
// short scaling series.
reports::ReportOptions small_report() {
  reports::ReportOptions r;
  r.matrix.backends = cpu_backend_names();
  r.matrix.methods = {Method::analytic, Method::sphere};  // not the registry's order
  r.matrix.width = r.matrix.conform_width = 32;
  r.matrix.height = r.matrix.conform_height = 18;
  r.matrix.repetitions = 2;
  r.matrix.min_time = 0.001;
  r.sweep.methods = r.matrix.methods;
  r.sweep.eps = {1e-2, 1e-3, 1e-4, 1e-5};
  r.sweep.offset_factors = {2.0, 10.0};
  r.sweep.offset_fixed = {1e-2};
  r.sweep.width = 16;
  r.sweep.height = 9;
  r.sweep.repetitions = 1;
  r.scaling.backends = cpu_backend_names();
  r.scaling.methods = {Method::analytic};
  r.scaling.polygon_n = {2, 4};
  r.scaling.staircase_squares = {2, 4};
  r.scaling.resolutions = {{16, 9}, {32, 18}};
  r.scaling.max_distances = {10, 20};
  r.scaling.width = 32;
  r.scaling.height = 18;
  r.scaling.repetitions = 2;
  r.scaling.min_time = 0.001;
  return r;
}

std::vector<Scene> small_gallery() {
  std::vector<Scene> scenes;
  for (const char* s : {"torus", "l_shape", "mirror_pentagon", "cone_pi"})
    scenes.push_back(load_scene(std::string(FLATMARCH_SOURCE_DIR) + "/scenes/" + s + ".json"));
  return scenes;
}

// The recommendation names the first backend of the ranking with a method that passed on every
// scene, and that method.
void expect_fastest_recommended(const json& results, const std::string& what) {
  const json& rec = results["recommendation"];
  for (const json& b : results["ranking"])
    if (!b["best_method"].is_null()) {
      EXPECT_EQ(rec["backend"], b["backend"]) << what;
      EXPECT_EQ(rec["method"], b["best_method"]) << what;
      return;
    }
  ADD_FAILURE() << what << ": no backend has a method that passed on every scene";
}

TEST(ShardedReport, MergedShardsEqualAnUnshardedRun) {
  const std::vector<Scene> scenes = small_gallery();
  const reports::ReportOptions options = small_report();
  const json whole = reports::run_report(scenes, options, nullptr);
  const json expected = deterministic_report(whole);
  expect_fastest_recommended(whole, "unsharded");
  const size_t backends = cpu_backend_names().size();
  ASSERT_EQ(expected["matrix"].size(), 4u * 2u * backends);  // scenes x methods x backends
  ASSERT_FALSE(expected["points"].empty());
  ASSERT_FALSE(expected["confirmations"].empty());
  ASSERT_EQ(expected["scaling"].size(), 4u * backends);  // 4 families x backends
  const std::vector<std::pair<std::string, double>> cases = reports::report_cases(scenes, options);
  for (const int n : {1, 2, 3, 7}) {
    std::vector<std::pair<std::string, json>> shards;
    std::vector<std::string> progress;
    for (int i = n; i >= 1; --i) {  // in any order
      reports::ReportOptions o = options;
      o.shard = reports::Shard{i, n};
      json r = reports::run_report(
          scenes, o, [&](const std::string& stage, const std::string& line, int, int) {
            if (stage == "shard") progress.push_back(line);
          });
      EXPECT_FALSE(r.contains("ranking")) << "a shard ranks nothing";
      EXPECT_EQ(r["shard"]["cases"].size(), cases.size());
      shards.emplace_back("shard" + std::to_string(i), std::move(r));
    }
    // Each shard says what it holds and its estimated time before it starts.
    ASSERT_EQ(progress.size(), static_cast<size_t>(n));
    EXPECT_EQ(progress.back().rfind("shard 1/" + std::to_string(n) + " holds", 0), 0u)
        << progress.back();
    const json merged = reports::merge_report(shards);
    EXPECT_EQ(deterministic_report(merged), expected) << n << " shards";
    expect_fastest_recommended(merged, std::to_string(n) + " shards");
    EXPECT_EQ(merged["options"], whole["options"]);
    // Timings present for every case.
    for (const json& c : merged["matrix"]["cases"]) {
      EXPECT_GT(c["time_ms"].get<double>(), 0.0) << c["name"];
      EXPECT_EQ(c["time_samples_ms"].size(), 2u) << c["name"];
    }
    for (const json& p : merged["sweep"]["points"]) EXPECT_GT(p["time_ms"].get<double>(), 0.0);
    for (const json& s : merged["scaling"]["series"])
      EXPECT_EQ(s["time_ms"].size(), 2u) << s["family"];
    EXPECT_EQ(merged["shards"].size(), static_cast<size_t>(n));
  }
}

TEST(ShardedReport, AWrongSetFailsNamingTheFileAndWhy) {
  const std::vector<Scene> scenes = small_gallery();
  reports::ReportOptions o = small_report();
  o.sweep_enabled = o.scaling_enabled = false;
  const auto shard = [&](int i, int n, double eps = 1e-4) {
    reports::ReportOptions s = o;
    s.shard = reports::Shard{i, n};
    s.matrix.params.eps = eps;
    return reports::run_report(scenes, s, nullptr);
  };
  const json a = shard(1, 2), b = shard(2, 2), other = shard(2, 2, 1e-3);
  json truncated = b;
  truncated["matrix"]["cases"].erase(truncated["matrix"]["cases"].size() - 1);
  json conform = b;
  conform["format"] = "flatmarch-conform/1";
  const auto says = [](const std::vector<std::pair<std::string, json>>& files) {
    try {
      reports::merge_report(files);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("merged");
  };
  EXPECT_EQ(says({{"a", a}, {"b", b}}), "merged");
  EXPECT_EQ(says({{"a", a}}), "shard 2/2 is missing (given 1 of 2)");
  EXPECT_EQ(says({{"a", a}, {"b", b}, {"b2", b}}).rfind("b2: shard 2/2 again (also b)", 0), 0u);
  EXPECT_EQ(says({{"a", a}, {"other", other}}).rfind("other: its parameters differ from a's", 0),
            0u);
  EXPECT_NE(says({{"a", a}, {"cut", truncated}}).find("cut: has no results of matrix/"),
            std::string::npos);
  EXPECT_EQ(says({{"a", a}, {"c", conform}}).rfind("c: not the results of `flatmarch report`", 0),
            0u);
}

// The command line: shards written by `report --shard`, merged by `flatmarch merge` with the
// images gathered; a bad set exits 2 naming the file; several machines merge apart.
TEST(ShardedReport, ReportShardsMergeOnTheCommandLine) {
  const std::string dir = test::make_temp_dir();
  const auto report = [&](const std::string& out, const std::string& i_of_n) {
    return test::run_flatmarch({"report",
                                "--backend",
                                "scalar",
                                "--method",
                                "analytic",
                                "--scene",
                                "torus",
                                "--scene",
                                "cone_pi",
                                "--gallery",
                                std::string(FLATMARCH_SOURCE_DIR) + "/scenes",
                                "--size",
                                "32x18",
                                "--conform-size",
                                "32x18",
                                "--repetitions",
                                "2",
                                "--min-time",
                                "0.001",
                                "--no-sweep",
                                "--no-scaling",
                                "-q",
                                "-o",
                                out,
                                "--shard",
                                i_of_n},
                               300.0);
  };
  for (const char* i : {"1", "2"}) {
    const auto r = report(dir + "/s" + i, std::string(i) + "/2");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("report: shard " + std::string(i) + "/2: wrote"), std::string::npos);
  }
  auto r = test::run_flatmarch({"merge", dir + "/s2/results.json", dir + "/s1/results.json", "-o",
                                dir + "/m/results.json", "--no-html"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json merged = read_json(dir + "/m/results.json");
  EXPECT_EQ(merged["matrix"]["cases"].size(), 2u);
  EXPECT_EQ(merged["ranking"][0]["backend"], "scalar");
  for (const char* scene : {"torus", "cone_pi"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/m/images/scalar/" + scene + ".png")) << scene;
  r = test::run_flatmarch({"merge", dir + "/s1/results.json", "-o", dir + "/m/x.json"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("shard 2/2 is missing"), std::string::npos) << r.err;
  // Shard 2 measured on another kind of machine, with its own shard 1: two machines compared.
  json elsewhere = read_json(dir + "/s2/results.json");
  elsewhere["fingerprint"]["cpu"]["model"] = "another CPU";
  elsewhere["fingerprint"]["host"] = "elsewhere";
  std::ofstream(dir + "/e2.json") << elsewhere.dump();
  elsewhere = read_json(dir + "/s1/results.json");
  elsewhere["fingerprint"]["cpu"]["model"] = "another CPU";
  elsewhere["fingerprint"]["host"] = "elsewhere";
  std::ofstream(dir + "/e1.json") << elsewhere.dump();
  r = test::run_flatmarch({"merge", dir + "/s1/results.json", dir + "/s2/results.json",
                           dir + "/e1.json", dir + "/e2.json", "-o", dir + "/c/results.json",
                           "--no-html"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir + "/c/results-elsewhere.json"));
  EXPECT_EQ(read_json(dir + "/c/results-elsewhere.json")["fingerprint"]["cpu"]["model"],
            "another CPU");
}

// `sweep --shard I/N`: whole groups (surface type x method) per shard; the merge makes the
// analysis again and equals an unsharded sweep.
TEST(ShardedSweep, MergedShardsEqualAnUnshardedSweep) {
  const std::string dir = test::make_temp_dir();
  const auto sweep = [&](const std::string& file, std::vector<std::string> more) {
    std::vector<std::string> args = {
        "sweep",         "--scene",   "torus",
        "--scene",       "cone_pi",   "--scene",
        "mirror_square", "--gallery", std::string(FLATMARCH_SOURCE_DIR) + "/scenes",
        "--method",      "analytic",  "--method",
        "sphere",        "--eps",     "1e-2",
        "--eps",         "1e-3",      "--eps",
        "1e-4",          "--size",    "16x9",
        "--repetitions", "1",         "-q",
        "--json",        file};
    args.insert(args.end(), more.begin(), more.end());
    return test::run_flatmarch(args, 300.0);
  };
  ASSERT_EQ(sweep(dir + "/whole.json", {}).exit_code, 0);
  std::vector<std::string> merge = {"merge"};
  for (const char* i : {"1", "2", "3"}) {
    const auto r = sweep(dir + "/s" + i + ".json", {"--shard", std::string(i) + "/3"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("sweep: shard " + std::string(i) + "/3 holds"), std::string::npos);
    merge.push_back(dir + "/s" + i + ".json");
  }
  merge.insert(merge.end(), {"-o", dir + "/merged.json"});
  const auto r = test::run_flatmarch(merge);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json whole = read_json(dir + "/whole.json"), merged = read_json(dir + "/merged.json");
  const auto strip = [](json doc) {
    for (json& p : doc["points"]) p.erase("time_ms");
    for (json& g : doc["analysis"]) {
      g.erase("pareto");
      for (json& c : g["grid"]) c.erase("time_ms");
      if (!g["recommended"].is_null()) g["recommended"].erase("time_ms");
    }
    return json{doc["points"], doc["confirmations"], doc["analysis"]};
  };
  ASSERT_EQ(whole["analysis"].size(), 12u);  // 3 surface types x 2 methods x f32, f64
  EXPECT_EQ(strip(merged), strip(whole));
  EXPECT_EQ(merged["options"], whole["options"]);
  // A conform shard among sweep shards, and a shard missing.
  json other = read_json(dir + "/s2.json");
  other["format"] = "flatmarch-conform/1";
  std::ofstream(dir + "/other.json") << other.dump();
  auto wrong = test::run_flatmarch(
      {"merge", dir + "/s1.json", dir + "/other.json", dir + "/s3.json", "-o", dir + "/w.json"});
  EXPECT_EQ(wrong.exit_code, 2);
  EXPECT_NE(wrong.err.find(dir + "/other.json: not the results of `flatmarch sweep`"),
            std::string::npos)
      << wrong.err;
  wrong = test::run_flatmarch({"merge", dir + "/s1.json", dir + "/s3.json", "-o", dir + "/w.json"});
  EXPECT_EQ(wrong.exit_code, 2);
  EXPECT_NE(wrong.err.find("shard 2/3 is missing"), std::string::npos) << wrong.err;
}

}  // namespace
}  // namespace flatmarch
