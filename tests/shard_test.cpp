// Sharded runs (issue 24): the split of a run's cases among N shards, and `flatmarch merge`
// putting `conform --shard I/N` results back together as one unsharded run writes them.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <numeric>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "reports/shard.hpp"
#include "tests/process.hpp"

namespace flatmarch {
namespace {

using nlohmann::json;
using reports::assign_shards;
using reports::parse_shard;

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

}  // namespace
}  // namespace flatmarch
