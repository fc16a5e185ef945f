// Supervised cases (reports/supervise.hpp): a case that crashes, hangs or runs out of memory costs
// only itself. This program is also the command line (`isolation_test --flatmarch-cli ARGS`, its
// own main below), so that its runs have the test programs' faulty backend and their workers are
// this program again.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <thread>

#include "backends/backend.hpp"
#include "cli/commands.hpp"
#include "reports/supervise.hpp"
#include "tests/process.hpp"

extern char** environ;

namespace flatmarch {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

constexpr const char* kCliFlag = "--flatmarch-cli";

std::string self() {
  return cli::this_program("isolation_test");
}

json read_json(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

// A case's deterministic fields: all but its time.
json deterministic(json c) {
  c.erase("seconds");
  return c;
}

std::string key(const json& c) {
  return c["backend"].get<std::string>() + "/" + c["method"].get<std::string>() + "/" +
         c["scene"].get<std::string>();
}

// `flatmarch conform` over 30 cases: the faulty and scalar backends, five scenes, three methods.
test::ProcessResult conform(const std::string& json_path, const std::vector<std::string>& more,
                            const char* faults) {
  if (faults)
    setenv("FLATMARCH_FAULTY", faults, 1);
  else
    unsetenv("FLATMARCH_FAULTY");
  std::vector<std::string> argv{self(), kCliFlag, "conform", "--backend", "faulty", "--backend",
                                "scalar", "--size", "32x18", "--json", json_path,
                                // The hang's wait: 6 s, and 5 for its fresh worker's start
                                // (not the 30 a browser may take: 36 s of the test's 41);
                                // long enough for the oom case to fill its 2 GiB under a
                                // loaded 2-core machine's other tests (3 s was not, once, in a
                                // -O1 build).
                                "--deadline-floor", "6", "--worker-start", "5", "--worker-memory",
                                "2", "--gallery", FLATMARCH_SOURCE_DIR "/scenes"};
  for (const char* scene : {"torus", "l_shape", "cube", "klein_bottle", "mirror_square"})
    argv.insert(argv.end(), {"--scene", scene});
  argv.insert(argv.end(), more.begin(), more.end());
  test::ProcessResult r = test::run_process(argv, 300.0);
  unsetenv("FLATMARCH_FAULTY");
  return r;
}

TEST(IsolatedConform, ACrashAHangAndAnOutOfMemoryCostOnlyTheirOwnCases) {
  const std::string dir = test::make_temp_dir();
#ifdef FLATMARCH_SANITIZE_BUILD
  // No address-space limit holds a sanitizer's shadow memory: an abort stands in for the
  // allocation without bound, and only the crash and the hang are checked.
  const char* faults = "crash=torus/analytic,hang=l_shape/sphere,abort=cube/relaxed";
#else
  const char* faults = "crash=torus/analytic,hang=l_shape/sphere,oom=cube/relaxed";
#endif
  const test::ProcessResult clean = conform(dir + "/clean.json", {"--isolate", "none"}, nullptr);
  const test::ProcessResult faulty = conform(dir + "/faulty.json", {}, faults);
  // Exit 1: the faulty backend fails every case it finishes, and three did not finish.
  ASSERT_EQ(clean.exit_code, 1) << clean.err;
  ASSERT_EQ(faulty.exit_code, 1) << faulty.out << faulty.err;
  const json a = read_json(dir + "/clean.json"), b = read_json(dir + "/faulty.json");
  ASSERT_EQ(a["cases"].size(), 30u);
  ASSERT_EQ(b["cases"].size(), 30u);
  std::map<std::string, json> unfinished;
  for (size_t k = 0; k < 30; ++k) {
    const json& c = b["cases"][k];
    ASSERT_EQ(key(c), key(a["cases"][k])) << "the cases in another order";
    const std::string verdict = c.value("verdict", "");
    if (reports::is_supervision_verdict(verdict))
      unfinished[key(c)] = c;
    else
      EXPECT_EQ(deterministic(c), deterministic(a["cases"][k])) << key(c);
  }
  ASSERT_EQ(unfinished.size(), 3u) << faulty.out;
  const json& crash = unfinished["faulty/analytic/torus"];
  EXPECT_EQ(crash["verdict"], "crash");
#ifdef FLATMARCH_SANITIZE_BUILD
  // AddressSanitizer catches the SIGSEGV, reports it and exits 1.
  EXPECT_EQ(crash["exit_code"], 1) << crash.dump();
  EXPECT_NE(crash["stderr_tail"].get<std::string>().find("AddressSanitizer"), std::string::npos);
  const std::string crash_line = "faulty/analytic/torus  CRASH (exit 1)";
#else
  EXPECT_EQ(crash["signal_name"], "SIGSEGV") << crash.dump();
  const std::string crash_line = "faulty/analytic/torus  CRASH (SIGSEGV)";
#endif
  const json& hang = unfinished["faulty/sphere/l_shape"];
  EXPECT_EQ(hang["verdict"], "timeout");
  // Its deadline: the floor, and the start a fresh worker is given where it was one.
  EXPECT_LE(hang["deadline_seconds"].get<double>(), 6.0 + 5.0) << hang.dump();
  EXPECT_GE(hang["seconds"].get<double>(), 3.0);
  EXPECT_LT(hang["seconds"].get<double>(), 60.0);
  const json& third = unfinished["faulty/relaxed/cube"];
#ifdef FLATMARCH_SANITIZE_BUILD
  EXPECT_EQ(third["verdict"], "crash");
#else
  EXPECT_EQ(third["verdict"], "out_of_memory") << third.dump();
  EXPECT_EQ(third["memory_limit_bytes"], 2.0 * 1024 * 1024 * 1024);
#endif
  // The table says so too, and the summary counts them.
  EXPECT_NE(faulty.out.find(crash_line), std::string::npos) << faulty.out;
  EXPECT_NE(faulty.out.find("faulty/sphere/l_shape  TIMEOUT"), std::string::npos);
  EXPECT_NE(faulty.out.find("3 did not finish"), std::string::npos) << faulty.out;
}

// A small `flatmarch report` of the scalar backend into `out`: two matrix cases, one sweep group
// (both scenes are translation surfaces) and eight scaling series, 11 cases in all.
std::vector<std::string> small_report(const std::string& out) {
  std::vector<std::string> argv{self(),
                                kCliFlag,
                                "report",
                                "--backend",
                                "scalar",
                                "--method",
                                "analytic",
                                "--size",
                                "32x18",
                                "--conform-size",
                                "32x18",
                                "--sweep-size",
                                "16x9",
                                "--min-time",
                                "0.001",
                                "--repetitions",
                                "2",
                                "--no-html",
                                "-q",
                                "-o",
                                out,
                                "--gallery",
                                FLATMARCH_SOURCE_DIR "/scenes"};
  for (const char* scene : {"torus", "l_shape"}) argv.insert(argv.end(), {"--scene", scene});
  return argv;
}

std::vector<std::string> with(std::vector<std::string> argv, const std::string& more) {
  argv.push_back(more);
  return argv;
}

// The cases' keys of a journal's records, in order.
std::vector<std::string> journal_keys(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> keys;
  for (std::string line; std::getline(in, line);) {
    const json j = json::parse(line);
    if (j.contains("key")) keys.push_back(j["key"]);
  }
  return keys;
}

// A report's deterministic figures: each matrix case's accuracy and frame counters, each sweep
// point's accuracy and steps, each scaling series' steps and crossings (timings left out).
json report_figures(const json& results) {
  json out = {{"matrix", json::array()}, {"sweep", json::array()}, {"scaling", json::array()}};
  for (const json& c : results["matrix"]["cases"]) {
    json counters = json::object();
    for (const char* k : {"steps_mean", "steps_p99", "crossings_mean", "out_of_steps"})
      counters[k] = c["counters"].value(k, -1.0);
    json accuracy = c["accuracy"];
    accuracy.erase("seconds");
    out["matrix"].push_back({{"name", c["name"]}, {"accuracy", accuracy}, {"counters", counters}});
  }
  for (json p : results["sweep"]["points"]) {
    p.erase("time_ms");
    p["accuracy"].erase("seconds");
    out["sweep"].push_back(p);
  }
  for (const json& s : results["scaling"]["series"])
    out["scaling"].push_back({{"family", s["family"]},
                              {"backend", s["backend"]},
                              {"x", s["x"]},
                              {"steps_mean", s["steps_mean"]},
                              {"crossings_mean", s["crossings_mean"]}});
  return out;
}

// Reports stopped by SIGKILL at random moments (the process gone at once, as by a scheduler or a
// lost machine) and resumed: every one ends with the uninterrupted run's figures, each case
// measured once.
TEST(ResumedReport, RunsKilledAtRandomAndResumedEqualAnUninterruptedOne) {
  const std::string dir = test::make_temp_dir();
  const auto whole_start = std::chrono::steady_clock::now();
  const test::ProcessResult whole = test::run_process(small_report(dir + "/whole"), 300.0);
  double whole_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - whole_start).count();
  ASSERT_FALSE(whole.timed_out);
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  const json expected = report_figures(read_json(dir + "/whole/results.json"));
  ASSERT_EQ(expected["matrix"].size(), 2u);
  ASSERT_EQ(expected["scaling"].size(), 4u);
  const size_t cases = journal_keys(dir + "/whole/results.json.journal").size();
  ASSERT_EQ(cases, 7u);
  // Ten moments over a run of seven cases: most fall inside one case or another, a few past the
  // end. (Twenty runs took 90 s of CI's two cores.)
#ifdef FLATMARCH_SANITIZE_BUILD
  const int runs = 4;
#else
  const int runs = 10;
#endif
  std::mt19937 random(74);
  // The moments are drawn up to a little past the run's time, the shortest an uninterrupted run
  // has taken so far: the machine's other tests load it unevenly (ctest -j), and a whole run
  // timed while it was busy would put most moments past the end of the runs after it.
  std::uniform_real_distribution<double> fraction(0.0, 1.0);
  int interrupted = 0;
  for (int run = 0; run < runs; ++run) {
    const std::string out = dir + "/run-" + std::to_string(run);
    const double moment = 0.02 + fraction(random) * (1.1 * whole_seconds - 0.02);
    const auto start = std::chrono::steady_clock::now();
    const test::ProcessResult first = test::run_process(small_report(out), moment);
    interrupted += first.timed_out;
    if (!first.timed_out)
      whole_seconds =
          std::min(whole_seconds,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    // Resumed until it finishes (the first resume does, unless it too is stopped: it is not).
    const test::ProcessResult rest = test::run_process(with(small_report(out), "--resume"), 300.0);
    ASSERT_FALSE(rest.timed_out);
    ASSERT_EQ(rest.exit_code, 0) << rest.err;
    EXPECT_EQ(report_figures(read_json(out + "/results.json")), expected) << "run " << run;
    // Each case recorded once, none lost: the journal holds every key once.
    std::vector<std::string> keys = journal_keys(out + "/results.json.journal");
    std::sort(keys.begin(), keys.end());
    EXPECT_EQ(std::adjacent_find(keys.begin(), keys.end()), keys.end()) << "a case twice";
    EXPECT_EQ(keys.size(), cases) << "run " << run;
  }
  // Most runs were stopped part way (the moments reach past the run's end for a few).
  EXPECT_GE(interrupted, runs / 2);
}

// The report's progress log (--progress-log): a line per case run, in stages as the cases ran,
// each with the stage's count and its estimate of the time left, none left after its last case.
TEST(ReportProgress, LogsEachCaseOnceWithItsStagesEstimate) {
  const std::string dir = test::make_temp_dir();
  std::vector<std::string> argv = small_report(dir + "/out");
  argv.insert(argv.end(), {"--progress-log", dir + "/progress.jsonl"});
  const test::ProcessResult r = test::run_process(argv, 300.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(dir + "/progress.jsonl");
  std::vector<json> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(json::parse(line));
  ASSERT_EQ(lines.size(), 7u);
  std::vector<std::string> stages, keys;
  double t = 0.0;
  for (const json& l : lines) {
    if (stages.empty() || stages.back() != l["stage"]) stages.push_back(l["stage"]);
    keys.push_back(l["key"]);
    EXPECT_EQ(l["key"].get<std::string>().rfind(l["stage"].get<std::string>() + "/", 0), 0u);
    EXPECT_GE(l["t"].get<double>(), t);
    t = l["t"];
    EXPECT_GE(l["seconds"].get<double>(), 0.0);
    EXPECT_GE(l["left"].get<double>(), 0.0);
  }
  EXPECT_EQ(stages, (std::vector<std::string>{"matrix", "sweep", "scaling"}));
  // Each stage counts its own cases, one more a line, and expects nothing after its last.
  // (The quick scaling series on the one CPU backend measured: 4 families x 1 method.)
  const std::map<std::string, int> totals = {{"matrix", 2}, {"sweep", 1}, {"scaling", 4}};
  std::map<std::string, int> done;
  for (const json& l : lines) {
    const std::string stage = l["stage"];
    EXPECT_EQ(l["total"].get<int>(), totals.at(stage));
    EXPECT_EQ(l["done"].get<int>(), ++done[stage]);
    if (done[stage] == totals.at(stage)) {
      EXPECT_EQ(l["left"].get<double>(), 0.0);
    }
  }
  std::vector<std::string> journaled = journal_keys(dir + "/out/results.json.journal");
  std::sort(keys.begin(), keys.end());
  std::sort(journaled.begin(), journaled.end());
  EXPECT_EQ(keys, journaled);
}

// A report whose faulty backend crashes on one case: the case is in the results with its
// verdict, the others as a clean run's, and the gate calls it a regression where the baseline
// had it pass.
TEST(IsolatedReport, ACrashedCaseIsRecordedAndIsARegression) {
  const std::string dir = test::make_temp_dir();
  const auto report = [&](const std::string& out, std::vector<std::string> more) {
    std::vector<std::string> argv = small_report(out);
    argv.insert(argv.end(), {"--backend", "faulty", "--no-sweep", "--no-scaling"});
    argv.insert(argv.end(), more.begin(), more.end());
    return test::run_process(argv, 300.0);
  };
  unsetenv("FLATMARCH_FAULTY");
  const test::ProcessResult clean =
      report(dir + "/clean", {"--isolate", "none", "--write-baseline", dir + "/baseline.json"});
  ASSERT_EQ(clean.exit_code, 0) << clean.err;
  setenv("FLATMARCH_FAULTY", "crash=torus/analytic", 1);
  const test::ProcessResult crashed = report(dir + "/crashed", {});
  unsetenv("FLATMARCH_FAULTY");
  ASSERT_EQ(crashed.exit_code, 0) << crashed.err;
  EXPECT_NE(crashed.out.find("1 cases did not finish"), std::string::npos) << crashed.out;
  const json a = read_json(dir + "/clean/results.json"),
             b = read_json(dir + "/crashed/results.json");
  ASSERT_EQ(a["matrix"]["cases"].size(), 4u);
  ASSERT_EQ(b["matrix"]["cases"].size(), 4u);
  for (size_t k = 0; k < 4; ++k) {
    const json& c = b["matrix"]["cases"][k];
    ASSERT_EQ(c["name"], a["matrix"]["cases"][k]["name"]) << "the cases in another order";
    if (c["backend"] == "faulty" && c["scene"] == "torus") {
      EXPECT_EQ(c["verdict"], "crash") << c.dump();
      EXPECT_NE(c["error"].get<std::string>().find("crash"), std::string::npos);
    } else {
      EXPECT_EQ(c["accuracy"], a["matrix"]["cases"][k]["accuracy"]) << c["name"];
    }
  }
  ASSERT_EQ(b["unfinished"].size(), 1u);
  EXPECT_EQ(b["unfinished"][0]["key"], "matrix/faulty/analytic/torus");
  EXPECT_EQ(b["unfinished"][0]["stage"], "matrix");
  // The ranking counts the crash as an error of its backend.
  for (const json& r : b["ranking"])
    if (r["backend"] == "faulty") {
      EXPECT_EQ(r["errors"], 1) << r.dump();
    }
  // A baseline in which the case passed (the faulty backend fails everything it finishes, so the
  // clean run's baseline is edited to say it passed): the crash is a regression of its verdict.
  json baseline = read_json(dir + "/baseline.json");
  bool edited = false;
  for (auto& [name, figures] : baseline["cases"].items())
    if (name.find("faulty/analytic/torus") == 0) {
      figures["passed"] = true;
      figures["verdict"] = "pass";
      edited = true;
    }
  ASSERT_TRUE(edited) << baseline["cases"].dump();
  { std::ofstream(dir + "/passed.json") << baseline.dump(); }
  setenv("FLATMARCH_FAULTY", "crash=torus/analytic", 1);
  const test::ProcessResult gated = report(dir + "/gated", {"--baseline", dir + "/passed.json"});
  unsetenv("FLATMARCH_FAULTY");
  EXPECT_EQ(gated.exit_code, 1) << gated.out << gated.err;
  const json gate = read_json(dir + "/gated/gate.json");
  bool found = false;
  for (const json& g : gate["regressions"])
    if (g["case"].get<std::string>().find("faulty/analytic/torus") == 0 && g["figure"] == "verdict")
      found = g["was"] == "pass" && g["now"] == "crash";
  EXPECT_TRUE(found) << gate.dump();
}

// SIGTERM (a scheduler's notice) and SIGINT (Ctrl-C): the case under way abandoned, the
// journal closed, how to resume printed, exit 143 or 130; a fresh start then refuses to forget
// the stopped run, and --resume finishes it.
TEST(ResumedConform, AStoppedRunSaysHowToResume) {
  const std::string dir = test::make_temp_dir();
  setenv("FLATMARCH_FAULTY", "sleep:30=l_shape", 1);  // a case long enough to be stopped in
  std::vector<std::string> argv{self(),
                                kCliFlag,
                                "conform",
                                "--backend",
                                "faulty",
                                "--size",
                                "32x18",
                                "--json",
                                dir + "/x.json",
                                "--scene",
                                "torus",
                                "--scene",
                                "l_shape",
                                "--method",
                                "analytic",
                                "--gallery",
                                FLATMARCH_SOURCE_DIR "/scenes"};
  // Started in the background: the test sends the signal.
  std::vector<char*> args;
  for (std::string& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  const std::string err_path = dir + "/err";
  for (const int sig : {SIGTERM, SIGINT}) {
    fs::remove(dir + "/x.json.journal");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0600);
    pid_t pid = 0;
    ASSERT_EQ(posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ), 0);
    posix_spawn_file_actions_destroy(&actions);
    // Until the first case (torus) is in the journal and the second (l_shape) sleeps.
    for (int k = 0; k < 600 && journal_keys(dir + "/x.json.journal").empty(); ++k)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    const auto sent = std::chrono::steady_clock::now();
    kill(pid, sig);
    int status = 0;
    waitpid(pid, &status, 0);
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
    ASSERT_TRUE(WIFEXITED(status)) << "ended by signal " << WTERMSIG(status);
    EXPECT_EQ(WEXITSTATUS(status), 128 + sig);
    EXPECT_LT(took, 10.0) << "the case under way was not abandoned";
    std::ifstream in(err_path);
    const std::string err((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(err.find("after 1 of 2 cases"), std::string::npos) << err;
    EXPECT_NE(err.find("--resume"), std::string::npos) << err;
    EXPECT_EQ(journal_keys(dir + "/x.json.journal"),
              std::vector<std::string>{"faulty/analytic/torus"});
  }
  unsetenv("FLATMARCH_FAULTY");
  const std::vector<std::string> again = argv;
  const test::ProcessResult fresh = test::run_process(again, 60.0);
  EXPECT_EQ(fresh.exit_code, 2);
  EXPECT_NE(fresh.err.find("add --resume to finish it"), std::string::npos) << fresh.err;
  const test::ProcessResult resumed = test::run_process(with(again, "--resume"), 60.0);
  EXPECT_EQ(resumed.exit_code, 1) << resumed.err;  // the faulty backend fails both cases
  EXPECT_EQ(read_json(dir + "/x.json")["cases"].size(), 2u);
}

// A case the worker answers with an error stays an error, not a crash; a worker that cannot be
// started is an error of the run.
TEST(Supervise, AWorkerThatCannotStartIsAnError) {
  reports::WorkerOptions o;
  o.argv = {"/nonexistent/flatmarch-worker"};
  EXPECT_THROW(reports::supervise(o, {{"a", 5.0}}, [](const std::string&, const json&) {}),
               std::runtime_error);
}

// A worker that answers with something other than a JSON object is an error of the run, and a
// worker that exits mid-case without a signal is a crash with its exit code.
TEST(Supervise, AWorkersAnswersAreChecked) {
  reports::WorkerOptions o;
  o.argv = {"/bin/sh", "-c", "read k; echo not-json"};
  EXPECT_THROW(reports::supervise(o, {{"a", 5.0}}, [](const std::string&, const json&) {}),
               std::runtime_error);
  o.argv = {"/bin/sh", "-c", "read k; echo '{\"n\": 1}'; read k; echo bye >&2; exit 7"};
  std::vector<json> records;
  reports::supervise(o, {{"a", 5.0}, {"b", 5.0}, {"c", 5.0}},
                     [&](const std::string&, const json& r) { records.push_back(r); });
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[0], (json{{"n", 1}}));
  EXPECT_EQ(records[1]["verdict"], "crash");
  EXPECT_EQ(records[1]["exit_code"], 7);
  EXPECT_EQ(records[1]["stderr_tail"], "bye\n");
  EXPECT_EQ(records[2], (json{{"n", 1}}));  // a fresh worker took the next case
  // A worker that sleeps past the deadline: a timeout, within the deadline and a little.
  o.argv = {"/bin/sh", "-c", "read k; sleep 30"};
  o.start_seconds = 0.0;
  records.clear();
  reports::supervise(o, {{"a", 0.5}},
                     [&](const std::string&, const json& r) { records.push_back(r); });
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0]["verdict"], "timeout");
  EXPECT_LT(records[0]["seconds"].get<double>(), 5.0);
}

// Cases in several workers at once: each case answered once, by its own worker's record, while
// the other workers run theirs (each worker's first case waits, bounded, until three workers have
// started: one at a time, none would see the others); a worker that dies costs only its case.
TEST(Supervise, InParallelEachCaseIsAnsweredOnceWhileTheOthersRun) {
  const std::string dir = test::make_temp_dir() + "/started";
  fs::create_directories(dir);
  reports::WorkerOptions o;
  o.argv = {"/bin/sh", "-c",
            "d=" + dir +
                "; while read k; do : > \"$d/$$\"; i=0; n=0; while [ $i -lt 250 ]; do "
                "n=$(ls \"$d\" | wc -l); [ $n -ge 3 ] && break; sleep 0.02; i=$((i+1)); done; "
                "[ \"$k\" = crash ] && exit 3; "
                "echo \"{\\\"key\\\": \\\"$k\\\", \\\"seen\\\": $n}\"; done"};
  std::vector<reports::SupervisedCase> cases;
  for (const char* k : {"a", "b", "c", "crash", "d", "e", "f", "g"}) cases.push_back({k, 20.0});
  std::map<std::string, json> records;
  reports::supervise_parallel(o, cases, 3, [&](const std::string& key, const json& r) {
    EXPECT_TRUE(records.emplace(key, r).second) << key << " answered twice";
  });
  ASSERT_EQ(records.size(), cases.size());
  for (const auto& [key, r] : records) {
    if (key == "crash") {
      EXPECT_EQ(r["verdict"], "crash");
      EXPECT_EQ(r["exit_code"], 3);
      continue;
    }
    EXPECT_EQ(r["key"], key);
    EXPECT_GE(r["seen"].get<int>(), 3) << key << ": its worker ran alone";
  }
  // An answer that is not JSON is the run's error, thrown once every worker has stopped.
  o.argv = {"/bin/sh", "-c", "while read k; do echo not-json; done"};
  EXPECT_THROW(reports::supervise_parallel(o, cases, 2, [](const std::string&, const json&) {}),
               std::runtime_error);
  EXPECT_THROW(reports::supervise_parallel(o, cases, 0, [](const std::string&, const json&) {}),
               std::invalid_argument);
}

// A report with a GPU backend compiles its kernels first, a stage of its own with a case per
// matrix case of that backend, several at once; then the matrix; --compile-jobs 0 leaves the stage
// out, and the matrix measures the same either way.
TEST(ReportProgress, CompilesTheGpuKernelsFirst) {
  // The first backend here that compiles its kernel per scene.
  std::string gpu;
  for (const auto& b : backends())
    if (gpu.empty() && b->compiles_per_scene() && b->availability().available) gpu = b->name();
  if (gpu.empty()) GTEST_SKIP() << "no backend that compiles its kernel per scene runs here";
  const std::string dir = test::make_temp_dir();
  const auto run = [&](const std::string& name, const std::string& jobs) {
    std::vector<std::string> argv = small_report(dir + "/" + name);
    argv[std::find(argv.begin(), argv.end(), "scalar") - argv.begin()] = gpu;
    argv.insert(argv.end(), {"--no-sweep", "--no-scaling", "--compile-jobs", jobs, "--progress-log",
                             dir + "/" + name + ".jsonl"});
    const test::ProcessResult r = test::run_process(argv, 300.0);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(dir + "/" + name + ".jsonl");
    std::vector<std::pair<std::string, std::string>> lines;  // (stage, key)
    for (std::string line; std::getline(in, line);) {
      const json l = json::parse(line);
      lines.emplace_back(l["stage"], l["key"]);
    }
    return lines;
  };
  const auto ahead = run("ahead", "2");
  ASSERT_EQ(ahead.size(), 4u);
  std::vector<std::string> compiled, measured;
  for (size_t k = 0; k < ahead.size(); ++k) {
    const auto& [stage, key] = ahead[k];
    (k < 2 ? compiled : measured).push_back(key.substr(key.find('/')));
    EXPECT_EQ(stage, k < 2 ? "compile" : "matrix") << key;
  }
  std::sort(compiled.begin(), compiled.end());
  std::sort(measured.begin(), measured.end());
  EXPECT_EQ(compiled, measured);
  EXPECT_EQ(compiled, (std::vector<std::string>{"/" + gpu + "/analytic/l_shape",
                                                "/" + gpu + "/analytic/torus"}));
  const auto own = run("own", "0");
  ASSERT_EQ(own.size(), 2u);
  for (const auto& [stage, key] : own) EXPECT_EQ(stage, "matrix") << key;
  const auto cases = [&](const std::string& name) {
    json c = read_json(dir + "/" + name + "/results.json")["matrix"]["cases"];
    for (json& x : c) x = x["accuracy"];
    return c;
  };
  EXPECT_EQ(cases("ahead"), cases("own"));
}

}  // namespace
}  // namespace flatmarch

int main(int argc, char** argv) {
  if (argc > 1 && std::strcmp(argv[1], flatmarch::kCliFlag) == 0)
    return flatmarch::cli::run(argc - 1, argv + 1,
                               {flatmarch::cli::this_program(argv[0]), flatmarch::kCliFlag});
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
