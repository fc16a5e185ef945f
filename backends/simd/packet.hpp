// What the SIMD backend's per-target code (packet.cpp) is given: a frame or a single ray to march
// in packets of rays, on one compiled scene. Plain data, the same for every instruction set.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <vector>

#include "backends/backend.hpp"
#include "backends/simd/edge_tables.hpp"
#include "kernels/camera.hpp"
#include "kernels/compile.hpp"

namespace flatmarch::simd {

// Lane utilisation: of the lanes a packet step could have used, how many did work.
struct LaneCounts {
  int64_t active = 0;  // lanes that took a step, summed over passes
  int64_t slots = 0;   // lanes per vector, summed over passes
};

struct PacketJob {
  const kernel::SceneTables<float>* tables = nullptr;
  // Per edge of tables->edges, what the packets would otherwise recompute per step: b - a (x, y),
  // the vertex tolerance in units of the edge parameter (z), a.y + (b - a).y (w).
  std::vector<glm::vec4> edge_extra;
  // And 1 + that tolerance, the edge parameter's upper bound (maths.glsl's on_edge): read by a
  // room's own exit-edge loop, which added it once per edge tested.
  std::vector<float> edge_high;
  EdgeTables edges;  // the edges' numbers and gluings as the packets read them
  // The analytic method's whole passes find their exit edge by the nearest line first (the same
  // exit: nearest-inl.h): in scenes of several convex rooms not alike, where it saves work.
  bool exit_by_nearest_line = false;
  // Modes (tuning.hpp's Mode) this job leaves to their fallbacks whatever the instruction set's
  // tuning takes: the tests run each mode's fallback on every instruction set.
  uint32_t modes_off = 0;

  // A frame: pixels [0, width) x [0, height) seen from `camera`.
  CameraBasis<float> basis{};
  int polygon = 0;
  glm::vec3 from{0.0f};
  int width = 0, height = 0;
  Frame* frame = nullptr;
};

// A job on `tables` with its edge_extra, edge_high and edges filled in (no frame).
PacketJob packet_job(const kernel::SceneTables<float>& tables);

// The job of a frame of `tables` seen from `camera`, drawn into `frame`: packet_job, the
// camera and the colour table (simd.cpp).
PacketJob frame_job(const kernel::SceneTables<float>& tables, const Camera& camera, int width,
                    int height, Frame& frame);

// The tile of pixels one packet covers, for a vector of `lanes` lanes: as square as it can be.
struct TileShape {
  int width = 1, height = 1;
};
inline TileShape tile_shape(int lanes) {
  TileShape s;
  while (s.width * s.width < lanes) s.width *= 2;
  s.height = lanes / s.width;
  return s;
}

// A frame's grid of tiles (`rows` x `cols`), handed out in blocks of up to kRows x kCols tiles to
// the threads that march it. Each thread's packet takes block after block and drains its lanes
// only when no block is left: lanes idle at the end of a thread's share of the frame, not at the
// end of every block (as when each of oneTBB's chunks drained its own packet: lanes busy fell with
// more threads, 0.90 on one thread to 0.845 on 16, the L-shape's analytic method on a 16-CPU
// Xeon). The blocks, row-major, are split into `parts` runs of consecutive blocks, one a thread:
// a thread takes its own run's blocks in order, then the next runs' (those of threads still at
// work), so that threads write apart until the frame's end. A block is a row of up to 40 tiles
// (160 pixels with 16 lanes): small, so that the threads end together, and wide, since on the
// Zen 5 VM blocks of 2 x 8 tiles made one thread's frames 1.07-1.08x slower (NOTES.md).
class TileBlocks {
 public:
  static constexpr int kRows = 1, kCols = 40;
  TileBlocks(int rows, int cols, int parts)
      : rows_(std::max(rows, 0)),
        cols_(std::max(cols, 0)),
        across_((cols_ + kCols - 1) / kCols),
        count_(int64_t{(rows_ + kRows - 1) / kRows} * across_),
        runs_(static_cast<size_t>(std::max(parts, 1))) {
    const auto n = static_cast<int64_t>(runs_.size());
    for (int64_t p = 0; p < n; ++p) {
      runs_[p].next = count_ * p / n;
      runs_[p].end = count_ * (p + 1) / n;
    }
  }
  int parts() const { return static_cast<int>(runs_.size()); }
  // Blocks in the frame.
  int64_t count() const { return count_; }
  // Tiles in the frame.
  int64_t tiles() const { return int64_t{rows_} * cols_; }
  // Takes the next block for the thread of `part`, tile rows [row0, row1) and columns
  // [col0, col1); false when none is left. Any thread may call it. No call in it: it is inlined
  // into the packets' loop, where a call would have their vectors saved and restored around it.
  bool take(int part, int& row0, int& row1, int& col0, int& col1) {
    const auto n = runs_.size();
    for (size_t q = 0; q < n; ++q) {  // bounded: one try a run
      Run& run = runs_[(static_cast<size_t>(std::max(part, 0)) + q) % n];
      if (run.next.load(std::memory_order_relaxed) >= run.end) continue;
      const int64_t k = run.next.fetch_add(1, std::memory_order_relaxed);
      if (k >= run.end) continue;
      row0 = static_cast<int>(k / across_) * kRows;
      row1 = std::min(row0 + kRows, rows_);
      col0 = static_cast<int>(k % across_) * kCols;
      col1 = std::min(col0 + kCols, cols_);
      taken_.fetch_add(1, std::memory_order_relaxed);
      return true;
    }
    return false;
  }
  // Blocks taken so far, from any thread.
  int64_t taken() const { return taken_.load(std::memory_order_relaxed); }

 private:
  struct alignas(64) Run {  // a cache line each: threads take from their own
    std::atomic<int64_t> next{0};
    int64_t end = 0;
  };
  int rows_, cols_, across_;
  int64_t count_;
  std::vector<Run> runs_;
  alignas(64) std::atomic<int64_t> taken_{0};
};

// What the packets of a frame take on one instruction set: the modes (tuning.hpp's Mode bits)
// and how a pass over the rays of several rooms reads their edges.
struct PacketModes {
  uint32_t modes = 0;
  // "one room" (the scene's only room), "lookup" (each lane's edges looked up in `vectors`
  // vectors of the scene's edges), "blend" (each room's broadcast and blended by lane) or
  // "single" (one room a pass).
  const char* passes = "";
  int vectors = 0;
};

// The per-target entry points of packet.cpp, for one instruction set.
struct PacketCode {
  // Lanes per vector: the rays in a packet.
  int (*lanes)();
  // Marches packets over the frame's tiles, taking blocks of them from `blocks` (its run `part`
  // first) until none is left, writes their pixels and adds their lane counts. Several threads
  // may share `blocks`, each with its own part.
  void (*march)(const PacketJob& job, TileBlocks& blocks, int part, LaneCounts* lanes);
  // Follows one ray (lane 0 of a packet), recording at most `max_events` events; returns its
  // steps.
  int (*trace)(const PacketJob& job, const Ray& ray, int max_events,
               std::vector<kernel::KernelEvent>* events);
  // One room's step on a full packet, `repeats` times: the packet of the frame's central tile of
  // pixels (a packet's worth of rays from the camera, in its room), each time from the rays'
  // start, takes one step. Returns the lane-steps taken (lanes times repeats where no ray
  // starts done). Timed, it is the most lane-steps a second a core makes on this scene and
  // method: no lane idle, no pixel to shade or write, the tables in cache.
  int64_t (*room_steps)(const PacketJob& job, int64_t repeats);
  // What a frame of `job` takes on this instruction set (PacketModes).
  PacketModes (*modes)(const PacketJob& job);
};

// The Highway targets (HWY_SSE4, HWY_AVX2, ...) packet.cpp was compiled for.
int64_t compiled_targets();
// The entry points for `target`, which must be compiled and supported by this CPU; 0: the best.
PacketCode packet_code(int64_t target);

}  // namespace flatmarch::simd
