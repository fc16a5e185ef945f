#include "backends/simd/simd.hpp"

#include <hwy/targets.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <limits>
#include <mutex>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "backends/kernel_trace.hpp"

namespace flatmarch {

namespace simd {
namespace {

// --isa names of the Highway targets packet.cpp may be compiled for, best first.
constexpr std::array<std::pair<const char*, int64_t>, 3> kIsas{
    {{"avx512", HWY_AVX3}, {"avx2", HWY_AVX2}, {"sse4", HWY_SSE4}}};

}  // namespace

// Made with the backend, started by its first frame (task_arena starts once, safely from any
// thread), and shared by the threads that render with it (execute() may be called from several).
struct Threads {
  explicit Threads(int threads) : arena(threads > 0 ? threads : tbb::task_arena::automatic) {}
  tbb::task_arena arena;
};

PacketJob frame_job(const kernel::SceneTables<float>& tables, const Camera& camera, int width,
                    int height, Frame& frame) {
  PacketJob job = packet_job(tables);
  job.basis = camera_basis<float>(float(camera.yaw_deg), float(camera.pitch_deg),
                                  float(camera.fov_deg), width, height);
  job.polygon = camera.polygon;
  job.from = glm::vec3(camera.position);
  job.width = width;
  job.height = height;
  job.frame = &frame;
  return job;
}

std::vector<std::string> isa_names(bool supported_only) {
  std::vector<std::string> names;
  const int64_t here = supported_only ? hwy::SupportedTargets() : ~int64_t{0};
  for (const auto& [name, target] : kIsas)
    if ((compiled_targets() & here & target) != 0) names.emplace_back(name);
  return names;
}

int64_t isa_target(const std::string& name) {
  for (const auto& [isa, target] : kIsas)
    if (name == isa) return target;
  return 0;
}

}  // namespace simd

SimdBackend::SimdBackend(BackendOptions options) : options_(std::move(options)) {
  const std::vector<std::string> supported = simd::isa_names(true);
  if (options_.threads < 0) {
    unavailable_ = "--threads must be 0 (all cores) or more";
  } else if (supported.empty()) {
    unavailable_ =
        "this CPU runs none of the instruction sets it was compiled for (avx512, avx2, "
        "sse4)";
  } else if (options_.isa.empty()) {
    isa_ = supported.front();
  } else if (std::find(supported.begin(), supported.end(), options_.isa) != supported.end()) {
    isa_ = options_.isa;
  } else {
    std::string list;
    for (const std::string& name : supported) list += (list.empty() ? "" : ", ") + name;
    const std::vector<std::string> compiled = simd::isa_names(false);
    const bool known = std::find(compiled.begin(), compiled.end(), options_.isa) != compiled.end();
    unavailable_ = "instruction set \"" + options_.isa + "\" " +
                   (known ? "is not supported by this CPU" : "is unknown") +
                   " (this CPU runs: " + list + ")";
  }
  for (const auto& [name, target] : simd::kIsas)
    if (isa_ == name) target_ = target;
  // The best target needs no forcing.
  if (target_ != 0) code_ = simd::packet_code(isa_ == supported.front() ? 0 : target_);
  if (target_ != 0) threads_ = std::make_shared<simd::Threads>(options_.threads);
}

std::string SimdBackend::description() const {
  return "the kernel on packets of rays with Google Highway (" +
         (isa_.empty() ? std::string("?") : isa_ + ", " + std::to_string(lanes()) + " lanes") +
         ") on " +
         (options_.threads > 0
              ? std::to_string(options_.threads) + " threads"
              : "all " + std::to_string(tbb::info::default_concurrency()) + " cores") +
         " (oneTBB); f32";
}

Availability SimdBackend::availability() const {
  if (!unavailable_.empty()) return {false, unavailable_};
  return {};
}

simd::PacketCode SimdBackend::code() const {
  if (target_ == 0) throw std::runtime_error("the simd backend is unavailable: " + unavailable_);
  return code_;
}

int SimdBackend::threads() const {
  return options_.threads > 0 ? options_.threads : tbb::info::default_concurrency();
}

int SimdBackend::lanes() const {
  return target_ == 0 ? 0 : code_.lanes();
}

namespace {

void check_precision(const MarchParams& params) {
  if (params.precision != Precision::f32)
    throw std::invalid_argument(
        "the simd backend marches in f32 only (the scalar backend runs f64)");
}

// Reports `done()` (a fraction below 1) to `progress` every 20 ms from a thread of its own, while
// it rises by 2% or more, until finish(), which reports 1. Nothing, and no thread, without
// `progress`.
class ProgressPoller {
 public:
  ProgressPoller(const Progress& progress, std::function<double()> done)
      : progress_(progress), done_(std::move(done)) {
    if (progress_) thread_ = std::thread([this] { run(); });
  }
  ProgressPoller(const ProgressPoller&) = delete;
  ProgressPoller& operator=(const ProgressPoller&) = delete;
  ~ProgressPoller() { stop(); }
  void finish() {
    stop();
    if (progress_) progress_(1.0);
  }

 private:
  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    double reported = 0.0;
    // Bounded: ends when stop() is called, once the frame is done.
    while (!stopped_.wait_for(lock, std::chrono::milliseconds(20), [this] { return stop_; })) {
      const double fraction = done_();
      if (fraction - reported >= 0.02 && fraction < 1.0) progress_(reported = fraction);
    }
  }
  void stop() {
    if (!thread_.joinable()) return;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    stopped_.notify_one();
    thread_.join();
  }

  const Progress& progress_;
  std::function<double()> done_;
  std::mutex mutex_;
  std::condition_variable stopped_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace

Frame SimdBackend::render(const Scene& scene, const Camera& camera, int width, int height,
                          const MarchParams& params, const Progress& progress) const {
  simd::LaneCounts lanes;
  return render_counted(scene, camera, width, height, params, progress, lanes);
}

Frame SimdBackend::render_counted(const Scene& scene, const Camera& camera, int width, int height,
                                  const MarchParams& params, const Progress& progress,
                                  simd::LaneCounts& lanes) const {
  check_precision(params);
  // The packets hold each lane's pixel's index in a 32-bit lane.
  if (width < 0 || height < 0 || int64_t{width} * height > std::numeric_limits<int32_t>::max())
    throw std::invalid_argument("the simd backend renders frames of up to 2^31 - 1 pixels, not " +
                                std::to_string(width) + "x" + std::to_string(height));
  const simd::PacketCode packets = code();
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
  Frame frame(width, height);
  const simd::PacketJob job = simd::frame_job(tables, camera, width, height, frame);
  const simd::TileShape tile = simd::tile_shape(packets.lanes());
  const int rows = (height + tile.height - 1) / tile.height;
  const int cols = (width + tile.width - 1) / tile.width;

  std::atomic<int64_t> active{0}, slots{0};
  // One packet a thread, each taking blocks of tiles until none is left (simd::TileBlocks).
  simd::TileBlocks blocks(rows, cols, threads_->arena.max_concurrency());
  // Progress, where asked for: the share of the frame's blocks handed out, read by a thread of
  // its own every 20 ms (the packets' loop makes no call to report it), then 1 once every pixel
  // is written.
  ProgressPoller poller(progress, [&] {
    return static_cast<double>(blocks.taken()) /
           static_cast<double>(std::max<int64_t>(blocks.count(), 1));
  });
  threads_->arena.execute([&] {
    tbb::parallel_for(
        0, blocks.parts(), 1,
        [&](int part) {
          simd::LaneCounts local;
          packets.march(job, blocks, part, &local);
          active += local.active;
          slots += local.slots;
        },
        tbb::simple_partitioner());
  });
  poller.finish();
  lanes.active += active;
  lanes.slots += slots;
  return frame;
}

std::optional<LaneFigures> SimdBackend::lane_figures(const Scene& scene, const Camera& camera,
                                                     int width, int height,
                                                     const MarchParams& params,
                                                     double peak_seconds) const {
  LaneFigures f;
  f.lanes = lanes();
  simd::LaneCounts counts;
  render_counted(scene, camera, width, height, params, {}, counts);
  f.active = counts.active;
  f.slots = counts.slots;
  f.peak_steps_per_s = peak_lane_steps(scene, camera, width, height, params, peak_seconds);
  if (threads() == 1 || isa().empty()) return f;
  BackendOptions options;
  options.isa = isa();
  options.threads = 1;
  const SimdBackend one(options);
  // One untimed frame first: without it the one-thread figures of the same cases moved by
  // 0.57-1.63x between builds in single runs on every instruction set (2-vCPU Intel Xeon, Emerald
  // Rapids; geometric means 0.94 / 0.83 / 0.99 on AVX-512 / AVX2 / SSE4), which no run there could
  // tell from the VM's drift.
  one.render_colour(scene, camera, width, height, params, {});
  std::array<double, 3> seconds{};
  for (double& s : seconds) {
    const auto start = std::chrono::steady_clock::now();
    const Frame frame = one.render_colour(scene, camera, width, height, params, {});
    s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (frame.rgb.empty() && frame.srgb.empty()) throw std::logic_error("an empty frame");
  }
  std::sort(seconds.begin(), seconds.end());
  if (seconds[1] > 0.0) f.one_thread_rays_per_s = static_cast<double>(width) * height / seconds[1];
  return f;
}

double SimdBackend::peak_lane_steps(const Scene& scene, const Camera& camera, int width, int height,
                                    const MarchParams& params, double seconds) const {
  check_precision(params);
  const simd::PacketCode packets = code();
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
  Frame none;  // nothing is drawn
  const simd::PacketJob job = simd::frame_job(tables, camera, width, height, none);
  const int threads = options_.threads > 0 ? options_.threads : tbb::info::default_concurrency();
  // One thread a core, each stepping its own packet for `seconds`: what the cores make at once.
  std::vector<double> rates(static_cast<size_t>(threads), 0.0);
  const auto run = [&](size_t k) {
    const auto start = std::chrono::steady_clock::now();
    int64_t steps = 0;
    double elapsed = 0.0;
    do {
      const int64_t more = packets.room_steps(job, 256);
      if (more == 0) return;  // every ray of the packet starts done: no step to time
      steps += more;
      elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    } while (elapsed < seconds);
    rates[k] = static_cast<double>(steps) / elapsed;
  };
  std::vector<std::thread> pool;
  for (size_t k = 1; k < rates.size(); ++k) pool.emplace_back(run, k);
  run(0);
  for (std::thread& t : pool) t.join();
  return std::accumulate(rates.begin(), rates.end(), 0.0);
}

Trace SimdBackend::trace(const Scene& scene, const Ray& ray, const MarchParams& params,
                         int max_events) const {
  check_precision(params);
  const simd::PacketCode packets = code();
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
  const simd::PacketJob job = simd::packet_job(tables);
  std::vector<kernel::KernelEvent> events;
  const int steps = packets.trace(job, ray, max_events, &events);
  return kernel_trace(events, steps);
}

}  // namespace flatmarch
