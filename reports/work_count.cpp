#include "reports/work_count.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>

#ifdef __linux__
#include <linux/perf_event.h>
#include <sys/ioctl.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace flatmarch::reports {

#ifdef __linux__

namespace {

int open_on(WorkCounter::Event event, pid_t tid) {
  perf_event_attr a{};
  a.size = sizeof a;
  a.type = event == WorkCounter::Event::kInstructions ? PERF_TYPE_HARDWARE : PERF_TYPE_SOFTWARE;
  a.config = event == WorkCounter::Event::kInstructions
                 ? static_cast<uint64_t>(PERF_COUNT_HW_INSTRUCTIONS)
                 : static_cast<uint64_t>(PERF_COUNT_SW_TASK_CLOCK);
  a.disabled = 1;
  a.exclude_kernel = 1;  // what perf_event_paranoid 2 (Debian's default) lets a process count
  a.exclude_hv = 1;
  return static_cast<int>(syscall(SYS_perf_event_open, &a, tid, -1, -1, 0));
}

}  // namespace

std::optional<WorkCounter> WorkCounter::open(Event event, std::string* why) {
  WorkCounter c;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task", error)) {
    const pid_t tid = static_cast<pid_t>(std::stol(entry.path().filename().string()));
    const int fd = open_on(event, tid);
    if (fd >= 0) {
      c.fds_.push_back(fd);
      continue;
    }
    if (errno == ESRCH) continue;  // the thread ended meanwhile
    if (why) {
      *why = std::string("perf_event_open: ") + std::strerror(errno);
      if (errno == ENOENT || errno == EOPNOTSUPP)
        *why += " (this CPU or virtual machine exposes no such counter)";
      else if (errno == EACCES || errno == EPERM)
        *why += " (kernel.perf_event_paranoid forbids it)";
    }
    return std::nullopt;
  }
  if (c.fds_.empty()) {
    if (why) *why = "no thread to count (/proc/self/task: " + error.message() + ")";
    return std::nullopt;
  }
  return c;
}

WorkCounter::WorkCounter(WorkCounter&& other) noexcept : fds_(std::move(other.fds_)) {
  other.fds_.clear();
}

WorkCounter::~WorkCounter() {
  for (int fd : fds_) close(fd);
}

void WorkCounter::start() {
  for (int fd : fds_) {
    ioctl(fd, PERF_EVENT_IOC_RESET, 0);
    ioctl(fd, PERF_EVENT_IOC_ENABLE, 0);
  }
}

uint64_t WorkCounter::stop() {
  uint64_t total = 0;
  for (int fd : fds_) {
    ioctl(fd, PERF_EVENT_IOC_DISABLE, 0);
    uint64_t n = 0;
    if (read(fd, &n, sizeof n) == static_cast<ssize_t>(sizeof n)) total += n;
  }
  return total;
}

#else

std::optional<WorkCounter> WorkCounter::open(Event, std::string* why) {
  if (why) *why = "counting instructions needs Linux's perf_event_open";
  return std::nullopt;
}
WorkCounter::WorkCounter(WorkCounter&& other) noexcept : fds_(std::move(other.fds_)) {}
WorkCounter::~WorkCounter() = default;
void WorkCounter::start() {}
uint64_t WorkCounter::stop() {
  return 0;
}

#endif

const std::string& instructions_unavailable() {
  static const std::string why = [] {
    std::string w;
    if (WorkCounter::open(WorkCounter::Event::kInstructions, &w)) return std::string();
    return w.empty() ? std::string("unavailable") : w;
  }();
  return why;
}

}  // namespace flatmarch::reports
