#include "cli/supervised.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <sstream>

#include "cli/common.hpp"
#include "reports/supervise.hpp"

namespace flatmarch::cli {

void add_supervision_options(CLI::App& cmd, SupervisionOptions& o, const std::string& journal) {
  cmd.add_option("--isolate", o.isolate,
                 "worker: the cases run in a worker process, watched, so that a case that "
                 "crashes, overruns its deadline or runs out of memory is recorded as crash, "
                 "timeout or out_of_memory and a fresh worker goes on; none: in this process "
                 "(for a debugger)")
      ->check(CLI::IsMember({"worker", "none"}))
      ->capture_default_str();
  cmd.add_option("--deadline-scale", o.deadline_scale,
                 "A case's deadline: this many times what the cost model expects of it ...")
      ->check(CLI::Range(1.0, 1000.0))
      ->capture_default_str();
  cmd.add_option("--deadline-floor", o.deadline_floor, "... and at least this many seconds")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  cmd.add_option("--worker-start", o.worker_start,
                 "Seconds a fresh worker has for its start (loading the scenes, starting its "
                 "backends: a browser, GPU contexts), on top of its first case's deadline")
      ->check(CLI::Range(0.0, 86400.0))
      ->capture_default_str();
  cmd.add_option("--worker-memory", o.worker_memory_gib,
                 "A worker's address-space limit in GiB (default: the machine's memory, or its "
                 "cgroup's where lower, but at least 8, since drivers reserve more address space "
                 "than they use; never above a limit this process has already)")
      ->check(CLI::Range(0.25, 65536.0));
  cmd.add_flag("--resume", o.resume,
               "Finish a run that was stopped: the cases in its journal (" + journal +
                   ", each case appended as it finishes) are kept, the others run; the same "
                   "command line otherwise");
  cmd.add_flag("--worker", o.worker)->group("");  // a worker of a supervised run (hidden)
}

nlohmann::json record_or_error(const std::function<nlohmann::json()>& run) {
  try {
    return run();
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const CaseSkipped& e) {
    return {{"skipped", e.what()}};
  } catch (const std::exception& e) {
    return {{"error", e.what()}};
  }
}

bool unfinished_record(const nlohmann::json& record) {
  return record.contains("verdict") || record.contains("error");
}

std::string record_verdict(const nlohmann::json& record) {
  if (record.contains("skipped")) return "skip";
  if (record.contains("error") && !record.contains("verdict")) return "error";
  if (record.contains("verdict")) return record["verdict"].get<std::string>();
  return "error";
}

std::string unfinished_lines(const std::string& key, const nlohmann::json& record) {
  std::string lines = key + "  " + reports::unfinished_summary(record, true) + "\n";
  // The last lines its worker wrote, indented.
  std::vector<std::string> tail;
  std::istringstream in(record.value("stderr_tail", ""));
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) tail.push_back(line);
  for (size_t k = tail.size() > 6 ? tail.size() - 6 : 0; k < tail.size(); ++k)
    lines += "    | " + tail[k] + "\n";
  return lines;
}

namespace {

// How a run's workers are started: this program again, --worker, limited to --worker-memory.
reports::WorkerOptions worker_options(const SupervisionOptions& o) {
  reports::WorkerOptions workers;
  workers.start_seconds = o.worker_start;
  workers.argv = worker_command();
  workers.memory_bytes = o.worker_memory_gib > 0.0
                             ? o.worker_memory_gib * 1024.0 * 1024.0 * 1024.0
                             : std::max(memory_limit().bytes, 8.0 * 1024 * 1024 * 1024);
  return workers;
}

std::vector<reports::SupervisedCase> supervised_cases(const std::vector<const RunCase*>& cases,
                                                      const SupervisionOptions& o) {
  std::vector<reports::SupervisedCase> supervised;
  for (const RunCase* c : cases)
    supervised.push_back(
        {c->key, reports::case_deadline(c->cost_seconds, o.deadline_scale, o.deadline_floor)});
  return supervised;
}

}  // namespace

void run_alongside(
    const std::vector<RunCase>& cases, const SupervisionOptions& o, int workers,
    const std::vector<std::string>& worker_args,
    const std::function<void(const std::string& key, const nlohmann::json& record)>& show) {
  std::vector<const RunCase*> all;
  for (const RunCase& c : cases) all.push_back(&c);
  if (all.empty()) return;
  reports::WorkerOptions workers_options = worker_options(o);
  workers_options.argv.insert(workers_options.argv.end(), worker_args.begin(), worker_args.end());
  const reports::StopSignals stop;
  reports::supervise_parallel(workers_options, supervised_cases(all, o), workers, show);
}

std::map<std::string, nlohmann::json> run_supervised(
    const SupervisedRun& run, const SupervisionOptions& o,
    const std::function<nlohmann::json(const std::string& key)>& run_here,
    const std::function<void(const std::string& key, const nlohmann::json& record)>& show,
    std::optional<reports::Journal>& journal) {
  std::vector<std::string> keys;
  for (const RunCase& c : run.cases) keys.push_back(c.key);
  const nlohmann::json header =
      reports::journal_header(run.command, run.fingerprint, run.options, keys);
  std::map<std::string, nlohmann::json> records;
  try {
    journal.emplace(o.resume ? reports::Journal::resume(run.journal, header, records)
                             : reports::Journal::start(run.journal, header));
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string(o.resume ? "--resume: " : "") + e.what());
  }
  if (o.resume && !run.quiet)
    std::fprintf(stderr, "%s: resuming %s: %zu of %zu cases done\n", run.command.c_str(),
                 journal->path().c_str(), records.size(), run.cases.size());
  std::vector<const RunCase*> to_run;
  for (const RunCase& c : run.cases) {
    if (const auto it = records.find(c.key); it != records.end()) {
      if (run.resumed) run.resumed(c.key);
      show(c.key, it->second);
    } else
      to_run.push_back(&c);
  }
  // A case finished (here, by a worker, or by a supervisor that saw it fail): journaled, shown.
  const auto take = [&](const std::string& key, const nlohmann::json& record) {
    journal->append(key, record);
    show(key, record);
    records[key] = record;
  };
  try {
    const reports::StopSignals stop;
    if (o.isolate == "none") {
      for (const RunCase* c : to_run) {
        if (const int sig = reports::StopSignals::stop_requested()) throw reports::Interrupted(sig);
        take(c->key, run_here(c->key));
      }
    } else if (!to_run.empty()) {
      reports::supervise(worker_options(o), supervised_cases(to_run, o), take);
    }
  } catch (const reports::Interrupted& e) {
    std::fprintf(stderr,
                 "%s: %s after %zu of %zu cases; the journal %s keeps them: resume with\n"
                 "  flatmarch %s\n",
                 run.command.c_str(), e.what(), records.size(), run.cases.size(),
                 journal->path().c_str(), quoted_command_line("--resume").c_str());
    throw;
  }
  return records;
}

}  // namespace flatmarch::cli
