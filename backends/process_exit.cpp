#include "backends/process_exit.hpp"

#include <atomic>
#include <cstdlib>
#include <mutex>
#include <vector>

namespace flatmarch {

namespace {
std::atomic<bool> exiting{false};
}  // namespace

void driver_loaded() {
  // A handler for every driver loaded (there are few), so that one runs before each driver's.
  std::atexit([] { exiting = true; });
}

bool process_exiting() {
  return exiting;
}

void leave_to_the_os(std::shared_ptr<void> object) {
  static std::mutex mutex;
  static auto* kept = new std::vector<std::shared_ptr<void>>;
  const std::lock_guard<std::mutex> lock(mutex);
  kept->push_back(std::move(object));
}

}  // namespace flatmarch
