#include "reports/supervise.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <mutex>
#include <new>
#include <optional>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace flatmarch::reports {

using json = nlohmann::json;

namespace {

using Clock = std::chrono::steady_clock;

constexpr const char* kMemoryVariable = "FLATMARCH_WORKER_MEMORY";
constexpr const char* kParentVariable = "FLATMARCH_WORKER_PARENT";

std::string system_error(const std::string& what) {
  return what + ": " + std::strerror(errno);
}

// A running worker: its process (the leader of its own group) and its three pipes.
class Worker {
 public:
  explicit Worker(const WorkerOptions& options) : tail_bytes_(options.stderr_tail_bytes) {
    int in[2], out[2], err[2];
    if (pipe2(in, O_CLOEXEC) || pipe2(out, O_CLOEXEC) || pipe2(err, O_CLOEXEC))
      throw std::runtime_error(system_error("a worker's pipes"));
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, in[0], 0);
    posix_spawn_file_actions_adddup2(&actions, out[1], 1);
    posix_spawn_file_actions_adddup2(&actions, err[1], 2);
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t defaults;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGPIPE);  // ignored here, not in the worker
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setpgroup(&attr, 0);  // its own group: ended with what it started
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF);
    std::vector<std::string> env_text;
    for (char** e = environ; *e; ++e)
      if (std::strncmp(*e, kMemoryVariable, std::strlen(kMemoryVariable)) != 0 &&
          std::strncmp(*e, kParentVariable, std::strlen(kParentVariable)) != 0)
        env_text.emplace_back(*e);
    env_text.push_back(std::string(kParentVariable) + "=" + std::to_string(::getpid()));
    if (options.memory_bytes > 0.0)
      env_text.push_back(std::string(kMemoryVariable) + "=" +
                         std::to_string(static_cast<long long>(options.memory_bytes)));
    std::vector<char*> env, argv;
    for (std::string& s : env_text) env.push_back(s.data());
    env.push_back(nullptr);
    std::vector<std::string> args = options.argv;
    for (std::string& s : args) argv.push_back(s.data());
    argv.push_back(nullptr);
    const int spawned = posix_spawn(&pid_, argv[0], &actions, &attr, argv.data(), env.data());
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
    ::close(in[0]);
    ::close(out[1]);
    ::close(err[1]);
    in_ = in[1];
    out_ = out[0];
    err_ = err[0];
    if (spawned != 0) {
      close_pipes();
      errno = spawned;
      throw std::runtime_error(system_error("cannot start a worker (" + options.argv[0] + ")"));
    }
    started_ = Clock::now();
  }
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;
  ~Worker() {
    if (pid_ > 0) end();
    close_pipes();
  }

  // Hands it a case; false if it is gone.
  bool send(const std::string& key) {
    const std::string line = key + "\n";
    size_t sent = 0;
    while (sent < line.size()) {
      const ssize_t n = ::write(in_, line.data() + sent, line.size() - sent);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return false;
      sent += static_cast<size_t>(n);
    }
    return true;
  }

  enum class Read { line, gone, late };
  // Waits until it has answered with a line (into `line`), it is gone, or `until` passes.
  Read wait_for_line(Clock::time_point until, std::string& line) {
    for (;;) {
      if (const size_t nl = out_buffer_.find('\n'); nl != std::string::npos) {
        line = out_buffer_.substr(0, nl);
        out_buffer_.erase(0, nl + 1);
        return Read::line;
      }
      if (out_ < 0) return Read::gone;
      if (const int sig = StopSignals::stop_requested()) throw Interrupted(sig);
      const auto now = Clock::now();
      if (now >= until) return Read::late;
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - now);
      pollfd fds[2] = {{out_, POLLIN, 0}, {err_, POLLIN, 0}};
      const int ready = ::poll(fds, err_ >= 0 ? 2 : 1,
                               static_cast<int>(std::min<int64_t>(left.count() + 1, 1000)));
      if (ready < 0 && errno != EINTR) throw std::runtime_error(system_error("poll"));
      if (ready <= 0) continue;
      if (err_ >= 0 && (fds[1].revents & (POLLIN | POLLHUP))) drain_stderr();
      if (fds[0].revents & (POLLIN | POLLHUP)) {
        char buffer[65536];
        const ssize_t n = ::read(out_, buffer, sizeof buffer);
        if (n > 0) {
          out_buffer_.append(buffer, static_cast<size_t>(n));
        } else if (n == 0 || errno != EINTR) {
          ::close(out_);
          out_ = -1;
        }
      }
    }
  }

  // Ends it (its whole group) if it still runs, and reaps it; the wait status.
  int end() {
    if (pid_ <= 0) return status_;
    ::kill(-pid_, SIGKILL);
    ::kill(pid_, SIGKILL);
    reap();
    return status_;
  }

  // Waits up to `seconds` for it to exit by itself (its input closed), then ends it.
  int finish(double seconds) {
    if (in_ >= 0) ::close(in_);
    in_ = -1;
    const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                          std::chrono::duration<double>(seconds));
    while (pid_ > 0 && Clock::now() < until) {
      int status = 0;
      const pid_t r = ::waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        status_ = status;
        pid_ = -1;
        ::kill(-r, SIGKILL);  // anything it left in its group
        break;
      }
      drain_stderr();
      ::usleep(10000);
    }
    return end();
  }

  std::string stderr_tail() {
    drain_stderr();
    return err_tail_;
  }
  double seconds_since_start() const {
    return std::chrono::duration<double>(Clock::now() - started_).count();
  }

 private:
  void reap() {
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    status_ = status;
    pid_ = -1;
  }
  void drain_stderr() {
    if (err_ < 0) return;
    for (;;) {
      pollfd fd{err_, POLLIN, 0};
      if (::poll(&fd, 1, 0) <= 0 || !(fd.revents & (POLLIN | POLLHUP))) return;
      char buffer[8192];
      const ssize_t n = ::read(err_, buffer, sizeof buffer);
      if (n <= 0) {
        ::close(err_);
        err_ = -1;
        return;
      }
      err_tail_.append(buffer, static_cast<size_t>(n));
      if (err_tail_.size() > tail_bytes_) err_tail_.erase(0, err_tail_.size() - tail_bytes_);
    }
  }
  void close_pipes() {
    for (int* fd : {&in_, &out_, &err_})
      if (*fd >= 0) {
        ::close(*fd);
        *fd = -1;
      }
  }

  size_t tail_bytes_;
  pid_t pid_ = -1;
  int status_ = 0;
  int in_ = -1, out_ = -1, err_ = -1;
  std::string out_buffer_, err_tail_;
  Clock::time_point started_;
};

// The record of a case its worker did not answer: how the worker ended.
json failed_case(const char* verdict, int status, double seconds, std::string tail) {
  json r = {{"verdict", verdict}, {"seconds", seconds}};
  if (WIFSIGNALED(status)) {
    r["signal"] = WTERMSIG(status);
    const char* name = sigabbrev_np(WTERMSIG(status));
    r["signal_name"] =
        name ? std::string("SIG") + name : "signal " + std::to_string(WTERMSIG(status));
  } else if (WIFEXITED(status)) {
    r["exit_code"] = WEXITSTATUS(status);
  }
  // Text for the JSON: bytes beyond ASCII (a multi-byte character the tail cut, or a program's
  // binary output) and control characters but line ends and tabs replaced.
  for (char& ch : tail)
    if ((static_cast<unsigned char>(ch) < 0x20 && ch != '\n' && ch != '\t') ||
        static_cast<unsigned char>(ch) >= 0x7f)
      ch = '?';
  r["stderr_tail"] = std::move(tail);
  return r;
}

// SIGPIPE ignored while a worker may be written to after it died.
class IgnoreSigpipe {
 public:
  IgnoreSigpipe() {
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    sigemptyset(&ignore.sa_mask);
    ::sigaction(SIGPIPE, &ignore, &old_);
  }
  ~IgnoreSigpipe() { ::sigaction(SIGPIPE, &old_, nullptr); }
  IgnoreSigpipe(const IgnoreSigpipe&) = delete;
  IgnoreSigpipe& operator=(const IgnoreSigpipe&) = delete;

 private:
  struct sigaction old_ {};
};

}  // namespace

namespace {
volatile sig_atomic_t g_stop = 0;
extern "C" void note_stop(int signal) {
  g_stop = signal;
}
}  // namespace

Interrupted::Interrupted(int sig)
    : std::runtime_error(std::string("interrupted by ") + (sig == SIGINT    ? "SIGINT"
                                                           : sig == SIGTERM ? "SIGTERM"
                                                                            : "a signal")),
      signal(sig) {}

StopSignals::StopSignals() {
  g_stop = 0;
  struct sigaction note {};
  note.sa_handler = note_stop;
  sigemptyset(&note.sa_mask);
  note.sa_flags = 0;  // no SA_RESTART: poll() and waits return EINTR
  ::sigaction(SIGINT, &note, &old_[0]);
  ::sigaction(SIGTERM, &note, &old_[1]);
}

StopSignals::~StopSignals() {
  ::sigaction(SIGINT, &old_[0], nullptr);
  ::sigaction(SIGTERM, &old_[1], nullptr);
}

int StopSignals::stop_requested() {
  return g_stop;
}

bool is_supervision_verdict(const std::string& verdict) {
  return conformance::is_unfinished_verdict(verdict);
}

double case_deadline(double cost_seconds, double scale, double floor_seconds) {
  return std::max(floor_seconds, scale * cost_seconds);
}

namespace {

// supervise()'s loop, over the cases `next` hands out (null: no more), SIGPIPE ignored already.
void supervise_from(const WorkerOptions& options,
                    const std::function<const SupervisedCase*()>& next,
                    const std::function<void(const std::string& key, const json& record)>& done) {
  std::optional<Worker> worker;
  while (const SupervisedCase* next_case = next()) {
    const SupervisedCase& c = *next_case;
    bool fresh = false;
    if (!worker) {
      worker.emplace(options);
      fresh = true;
    }
    const auto started = Clock::now();
    const double allowed = c.deadline_seconds + (fresh ? options.start_seconds : 0.0);
    const auto until = started + std::chrono::duration_cast<Clock::duration>(
                                     std::chrono::duration<double>(allowed));
    std::string line;
    Worker::Read got =
        worker->send(c.key) ? worker->wait_for_line(until, line) : Worker::Read::gone;
    const double seconds = std::chrono::duration<double>(Clock::now() - started).count();
    if (got == Worker::Read::line) {
      json record;
      try {
        record = json::parse(line);
      } catch (const json::parse_error&) {
      }
      if (!record.is_object())
        throw std::runtime_error("a worker answered case " + c.key + " with \"" +
                                 line.substr(0, 200) + "\", not a JSON object");
      if (record.value("verdict", "") == kVerdictOutOfMemory) {
        // The worker says so itself, and exits: its state may be broken.
        worker->finish(5.0);
        record = failed_case(kVerdictOutOfMemory, 0, seconds, worker->stderr_tail());
        record.erase("exit_code");
        if (options.memory_bytes > 0.0) record["memory_limit_bytes"] = options.memory_bytes;
        worker.reset();
      }
      done(c.key, record);
      continue;
    }
    if (got == Worker::Read::late) {
      const int status = worker->end();
      json record = failed_case(kVerdictTimeout, status, seconds, worker->stderr_tail());
      record.erase("signal");  // ours
      record.erase("signal_name");
      record["deadline_seconds"] = allowed;
      worker.reset();
      done(c.key, record);
      continue;
    }
    // Gone: it died in this case (or before it, starting). Killed for memory by the kernel, a
    // crash to us.
    const int status = worker->finish(5.0);
    json record = failed_case(kVerdictCrash, status, seconds, worker->stderr_tail());
    worker.reset();
    done(c.key, record);
  }
  if (worker) worker->finish(10.0);
}

}  // namespace

void supervise(const WorkerOptions& options, const std::vector<SupervisedCase>& cases,
               const std::function<void(const std::string& key, const json& record)>& done) {
  if (options.argv.empty()) throw std::invalid_argument("supervise: no worker command");
  const IgnoreSigpipe ignore;
  size_t k = 0;
  supervise_from(
      options, [&]() { return k < cases.size() ? &cases[k++] : nullptr; }, done);
}

void supervise_parallel(
    const WorkerOptions& options, const std::vector<SupervisedCase>& cases, int workers,
    const std::function<void(const std::string& key, const json& record)>& done) {
  if (options.argv.empty()) throw std::invalid_argument("supervise: no worker command");
  if (workers < 1) throw std::invalid_argument("supervise_parallel: no worker");
  // Once, around every thread: an IgnoreSigpipe of each would restore the others' state.
  const IgnoreSigpipe ignore;
  std::mutex mutex;  // over `k`, `done` and `failure`
  size_t k = 0;
  std::exception_ptr failure;
  const auto next = [&]() -> const SupervisedCase* {
    const std::lock_guard<std::mutex> lock(mutex);
    return !failure && k < cases.size() ? &cases[k++] : nullptr;
  };
  const auto take = [&](const std::string& key, const json& record) {
    const std::lock_guard<std::mutex> lock(mutex);
    done(key, record);
  };
  std::vector<std::thread> threads;
  const size_t count = std::min(static_cast<size_t>(workers), cases.size());
  for (size_t t = 0; t < count; ++t)
    threads.emplace_back([&] {
      try {
        supervise_from(options, next, take);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(mutex);
        if (!failure) failure = std::current_exception();
      }
    });
  for (std::thread& t : threads) t.join();
  if (failure) std::rethrow_exception(failure);
}

std::string unfinished_summary(const json& record, bool loud) {
  const std::string verdict = record.value("verdict", record.contains("error") ? "error" : "");
  std::string what = verdict == kVerdictOutOfMemory ? (loud ? "OUT OF MEMORY" : "out of memory")
                     : verdict.empty()              ? (loud ? "ERROR" : "error")
                                                    : verdict;
  if (loud)
    std::transform(what.begin(), what.end(), what.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  if (record.contains("signal_name")) what += " (" + record["signal_name"].get<std::string>() + ")";
  if (record.contains("exit_code"))
    what += " (exit " + std::to_string(record["exit_code"].get<int>()) + ")";
  if (record.contains("error")) what += ": " + record["error"].get<std::string>();
  if (record.contains("seconds")) {
    char seconds[64];
    std::snprintf(seconds, sizeof seconds, " after %.1f s", record["seconds"].get<double>());
    what += seconds;
  }
  if (record.contains("deadline_seconds")) what += ", its deadline";
  return what;
}

void serve_cases(const std::function<json(const std::string& key)>& run) {
  // The records go to the parent on the standard output as it was; anything else the command
  // prints there goes to the standard error.
  std::cout.flush();
  std::fflush(stdout);
  const int records = ::dup(1);
  if (records < 0 || ::dup2(2, 1) < 0) throw std::runtime_error(system_error("a worker's output"));
  // Ended with its parent, however the parent ends (SIGKILL included); and at once if the parent
  // is gone already.
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (const char* parent = std::getenv(kParentVariable);
      parent && ::getppid() != static_cast<pid_t>(std::strtol(parent, nullptr, 10)))
    std::_Exit(4);
#ifndef FLATMARCH_SANITIZE_BUILD
  if (const char* limit = std::getenv(kMemoryVariable)) {
    rlim_t bytes = static_cast<rlim_t>(std::strtoull(limit, nullptr, 10));
    // Never above a limit this process has already (the parent's own, say).
    if (rlimit now{}; ::getrlimit(RLIMIT_AS, &now) == 0 && now.rlim_max != RLIM_INFINITY)
      bytes = std::min(bytes, now.rlim_max);
    // The soft limit alone: a backend may start a program of its own outside it (the webgl
    // backend's browser, whose V8 reserves tens of GiB of address space it never touches).
    rlimit as{};
    ::getrlimit(RLIMIT_AS, &as);
    as.rlim_cur = bytes;
    if (bytes > 0 && ::setrlimit(RLIMIT_AS, &as) != 0)
      std::cerr << system_error("worker: RLIMIT_AS") << "\n";
  }
#endif
  const auto write_all = [records](const char* data, size_t size) {
    while (size > 0) {
      const ssize_t n = ::write(records, data, size);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) std::_Exit(4);  // the parent is gone
      data += n;
      size -= static_cast<size_t>(n);
    }
  };
  for (std::string key; std::getline(std::cin, key);) {
    std::string line;
    try {
      line = run(key).dump(-1, ' ', false, json::error_handler_t::replace) + "\n";
    } catch (const std::bad_alloc&) {
      // Written without allocating: the memory may still be held.
      static constexpr char kOom[] = "{\"verdict\":\"out_of_memory\"}\n";
      write_all(kOom, sizeof kOom - 1);
      std::_Exit(3);
    }
    write_all(line.data(), line.size());
  }
  ::close(records);
}

}  // namespace flatmarch::reports
