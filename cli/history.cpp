// `flatmarch history`: every run kept in a database, its series judged for change points, and a
// timeline page (issue 77).
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "history/analysis.hpp"
#include "history/database.hpp"
#include "output/dynamic_library.hpp"

namespace flatmarch::cli {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The commit a run is of: --commit, else $GITHUB_SHA (a CI job's), else the checkout's HEAD.
std::string commit_of(const std::string& given) {
  if (!given.empty()) return given;
  if (const char* sha = std::getenv("GITHUB_SHA"); sha && *sha) return sha;
  std::string head;
  if (FILE* git = popen("git rev-parse HEAD 2>/dev/null", "r")) {
    char line[128];
    if (std::fgets(line, sizeof line, git)) head = line;
    pclose(git);
  }
  while (!head.empty() && (head.back() == '\n' || head.back() == '\r')) head.pop_back();
  if (head.empty())
    throw UsageError(
        "--commit: not given, no $GITHUB_SHA and no git checkout here: say which "
        "commit the results are of");
  return head;
}

history::Database open_database(const std::string& path, bool must_exist) {
  if (must_exist && !fs::exists(path))
    throw UsageError("--db: no " + path + "; `flatmarch history add` makes it");
  if (const fs::path folder = fs::path(path).parent_path(); !folder.empty())
    fs::create_directories(folder);
  try {
    return history::Database(path);
  } catch (const std::runtime_error& e) {
    throw UsageError(std::string("--db: ") + e.what());
  }
}

// The change points' two limits, options of each command that judges the series.
void add_change_options(CLI::App& cmd, history::ChangeOptions& o) {
  cmd.add_option("--threshold", o.threshold,
                 "Change points' z (t-corrected where the variances are estimated from few runs)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 20.0));
  cmd.add_option("--min-change", o.min_change, "Smallest relative timing change reported")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
}

// One finding in a line: where, what changed, between which commits.
std::string describe(const json& f) {
  std::string what;
  char buf[160];
  if (f["before"].is_string()) {
    what = f["before"].get<std::string>() + " -> " + f["after"].get<std::string>();
  } else if (f["kind"] == "timing") {
    std::snprintf(buf, sizeof buf, "%.4g -> %.4g (%+.1f%%, z %.1f)", f["before"].get<double>(),
                  f["after"].get<double>(),
                  100.0 * (f["after"].get<double>() / f["before"].get<double>() - 1.0),
                  f["z"].get<double>());
    what = buf;
  } else {
    std::snprintf(buf, sizeof buf, "%.6g -> %.6g", f["before"].get<double>(),
                  f["after"].get<double>());
    what = buf;
  }
  const std::string from = f["commits"][0], to = f["commits"][1];
  return f["case"].get<std::string>() + " " + f["figure"].get<std::string>() + ": " + what +
         (f["worse"].get<bool>() ? " (worse)" : "") + ", between " + from.substr(0, 12) + " and " +
         to.substr(0, 12);
}

void add_history_add(CLI::App& history, const std::shared_ptr<std::string>& db) {
  auto* cmd = history.add_subcommand(
      "add",
      "Keep results files in the database: `flatmarch report` and `merge` results, `flatmarch\n"
      "conform` JSON, Google Benchmark programs' --benchmark_out JSON. Each is one run, keyed by\n"
      "its content (adding it again changes nothing), its commit, machine (CPU, instruction sets,\n"
      "GPU devices), build and options; a file of any other kind is refused with why.");
  struct Options {
    std::vector<std::string> files;
    std::string commit, baseline, page;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("RESULTS", o->files, "Results files")->required()->check(CLI::ExistingFile);
  cmd->add_option(
      "--commit", o->commit,
      "The commit the results are of (default: $GITHUB_SHA, else `git rev-parse HEAD`)");
  cmd->add_option("--baseline", o->baseline,
                  "The baseline the run was gated against (default: the one its results name): "
                  "a deterministic change where the baseline changed too is accepted")
      ->check(CLI::ExistingFile);
  cmd->add_option("--page", o->page,
                  "The run's own report page, a path or URL the timeline links to (default: "
                  "index.html beside a report's results, where there is one)");
  cmd->callback([o, db] {
    const std::string commit = commit_of(o->commit);
    history::Database d = open_database(*db, false);
    for (const std::string& file : o->files) {
      history::Run run;
      try {
        run = history::read_run(file, commit, o->baseline);
      } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
      }
      if (!o->page.empty()) run.page = o->page;
      const auto id = d.add(run);
      if (id)
        std::printf("history: added %s as run %lld: %s of %s, %zu figures, on %s\n", file.c_str(),
                    static_cast<long long>(*id), run.kind.c_str(), commit.substr(0, 12).c_str(),
                    run.measurements.size(), run.machine_text.c_str());
      else
        std::printf("history: %s is there already (the same content): nothing added\n",
                    file.c_str());
    }
  });
}

void add_history_query(CLI::App& history, const std::shared_ptr<std::string>& db) {
  auto* cmd = history.add_subcommand(
      "query",
      "Print a case's series: each run's commit, time and figure, with the change points marked\n"
      "(*). Without CASE, the runs kept and how many series. The database is plain SQLite:\n"
      "`sqlite3 history.db 'SELECT * FROM runs'` reads it too (docs/history.md).");
  struct Options {
    std::string case_name, figure, machine;
    bool json = false;
    history::ChangeOptions changes;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("CASE", o->case_name,
                  "A case: report/BACKEND/METHOD/SCENE/WxH, conform/..., bench/NAME");
  cmd->add_option("--figure", o->figure, "One figure (default: every figure of the case)");
  cmd->add_option("--machine", o->machine, "One machine's key (default: every machine)");
  cmd->add_flag("--json", o->json, "JSON: the series with their change points");
  add_change_options(*cmd, o->changes);
  cmd->callback([o, db] {
    const history::Database d = open_database(*db, true);
    const json analysed = history::analyse(d, o->changes);
    if (o->case_name.empty()) {
      if (o->json) {
        std::printf("%s\n", analysed["runs"].dump(1).c_str());
        return;
      }
      for (const json& r : analysed["runs"])
        std::printf("run %lld  %s  %s  %-9s %5d figures  %s\n",
                    static_cast<long long>(r["id"].get<int64_t>()),
                    r["created"].get<std::string>().c_str(),
                    r["commit"].get<std::string>().substr(0, 12).c_str(),
                    r["kind"].get<std::string>().c_str(), r["measurements"].get<int>(),
                    r["machine_text"].get<std::string>().c_str());
      std::printf("%zu runs, %zu series, %zu change points\n", analysed["runs"].size(),
                  analysed["series"].size(), analysed["findings"].size());
      return;
    }
    json shown = json::array();
    for (const json& s : analysed["series"])
      if (s["case"] == o->case_name && (o->figure.empty() || s["figure"] == o->figure) &&
          (o->machine.empty() || s["machine"] == o->machine))
        shown.push_back(s);
    if (shown.empty())
      throw UsageError("CASE: no series of " + o->case_name +
                       (o->figure.empty() ? "" : " " + o->figure) + " in " + *db);
    if (o->json) {
      std::printf("%s\n", shown.dump(1).c_str());
      return;
    }
    for (const json& s : shown) {
      std::printf("%s %s (%s) on machine %s\n", s["case"].get<std::string>().c_str(),
                  s["figure"].get<std::string>().c_str(), s["judged"].get<std::string>().c_str(),
                  s["machine"].get<std::string>().c_str());
      std::vector<bool> marked(s["points"].size());
      for (const json& f : s["changes"]) marked[f["at"].get<size_t>()] = true;
      size_t k = 0;
      for (const json& p : s["points"]) {
        const std::string value = p.contains("text") ? p["text"].get<std::string>()
                                                     : std::to_string(p["value"].get<double>());
        std::printf("  %s run %-5lld %s  %s  %s\n", marked[k++] ? "*" : " ",
                    static_cast<long long>(p["run"].get<int64_t>()),
                    p["commit"].get<std::string>().substr(0, 12).c_str(),
                    p["created"].get<std::string>().c_str(), value.c_str());
      }
      for (const json& f : s["changes"]) std::printf("  * %s\n", describe(f).c_str());
    }
  });
}

void add_history_check(CLI::App& history, const std::shared_ptr<std::string>& db) {
  auto* cmd = history.add_subcommand(
      "check",
      "What the newest run of each series changed: exit 1 on a deterministic change (steps,\n"
      "crossings, accuracy, verdict) that no baseline commit accepted (the gate's baseline did\n"
      "not change with it); timing regressions still open are printed as warnings.");
  auto limits = std::make_shared<history::ChangeOptions>();
  add_change_options(*cmd, *limits);
  cmd->callback([db, limits] {
    const history::Database d = open_database(*db, true);
    const json changes = history::newest_changes(history::analyse(d, *limits));
    for (const json& f : changes["timing"])
      std::printf("warning: slower: %s\n", describe(f).c_str());
    for (const json& f : changes["accepted"]) std::printf("accepted: %s\n", describe(f).c_str());
    for (const json& f : changes["deterministic"])
      std::printf("changed: %s\n", describe(f).c_str());
    std::printf(
        "history: %zu deterministic changes not accepted, %zu accepted, %zu open timing "
        "regressions\n",
        changes["deterministic"].size(), changes["accepted"].size(), changes["timing"].size());
    if (!changes["deterministic"].empty())
      throw ConformanceFailure(std::to_string(changes["deterministic"].size()) +
                               " deterministic figures changed with no baseline commit");
  });
}

void add_history_report(CLI::App& history, const std::shared_ptr<std::string>& db) {
  auto* cmd = history.add_subcommand(
      "report",
      "The timeline page, OUT/index.html (self-contained): open regressions first, newest first,\n"
      "each with its commit range and a link to its run's report page; then per backend and\n"
      "scene the series of rays a second and steps with the change points marked. OUT/\n"
      "timeline.json holds what it shows.");
  struct Options {
    std::string out = "history", python = default_python();
    history::ChangeOptions changes;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("-o,--out", o->out, "Output folder")->capture_default_str();
  cmd->add_option("--python", o->python,
                  "python3 with matplotlib and jinja2 (env FLATMARCH_PYTHON)")
      ->capture_default_str();
  add_change_options(*cmd, o->changes);
  cmd->callback([o, db] {
    const history::Database d = open_database(*db, true);
    json analysed = history::analyse(d, o->changes);
    analysed["database"] = fs::absolute(*db).string();
    analysed["options"] = {{"threshold", o->changes.threshold},
                           {"min_change", o->changes.min_change}};
    const fs::path data = fs::path(o->out) / "timeline.json";
    write_json(data, analysed);
    const std::string command = shell_quoted(o->python) + " " +
                                shell_quoted(data_file("history/make_timeline.py")) + " -o " +
                                shell_quoted(o->out) + " " + shell_quoted(data.string());
    if (std::system(command.c_str()) != 0)
      throw std::runtime_error("the timeline page could not be made (" + command +
                               " failed; it needs python3 with matplotlib and jinja2: "
                               "ci/install-deps.sh installs them); its data is in " +
                               data.string());
    std::printf("history: %zu runs, %zu change points; open %s\n", analysed["runs"].size(),
                analysed["findings"].size(), (fs::path(o->out) / "index.html").c_str());
  });
}

}  // namespace

void add_history(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "history",
      "Every run kept, and its series judged over time: `add` keeps results files in an SQLite\n"
      "database, `query` prints a case's series, `check` says what the newest run changed (exit\n"
      "1 on a deterministic change no baseline commit accepted), `report` draws the timeline\n"
      "page. Deterministic figures are flagged at any change; timings by change points\n"
      "(binary segmentation, weighted by each run's repetitions; docs/history.md).");
  auto db = std::make_shared<std::string>("history.db");
  cmd->add_option("--db", *db, "The database file")->capture_default_str();
  cmd->require_subcommand(1);
  add_history_add(*cmd, db);
  add_history_query(*cmd, db);
  add_history_check(*cmd, db);
  add_history_report(*cmd, db);
  // --db after the subcommand too: `flatmarch history add --db FILE ...`.
  for (CLI::App* sub : cmd->get_subcommands([](const CLI::App*) { return true; }))
    sub->fallthrough();
}

}  // namespace flatmarch::cli
