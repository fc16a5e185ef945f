// What the SIMD backend's per-target code (packet.cpp) is given: a frame or a single ray to march
// in packets of rays, on one compiled scene. Plain data, the same for every instruction set.
#pragma once

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
  EdgeTables edges;  // the edges' numbers and gluings as the packets read them

  // A frame: pixels [0, width) x [0, height) seen from `camera`.
  CameraBasis<float> basis{};
  int polygon = 0;
  glm::vec3 from{0.0f};
  int width = 0, height = 0;
  Frame* frame = nullptr;
};

// A job on `tables` with its edge_extra and edges filled in (no frame).
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

// The per-target entry points of packet.cpp, for one instruction set.
struct PacketCode {
  // Lanes per vector: the rays in a packet.
  int (*lanes)();
  // Marches the packets of the frame's grid of tiles in rows [row0, row1), columns
  // [col0, col1), writes their pixels and adds their lane counts.
  void (*march)(const PacketJob& job, int row0, int row1, int col0, int col1, LaneCounts* lanes);
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
};

// The Highway targets (HWY_SSE4, HWY_AVX2, ...) packet.cpp was compiled for.
int64_t compiled_targets();
// The entry points for `target`, which must be compiled and supported by this CPU; 0: the best.
PacketCode packet_code(int64_t target);

}  // namespace flatmarch::simd
