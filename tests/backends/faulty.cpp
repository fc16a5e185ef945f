// A backend registered only in the test programs that runs and is wrong on purpose, as the
// renderers this suite measures are wrong: a conformance suite that never meets a wrong backend
// cannot show that it catches one (Filament's no-op driver and deqp's fault injection in spirit).
// It appears in every list of backends with no edit but this file, so it also shows that those
// lists read the registry.
//
// By default every frame is blank (black, every ray a miss at t 0 after no step) and every trace
// empty: conformance must fail it on every case. FLATMARCH_FAULTY asks for worse, scene by scene
// (faults.hpp).
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "backends/backend.hpp"
#include "backends/scalar/scalar.hpp"
#include "tests/backends/faults.hpp"

namespace flatmarch::test {
namespace {

// How long a hang lasts at most (every loop is bounded): longer than any deadline a supervisor
// gives a case of this backend, so only the supervisor ends it.
constexpr int kHangSeconds = 3600;
// What an unbounded allocation stops at: far beyond any machine this runs on, so the address
// space limit stops it first (or, where none is set, this bound: the blocks are not filled).
constexpr size_t kMostBytes = size_t{1} << 40;

[[noreturn]] void hang() {
  for (int s = 0; s < kHangSeconds; ++s) std::this_thread::sleep_for(std::chrono::seconds(1));
  std::abort();
}

[[noreturn]] void exhaust_memory() {
  constexpr size_t kBlock = size_t{64} << 20;
  static std::vector<std::unique_ptr<char[]>> blocks;
  for (size_t held = 0; held < kMostBytes; held += kBlock) {
    // std::bad_alloc once the limit is reached: the worker's limit is on address space
    // (RLIMIT_AS), which the allocation alone takes. Each block is written once, not filled:
    // filled, the 2 GiB's page faults took the case past its 6 s deadline on a loaded 2-core VM
    // (a timeout, not out_of_memory, in two CI-like runs of isolation_test).
    blocks.emplace_back(new char[kBlock]);
    blocks.back()[0] = 1;
  }
  throw std::bad_alloc();
}

// Acts a fault that ends or stalls the process; returns for the others.
void act(const Fault& f) {
  switch (f.kind) {
    case Fault::Kind::crash:
      ::raise(SIGSEGV);
      std::abort();  // if SIGSEGV is caught and ignored
    case Fault::Kind::abort:
      std::abort();
    case Fault::Kind::hang:
      hang();
    case Fault::Kind::oom:
      exhaust_memory();
    case Fault::Kind::sleep:
      std::this_thread::sleep_for(std::chrono::duration<double>(f.seconds));
      return;
    case Fault::Kind::nan:
    case Fault::Kind::flip:
      return;
  }
}

class FaultyBackend final : public Backend {
 public:
  std::string name() const override { return "faulty"; }
  std::string description() const override {
    return "a test backend that runs and is wrong on purpose (FLATMARCH_FAULTY)";
  }
  Availability availability() const override {
    try {
      faults_from_environment();
    } catch (const std::invalid_argument& e) {
      return {false, e.what()};
    }
    return {true, ""};
  }
  std::vector<Method> methods() const override {
    return {kKernelMethods.begin(), kKernelMethods.end()};
  }

  Frame render(const Scene& scene, const Camera& camera, int width, int height,
               const MarchParams& params, const Progress& progress) const override {
    const std::optional<Fault> fault =
        fault_for(faults_from_environment(), scene.name, to_string(params.method));
    if (!fault) return blank(width, height);
    act(*fault);
    Frame f = scalar_.render(scene, camera, width, height, params, progress);
    if (fault->kind == Fault::Kind::nan) {
      const float nan = std::numeric_limits<float>::quiet_NaN();
      std::fill(f.rgb.begin(), f.rgb.end(), nan);
      std::fill(f.t.begin(), f.t.end(), nan);
    } else if (fault->kind == Fault::Kind::flip) {
      flip_rows(f);
    }
    return f;
  }

  Trace trace(const Scene& scene, const Ray& ray, const MarchParams& params,
              int max_events) const override {
    const std::optional<Fault> fault =
        fault_for(faults_from_environment(), scene.name, to_string(params.method));
    if (!fault) return {};
    act(*fault);
    Trace t = scalar_.trace(scene, ray, params, max_events);
    if (fault->kind == Fault::Kind::nan)
      for (Event& e : t.events) e.t = std::numeric_limits<double>::quiet_NaN();
    return t;  // flip: a trace has no rows; the frame's are flipped
  }

 private:
  static Frame blank(int width, int height) {
    Frame f(width, height);
    std::fill(f.rgb.begin(), f.rgb.end(), 0.0f);
    std::fill(f.steps.begin(), f.steps.end(), 0.0f);
    std::fill(f.crossings.begin(), f.crossings.end(), 0.0f);
    std::fill(f.hit.begin(), f.hit.end(), static_cast<float>(kHitMiss));
    std::fill(f.t.begin(), f.t.end(), 0.0f);
    return f;
  }

  static void flip_rows(Frame& f) {
    const auto w = static_cast<size_t>(f.width);
    for (int j = 0; j < f.height / 2; ++j) {
      const size_t a = f.pixel(0, j), b = f.pixel(0, f.height - 1 - j);
      std::swap_ranges(f.rgb.begin() + static_cast<ptrdiff_t>(3 * a),
                       f.rgb.begin() + static_cast<ptrdiff_t>(3 * (a + w)),
                       f.rgb.begin() + static_cast<ptrdiff_t>(3 * b));
      for (Channel* c : {&f.steps, &f.crossings, &f.hit, &f.t})
        std::swap_ranges(c->begin() + static_cast<ptrdiff_t>(a),
                         c->begin() + static_cast<ptrdiff_t>(a + w),
                         c->begin() + static_cast<ptrdiff_t>(b));
      if (!f.srgb.empty())
        std::swap_ranges(f.srgb.begin() + static_cast<ptrdiff_t>(4 * a),
                         f.srgb.begin() + static_cast<ptrdiff_t>(4 * (a + w)),
                         f.srgb.begin() + static_cast<ptrdiff_t>(4 * b));
    }
  }

  ScalarBackend scalar_;
};

[[maybe_unused]] const bool registered = register_backend(
    {.name = "faulty",
     .make = [](const BackendOptions&) { return std::make_unique<FaultyBackend>(); },
     .wrong_on_purpose = "a test backend, wrong on purpose: blank frames and empty traces, or "
                         "the faults FLATMARCH_FAULTY asks for"});

}  // namespace
}  // namespace flatmarch::test
