// The report page's tables (reports/page.hpp) on small results written by hand: each count, group,
// share and change as worked out here from the cases' figures.
#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

#include "reports/page.hpp"

namespace flatmarch::reports {
namespace {

using nlohmann::json;

// A matrix case: `verdict` "" leaves it unjudged (no accuracy), "error" gives it an error.
json make_case(const std::string& backend, const std::string& method, const std::string& scene,
               const std::string& verdict, double hit = 0.0, double ambiguous = 0.0,
               double rays_per_s = 1e6) {
  json c = {{"backend", backend},
            {"method", method},
            {"scene", scene},
            {"surface_type", scene == "torus_prism" ? "prism" : "translation"},
            {"name", backend + "/" + method + "/" + scene + "/64x36"},
            {"counters", {{"rays_per_s", rays_per_s}, {"steps_mean", 10.0}}}};
  if (verdict == "error") {
    c["error"] = "it broke";
  } else if (!verdict.empty()) {
    c["accuracy"] = {
        {"verdict", verdict},
        {"passed", verdict == "pass"},
        {"hit_mismatch", hit},
        {"ambiguous", ambiguous},
        {"failed_checks", verdict == "pass" ? json::array() : json{"hit_rate 0.9 < 0.99"}},
        {"limit", verdict == "limit" ? "out of steps" : ""},
        {"failures", {{"stuck", verdict == "fail" ? 3 : 0}}}};
  }
  return c;
}

json make_results(json cases) {
  return {{"fingerprint", {{"cpu", {{"model", "test CPU"}}}}},
          {"registry",
           {{"backends", {"scalar", "fast"}},
            {"methods", {"sphere", "analytic"}},
            {"surface_types", {"translation", "prism"}}}},
          {"options",
           {{"scenes", {"torus", "torus_prism"}}, {"size", "64x36"}, {"conform_size", "64x36"}}},
          {"matrix", {{"cases", std::move(cases)}}},
          {"ranking", json::array()}};
}

TEST(PageTables, CountsVerdictsPerBackendAndMethod) {
  const json results = make_results({make_case("scalar", "sphere", "torus", "pass"),
                                     make_case("scalar", "sphere", "torus_prism", "limit"),
                                     make_case("fast", "sphere", "torus", "fail"),
                                     make_case("fast", "analytic", "torus", "error"),
                                     make_case("fast", "analytic", "torus_prism", "")});
  const json t = page_tables(results, nullptr);
  EXPECT_EQ(t["verdicts"], json({"pass", "limit", "fail", "error", nullptr}));
  const json& s = t["summary"];
  EXPECT_EQ(s["total"], 4);  // the unjudged case is no verdict
  // pass, limit, fail always; error because there is one; the unfinished ones not at zero.
  EXPECT_EQ(s["shown"], json::parse(R"([{"verdict":"pass","n":1},{"verdict":"limit","n":1},
                                        {"verdict":"fail","n":1},{"verdict":"error","n":1}])"));
  ASSERT_EQ(s["rows"].size(), 2u);
  EXPECT_EQ(s["rows"][0]["backend"], "scalar");
  EXPECT_EQ(s["rows"][0]["cells"][0]["cls"], "limit");
  EXPECT_TRUE(s["rows"][0]["cells"][1].is_null());  // no analytic case on scalar
  EXPECT_EQ(s["rows"][1]["cells"][0]["cls"], "bad");
  EXPECT_EQ(s["rows"][1]["cells"][1]["parts"].back(), json({{"n", 1}, {"verdict", "error"}}));
}

TEST(PageTables, GroupsCasesThatFailAlikeAndSumsFailureClasses) {
  const json results = make_results({make_case("scalar", "sphere", "torus", "fail"),
                                     make_case("fast", "sphere", "torus", "fail"),
                                     make_case("fast", "sphere", "torus_prism", "limit"),
                                     make_case("fast", "analytic", "torus", "error")});
  const json f = page_tables(results, nullptr)["failures"];
  // Totals per (backend, method), sorted: fast/analytic, fast/sphere, scalar/sphere.
  ASSERT_EQ(f["totals"].size(), 3u);
  EXPECT_EQ(f["totals"][1]["backend"], "fast");
  EXPECT_EQ(f["totals"][1]["method"], "sphere");
  EXPECT_EQ(f["totals"][1]["cases"], 2);
  EXPECT_EQ(f["totals"][1]["limit"], 1);
  EXPECT_EQ(f["totals"][1]["bad"], 1);
  EXPECT_EQ(f["totals"][0]["bad"], 1);  // the error
  // stuck is the first failure class: 3 rays from the one failing case.
  EXPECT_EQ(f["totals"][1]["failures"][0], 3);
  // Bad verdicts first by scene and method: the error (torus, analytic), then both backends'
  // alike failures (torus, sphere) in one row, then the limit.
  ASSERT_EQ(f["cases"].size(), 3u);
  EXPECT_EQ(f["cases"][0]["verdict"], "error");
  EXPECT_EQ(f["cases"][0]["error"], "it broke");
  EXPECT_EQ(f["cases"][1]["backends"], json({"fast", "scalar"}));
  EXPECT_EQ(f["cases"][1]["size"], "64x36");
  EXPECT_EQ(f["cases"][1]["checks"][0]["line"], "hit_rate 0.9 < 0.99");
  EXPECT_FALSE(f["cases"][1]["checks"][0]["meaning"].get<std::string>().empty());
  EXPECT_EQ(f["cases"][2]["verdict"], "limit");
  EXPECT_EQ(f["cases"][2]["limit"], "out of steps");
}

TEST(PageTables, AmbiguityIsTheFirstBackendsShareWithOthersNamed) {
  const json results =
      make_results({make_case("fast", "sphere", "torus", "pass", 0.0, 0.10),
                    make_case("scalar", "sphere", "torus", "pass", 0.0, 0.02),
                    make_case("scalar", "sphere", "torus_prism", "pass", 0.0, 0.30),
                    make_case("fast", "sphere", "torus_prism", "pass", 0.0, 0.30)});
  const json a = page_tables(results, nullptr)["ambiguity"];
  EXPECT_EQ(a["first_backends"], json({"scalar"}));  // first in the registry, not in the matrix
  EXPECT_EQ(a["methods"], json({"sphere"}));
  const json& torus = a["rows"][0]["cells"][0];
  EXPECT_DOUBLE_EQ(torus["share"].get<double>(), 0.02);
  EXPECT_EQ(torus["others"], json::parse(R"([{"backend":"fast","share":0.1}])"));
  EXPECT_FALSE(torus["over_goal"].get<bool>());             // 2% under sphere's 12% outside prisms
  EXPECT_TRUE(a["rows"][1]["cells"][0]["others"].empty());  // both found 30%
  EXPECT_DOUBLE_EQ(a["means"][0].get<double>(), (0.02 + 0.30) / 2);
}

TEST(PageTables, LaneEfficiencyIsOneThreadOverScalarOverLanes) {
  json simd = make_case("fast", "sphere", "torus", "pass");
  simd["counters"]["lane_utilisation"] = 0.9;
  simd["counters"]["lanes"] = 8.0;
  simd["counters"]["one_thread_rays_per_s"] = 4e6;
  const json lanes =
      page_tables(make_results({simd, make_case("scalar", "sphere", "torus", "pass", 0, 0, 1e6)}),
                  nullptr)["lanes"];
  const json& cell = lanes["rows"][0]["cells"][0];
  EXPECT_DOUBLE_EQ(cell["busy"].get<double>(), 0.9);
  EXPECT_DOUBLE_EQ(cell["efficiency"].get<double>(), 4e6 / 1e6 / 8);
  EXPECT_EQ(cell["lanes"], 8);
}

TEST(PageTables, ChangesSinceAnEarlierRunWorseFirst) {
  const json before = make_results({make_case("scalar", "sphere", "torus", "pass", 0.0, 0.0, 1e6),
                                    make_case("fast", "sphere", "torus", "fail", 0.0, 0.0, 1e6),
                                    make_case("fast", "analytic", "torus", "pass")});
  const json now = make_results({make_case("scalar", "sphere", "torus", "fail", 0.01, 0.0, 1e6),
                                 make_case("fast", "sphere", "torus", "pass", 0.0, 0.0, 2e6),
                                 make_case("scalar", "analytic", "torus", "pass")});
  const json p = page_tables(now, &before)["previous"];
  EXPECT_EQ(p["common"], 2);
  EXPECT_EQ(p["new"], 1);
  EXPECT_EQ(p["gone"], 1);
  ASSERT_EQ(p["verdicts"].size(), 2u);
  EXPECT_EQ(p["verdicts"][0]["case"], "scalar/sphere/torus/64x36");  // worse, first
  EXPECT_TRUE(p["verdicts"][0]["worse"].get<bool>());
  EXPECT_FALSE(p["verdicts"][1]["worse"].get<bool>());
  // The hit moved 1 percentage point; the other case's speed doubled.
  ASSERT_EQ(p["figures"].size(), 2u);
  EXPECT_DOUBLE_EQ(p["figures"][0]["hit"].get<double>(), 0.01);
  EXPECT_DOUBLE_EQ(p["figures"][1]["speed"].get<double>(), 2.0);
  EXPECT_TRUE(p["same_cpu"].get<bool>());
}

TEST(PageTables, MachinesComparedByGeometricMeanOfFrameTimes) {
  json a = make_results({}), b = make_results({});
  for (auto [doc, t1, t2] : {std::tuple{&a, 2.0, 8.0}, std::tuple{&b, 1.0, 2.0}}) {
    json c1 = make_case("scalar", "sphere", "torus", "pass"),
         c2 = make_case("scalar", "sphere", "torus_prism", "pass");
    c1["time_ms"] = t1;
    c2["time_ms"] = t2;
    (*doc)["matrix"]["cases"] = {c1, c2};
  }
  b["fingerprint"]["gpu"] = {{"device", "Big GPU"}, {"software", false}};
  const json t = machines_tables({{"one/results.json", a}, {"two/results.json", b}});
  EXPECT_EQ(t["names"], json({"one: test CPU", "two: test CPU, GPU Big GPU"}));
  ASSERT_EQ(t["speedups"].size(), 1u);
  EXPECT_DOUBLE_EQ(t["speedups"][0]["mean"].get<double>(), std::sqrt(2.0 * 4.0));
  EXPECT_DOUBLE_EQ(t["speedups"][0]["least"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(t["speedups"][0]["greatest"].get<double>(), 4.0);
  EXPECT_EQ(t["machine_rows"][0], json({"CPU", "test CPU, ? threads", "test CPU, ? threads"}));
}

}  // namespace
}  // namespace flatmarch::reports
