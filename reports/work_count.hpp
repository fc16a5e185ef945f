// The work a frame does, counted by the CPU where the kernel lets a process count itself
// (perf_event_open(2)): instructions retired in user space by every thread of the process. Unlike
// time it hardly moves from run to run, so the results database can judge it where timings
// wander (issue 77); where the machine has no such counter (most VMs, containers under a strict
// perf_event_paranoid) the steps and crossings stand in, and the results say why.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace flatmarch::reports {

class WorkCounter {
 public:
  enum class Event {
    kInstructions,  // instructions retired, user space
    kTaskClock,     // the threads' CPU time in ns: a software event every Linux kernel has
  };
  // A counter on every thread the process has now (start it after the threads that do the work
  // exist: a thread made later is not counted); nullopt, with `why`, where it cannot be opened.
  static std::optional<WorkCounter> open(Event event, std::string* why);
  WorkCounter(WorkCounter&& other) noexcept;
  WorkCounter& operator=(WorkCounter&&) = delete;
  WorkCounter(const WorkCounter&) = delete;
  ~WorkCounter();

  void start();
  // The count since start(), summed over the threads.
  uint64_t stop();

 private:
  WorkCounter() = default;
  std::vector<int> fds_;
};

// "" where this machine counts instructions, else why not (asked once a process).
const std::string& instructions_unavailable();

}  // namespace flatmarch::reports
