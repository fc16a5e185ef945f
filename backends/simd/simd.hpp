// The SIMD backend: the kernel on packets of rays (packet.cpp, Google Highway), the best
// instruction set this CPU has picked at run time, one packet a thread on all cores (oneTBB), each
// taking blocks of tiles until none is left (simd::TileBlocks).
// Float32 only.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "backends/backend.hpp"
#include "backends/simd/packet.hpp"

namespace flatmarch {

namespace simd {
// Instruction sets by the names --isa takes, best first: those compiled in and, when
// `supported_only`, those this CPU runs.
std::vector<std::string> isa_names(bool supported_only);
// The Highway target of --isa's `name` (packet_code's argument); 0 for a name it does not know.
int64_t isa_target(const std::string& name);
// The threads a backend's frames run on (a oneTBB arena; simd.cpp).
struct Threads;
}  // namespace simd

class SimdBackend final : public Backend {
 public:
  // options.isa: one of simd::isa_names (empty: the best here); options.threads: 0 for all cores.
  explicit SimdBackend(BackendOptions options = {});

  static constexpr const char* kName = "simd";  // in the registry
  std::string name() const override { return kName; }
  std::string description() const override;
  Availability availability() const override;
  std::vector<Method> methods() const override {
    return {kKernelMethods.begin(), kKernelMethods.end()};
  }
  std::vector<Precision> precisions() const override { return {Precision::f32}; }
  Frame render(const Scene& scene, const Camera& camera, int width, int height,
               const MarchParams& params, const Progress& progress) const override;
  Trace trace(const Scene& scene, const Ray& ray, const MarchParams& params,
              int max_events) const override;

  // render, adding the lane counts of every packet step to `lanes`.
  Frame render_counted(const Scene& scene, const Camera& camera, int width, int height,
                       const MarchParams& params, const Progress& progress,
                       simd::LaneCounts& lanes) const;
  // The most lane-steps a second it makes on this scene, camera and method, on all its threads:
  // each thread times one room's step on a full packet (simd::PacketCode::room_steps) for about
  // `seconds`. A frame's steps a second over this is how close to this CPU's limit it runs; 0
  // when the rays of the packet timed (the frame's central tile) all end as they start.
  double peak_lane_steps(const Scene& scene, const Camera& camera, int width, int height,
                         const MarchParams& params, double seconds = 0.05) const;
  std::optional<LaneFigures> lane_figures(const Scene& scene, const Camera& camera, int width,
                                          int height, const MarchParams& params,
                                          double peak_seconds) const override;
  // The instruction set it runs (--isa's name) and its lanes per packet; "" and 0 if unavailable.
  std::string isa() const { return isa_; }
  int lanes() const;
  // The threads its frames run on: options.threads, or all cores for 0.
  int threads() const;

 private:
  simd::PacketCode code() const;

  BackendOptions options_;
  int64_t target_ = 0;       // the Highway target; 0 when options_.isa cannot run here
  simd::PacketCode code_{};  // its entry points
  std::string isa_, unavailable_;
  // Kept from frame to frame (copies of the backend share them): an arena made for each frame
  // woke oneTBB's sleeping worker at each frame's start, and on a 2-CPU VM the second thread
  // then joined a 640x360 frame about 190 us after it began (26 us with the arena kept).
  std::shared_ptr<simd::Threads> threads_;
};

}  // namespace flatmarch
