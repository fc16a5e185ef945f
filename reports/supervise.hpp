// Cases run in worker processes, watched (VK-GL-CTS's runners, Mesa's deqp-runner, in spirit): a
// renderer under test may crash, hang or run out of memory, and such a case must cost only
// itself. The parent starts a worker — this program again, with the command's own arguments and
// --worker — and hands it the cases' keys one line at a time on its standard input; the worker
// answers each with one line of JSON on its standard output. A worker that dies (a signal, or an
// exit mid-case), overruns the case's deadline or runs out of memory is ended (its whole process
// group) and the case recorded as `crash`, `timeout` or `out_of_memory`, with the signal, the
// seconds and the tail of its standard error; a fresh worker takes the next case.
#pragma once

#include <signal.h>
#include <sys/types.h>

#include <functional>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "conformance/vocabulary.hpp"

namespace flatmarch::reports {

// A run stopped by SIGINT or SIGTERM (`signal`) while StopSignals was in place: the case under
// way abandoned (its worker ended), nothing of it recorded.
class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(int signal);
  int signal;
};

// While one is in scope, SIGINT and SIGTERM do not end the process but are noted: supervise()
// then ends its worker and throws Interrupted, and a run in this process checks stop_requested()
// between cases. The handlers before are restored at its end.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;
  // The signal noted, or 0.
  static int stop_requested();

 private:
  struct sigaction old_[2] = {};  // SIGINT's and SIGTERM's handlers before
};

// The verdicts of a supervised case beside pass, limit and fail: conformance/vocabulary.hpp's
// kVerdictCrash, kVerdictTimeout and kVerdictOutOfMemory (its unfinished ones).
using conformance::kVerdictCrash;
using conformance::kVerdictOutOfMemory;
using conformance::kVerdictTimeout;
// Whether `verdict` is one of them.
bool is_supervision_verdict(const std::string& verdict);

// What ended a case without a result, from its record (supervise()'s, or {"error"} where the
// case threw), in a few words: "crash (SIGSEGV) after 2.1 s", "timeout after 30.0 s, its
// deadline", "error: WHAT"; the verdict in capitals where `loud` (a console table's).
std::string unfinished_summary(const nlohmann::json& record, bool loud = false);

// How a worker is started and watched.
struct WorkerOptions {
  // The worker's command line: this program (readlink of /proc/self/exe) and its arguments.
  std::vector<std::string> argv;
  // Its address-space limit (RLIMIT_AS, set by the worker itself: worker_limit_memory()); 0: none.
  double memory_bytes = 0.0;
  // Seconds a fresh worker has for its start (loading scenes, starting backends) on top of its
  // first case's deadline.
  double start_seconds = 30.0;
  // How much of a dead worker's standard error a record keeps.
  size_t stderr_tail_bytes = 4096;
};

// A case to run: its key (the worker's to interpret) and its deadline in seconds.
struct SupervisedCase {
  std::string key;
  double deadline_seconds = 60.0;
};

// Runs `cases` in workers, in order, and calls `done(key, record)` once a case, in order: the
// worker's own JSON line, or, where the worker failed it, {"verdict": crash | timeout |
// out_of_memory, "seconds", "signal" and "signal_name" where a signal ended it, "exit_code"
// where it exited, "deadline_seconds" for a timeout, "stderr_tail"}. Throws std::runtime_error
// when a worker cannot be started at all, or when it answers a case with something other than
// one JSON object.
void supervise(
    const WorkerOptions& options, const std::vector<SupervisedCase>& cases,
    const std::function<void(const std::string& key, const nlohmann::json& record)>& done);

// supervise() with up to `workers` workers at once, each taking the next case as it finishes
// one (work that may overlap: the GPU kernels compiled ahead of a report's matrix, whose timings
// would not bear another process beside them). `done` is called once a case, one call at a time,
// in the order the cases finish. The first error of any thread (Interrupted among them) is
// thrown once every worker has stopped.
void supervise_parallel(
    const WorkerOptions& options, const std::vector<SupervisedCase>& cases, int workers,
    const std::function<void(const std::string& key, const nlohmann::json& record)>& done);

// The worker's side. Sets its own address-space limit as the parent asked (through the
// environment: FLATMARCH_WORKER_MEMORY; not in a sanitizer build, whose shadow memory needs
// terabytes of address space), and reads the keys, calling `run(key)` for each and writing its
// record as one line. A case that runs out of memory (std::bad_alloc) is answered
// {"verdict": "out_of_memory"} and the worker exits, since its state may be broken.
void serve_cases(const std::function<nlohmann::json(const std::string& key)>& run);

// The deadline of a case whose cost model (reports/shard.hpp) says `cost_seconds`: `scale` times
// it, at least `floor_seconds`.
double case_deadline(double cost_seconds, double scale, double floor_seconds);

}  // namespace flatmarch::reports
