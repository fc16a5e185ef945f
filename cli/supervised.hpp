// A command's cases run supervised and journaled (issue 74): the options `conform`, `report` and
// `sweep` share (--isolate, --deadline-scale, --deadline-floor, --worker-memory, --resume, the
// hidden --worker), and the run itself — the journal beside the output started or resumed, the
// cases not yet in it run in watched workers (reports/supervise.hpp) or here, each appended to it
// as it finishes, and SIGINT or SIGTERM answered with how to resume.
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "reports/journal.hpp"

namespace flatmarch::cli {

struct SupervisionOptions {
  std::string isolate = "worker";
  double deadline_scale = 10.0, deadline_floor = 30.0, worker_memory_gib = 0.0;
  double worker_start = 30.0;  // seconds a fresh worker has to start, beside its first deadline
  bool resume = false;
  bool worker = false;  // this process is a worker of a supervised run
};

// Adds --isolate, --deadline-scale, --deadline-floor, --worker-start, --worker-memory, --resume
// and --worker to `cmd`; `journal` says where the journal lies ("beside --json, JSON.journal").
void add_supervision_options(CLI::App& cmd, SupervisionOptions& o, const std::string& journal);

// A case of a run: its key (what a worker is handed) and its expected seconds (the cost model's).
struct RunCase {
  std::string key;
  double cost_seconds = 0.0;
};

// A supervised run of `command` ("conform"), its journal at `journal`, described for the journal
// by the machine's `fingerprint` and the `options` that shape its results.
struct SupervisedRun {
  std::string command;
  std::filesystem::path journal;
  nlohmann::json fingerprint, options;
  std::vector<RunCase> cases;
  bool quiet = false;
  // Called for each case a resumed journal holds, before its `show`.
  std::function<void(const std::string& key)> resumed;
};

// Runs the run's cases, those its journal does not hold already (with --resume): each in a
// worker (`flatmarch COMMAND ... --worker`, which answers it with serve_cases) or, with
// --isolate none, here by `run_here(key)`. Each finished case's record is appended to the
// journal, then `show(key, record)` is called: once a case, in the run's order, the journal's
// first. A case its worker failed has the supervisor's record (a crash, timeout or
// out_of_memory verdict). Returns the records by key. On SIGINT or SIGTERM ends the case under
// way, prints how to resume and throws reports::Interrupted (cli::run exits 130 or 143).
// Throws UsageError for a journal it may not start or resume. complete() the journal returned in
// `journal_out` once the results are written.
std::map<std::string, nlohmann::json> run_supervised(
    const SupervisedRun& run, const SupervisionOptions& o,
    const std::function<nlohmann::json(const std::string& key)>& run_here,
    const std::function<void(const std::string& key, const nlohmann::json& record)>& show,
    std::optional<reports::Journal>& journal_out);

// Runs `cases` in up to `workers` workers at once (reports::supervise_parallel), neither
// journaled nor resumed: work ahead of a run whose results do not depend on it (the GPU kernels
// a report's matrix will compile). Each worker's command line ends with `worker_args` (so that it
// makes what it needs, no more). `show(key, record)` is called once a case, one at a time, as
// they finish. On SIGINT or SIGTERM ends them and throws reports::Interrupted.
void run_alongside(
    const std::vector<RunCase>& cases, const SupervisionOptions& o, int workers,
    const std::vector<std::string>& worker_args,
    const std::function<void(const std::string& key, const nlohmann::json& record)>& show);

// What ended a case without a result, in a line: "CRASH (SIGSEGV) after 2.1 s", then the last
// lines its worker wrote on its standard error, indented; for a table.
std::string unfinished_lines(const std::string& key, const nlohmann::json& record);

// The record of a case run here by `run`: its own, {"skipped": why} where its renderer cannot
// render it (CaseSkipped), or {"error": what} where it threw. A
// std::bad_alloc passes on: a worker answers it out_of_memory (serve_cases).
nlohmann::json record_or_error(const std::function<nlohmann::json()>& run);

// Whether a record is of a case that did not finish: the supervisor's (crash, timeout,
// out_of_memory) or an error. A report's or sweep's finished record is its part of the results.
bool unfinished_record(const nlohmann::json& record);

// A case record's verdict: pass, limit or fail (conformance's), crash, timeout or out_of_memory
// (the supervisor's), or "error" (the case threw: {"error"}).
std::string record_verdict(const nlohmann::json& record);

}  // namespace flatmarch::cli
