// The SIMD backend's frames and rays, per instruction set: packets of rays over tiles of pixels
// (packet.hpp's tile_shape), lanes refilled with the next pixels as their rays end; the camera
// rays and the shading of a packet; and the entry points packet.hpp lists. The march itself is
// marcher-inl.h's, on the walls of walls-inl.h and the solids of solids-inl.h, in the vectors of
// lanes-inl.h.
//
// This file is compiled once per instruction set (hwy/foreach_target.h) and the best one the CPU
// supports is picked at run time (HWY_DYNAMIC_DISPATCH; simd.cpp can force one).

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "backends/simd/packet.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>
#include <stdexcept>

#include "backends/simd/packet.hpp"
// Per-target parts (after foreach_target.h, as it re-includes this file for each target).
#include "backends/simd/lanes-inl.h"
#include "backends/simd/marcher-inl.h"
#include "backends/simd/maths-inl.h"

HWY_BEFORE_NAMESPACE();
namespace flatmarch::simd {
namespace HWY_NAMESPACE {

#if HWY_TARGET == HWY_SCALAR
// Highway compiles its baseline target, one lane without SIMD, into every dispatch table, but the
// backend never runs it: simd.cpp offers avx512, avx2 and sse4 (kIsas) and is unavailable on a CPU
// without one. Compiled as the others, it was nearly half of this file's compile time (280 s ->
// 152 s at -O2 -g on one core of a Zen 5); here the entry points only say so.
[[noreturn]] inline void NotOffered() {
  throw std::logic_error("the simd backend has no packets for Highway's scalar target");
}
int PacketLanes() {
  NotOffered();
}
void MarchPackets(const PacketJob&, TileBlocks&, int, LaneCounts*) {
  NotOffered();
}
int64_t RoomSteps(const PacketJob&, int64_t) {
  NotOffered();
}
int TraceRay(const PacketJob&, const Ray&, int, std::vector<kernel::KernelEvent>*) {
  NotOffered();
}
PacketModes Modes(const PacketJob&) {
  NotOffered();
}
#else
// march.glsl's shade(): the colour of finished rays, linear and tone-mapped.
HWY_INLINE void Shade(const KernelParams& params, const Packet& r, V& red, V& green, V& blue) {
  const lane::vec3 fog(lane::Broadcast(params.fog));
  lane::vec3 surface = fog;
  const lane::vec3 normal(r.nx, r.ny, r.nz);
  const M object = AtLeastZero(r.hit);
  const M wall = Equal(r.hit, kHitWall);
  const M floor = Equal(r.hit, kHitFloor);
  const M solid = hn::Or(object, hn::Or(wall, floor));
  if (Any(solid)) {
    lane::vec3 colour = lane::vec3(r.sr, r.sg, r.sb);
    colour = lane::select(lane::lane_bool{wall}, lane::vec3(lane::Broadcast(params.wall)), colour);
    if (Any(floor)) {
      const lane::vec3 tiles =
          lane::floor_tone(lane::vec2(r.ox, r.oy), lane::real(r.t), lane::real(r.dz)) *
          lane::vec3(lane::Broadcast(params.floor_colour));
      colour = lane::select(lane::lane_bool{floor}, tiles, colour);
    }
    const lane::vec3 seen = lane::fogged(lane::lit(colour, normal), fog, r.t, params.fog_distance);
    surface = lane::select(lane::lane_bool{solid}, seen, surface);
  }
  const M open = hn::Or(Equal(r.hit, kHitEscape), Equal(r.hit, kHitMiss));
  if (Any(open)) {
    const lane::vec3 sky = lane::sky_colour(fog, lane::vec3(lane::Broadcast(params.sky)),
                                            lane::vec3(lane::Broadcast(params.ground)), r.dz);
    surface = lane::select(lane::lane_bool{open}, sky, surface);
  }
  const lane::vec3 c = lane::tone_map(lane::vec3(r.lr, r.lg, r.lb) + lane::real(r.clear) * surface);
  red = c.x.v;
  green = c.y.v;
  blue = c.z.v;
}

// Number of lanes of this target's vectors: the packet size.
int PacketLanes() {
  return static_cast<int>(hn::Lanes(D()));
}

// maths.glsl's camera_ray for each lane's pixel (i, j): through the pixel's centre.
HWY_INLINE void CameraRays(const PacketJob& job, VI i, VI j, V& dx, V& dy, V& dz) {
  const CameraBasis<float>& c = job.basis;
  const lane::vec2 at(hn::ConvertTo(D(), i) + Splat(0.5f), hn::ConvertTo(D(), j) + Splat(0.5f));
  const lane::vec2 size(static_cast<float>(job.width), static_cast<float>(job.height));
  const lane::vec3 d = lane::camera_ray(lane::Broadcast(c.forward), lane::Broadcast(c.right),
                                        lane::Broadcast(c.up), c.tan_half_fov, c.aspect, at, size);
  dx = d.x.v;
  dy = d.y.v;
  dz = d.z.v;
}

// The refill rule's thresholds (tuning.hpp's Tuning::refill_at, refill_spread, patience and
// patience_two_rooms, per instruction set, with how each was measured) are read in
// MarchPacketsWith.

// The pixels of the blocks of tiles a thread takes from `blocks`, in the order its packet takes
// them: block after block as they come, tile by tile within a block, row-major; lane order within
// a tile; pixels outside the frame skipped. A cursor, not an index: no division per pixel.
class PixelQueue {
 public:
  PixelQueue(const PacketJob& job, TileBlocks& blocks, int part, int lanes)
      : blocks_(blocks),
        part_(part),
        tile_(tile_shape(lanes)),
        lanes_(lanes),
        width_(job.width),
        height_(job.height),
        lanes_log2_(Log2(lanes)),
        width_log2_(Log2(tile_.width)) {}
  // Whether pixels may be left: the block's, or blocks not yet taken (pop() tells). A load, no
  // call: the step's loop asks it every time round.
  bool more() const { return row_ < row1_ || !drained_; }
  // The lanes of `waiting`, `count` of them, take the next `count` pixels at once, in lane order
  // (as as many pop()s would give them), where those lie in the tile row being handed out and
  // the block lies inside the frame: the usual case, as only blocks at the frame's right and
  // bottom edges run off it. Sets their pixels in (i, j); false, taking none, otherwise. In
  // vectors, a lane's place in the run being its rank among the lanes of `waiting`: against
  // pop() lane by lane, the analytic frames 0.96-0.97x the time (NOTES.md).
  bool take(M waiting, size_t count, VI& i, VI& j) {
    if (row_ >= row1_ || !inside_) return false;
    const int n = static_cast<int>(count);
    if ((col1_ - col_) * lanes_ - lane_ < n) return false;
    const VI at = SplatI(lane_) + Rank(waiting);  // pixels on from tile col_'s first
    const VI in_tile = hn::And(at, SplatI(lanes_ - 1));
    const VI column = SplatI(col_) + hn::ShiftRightSame(at, lanes_log2_);
    const VI x = hn::ShiftLeftSame(column, width_log2_) + hn::And(in_tile, SplatI(tile_.width - 1));
    const VI y = SplatI(row_ * tile_.height) + hn::ShiftRightSame(in_tile, width_log2_);
    i = Select(waiting, x, i);
    j = Select(waiting, y, j);
    const int next = lane_ + n;
    col_ += next >> lanes_log2_;
    lane_ = next & (lanes_ - 1);
    if (col_ == col1_) {
      col_ = col0_;
      ++row_;
    }
    return true;
  }
  // The next pixel (i, j) in the frame; false when none is left.
  bool pop(int& i, int& j) {
    // Bounded: every turn moves the cursor on or takes one of the frame's blocks.
    while (row_ < row1_ || next_block()) {
      i = col_ * tile_.width + lane_ % tile_.width;
      j = row_ * tile_.height + lane_ / tile_.width;
      if (++lane_ == lanes_) {
        lane_ = 0;
        if (++col_ == col1_) {
          col_ = col0_;
          ++row_;
        }
      }
      if (i < width_ && j < height_) return true;
    }
    return false;
  }

 private:
  bool next_block() {
    if (drained_ || !blocks_.take(part_, row_, row1_, col0_, col1_)) {
      drained_ = true;  // and no more calls to take()
      return false;
    }
    col_ = col0_;
    lane_ = 0;
    inside_ = col1_ * tile_.width <= width_ && row1_ * tile_.height <= height_;
    return true;
  }

  // Of n, a power of two (as lane counts and tile_shape's sides are).
  static int Log2(int n) {
    int k = 0;
    while ((1 << k) < n) ++k;
    return k;
  }

  TileBlocks& blocks_;
  int part_;
  TileShape tile_;
  int lanes_, width_, height_;
  int lanes_log2_, width_log2_;                   // of lanes_ and tile_.width
  int row_ = 0, row1_ = 0, col0_ = 0, col1_ = 0;  // the block: its tile rows and columns
  int col_ = 0, lane_ = 0;                        // the next pixel's tile column and lane
  bool inside_ = false;                           // the block lies inside the frame
  bool drained_ = false;
};

// Marches the pixels of the blocks of tiles it takes from `blocks`, until none is left, and
// writes them. The lanes of one packet take the pixels tile by tile, and a lane whose ray has
// ended takes a next pixel soon (Tuning::refill_at), so that a few long rays do not hold up the
// rest of their tile; one block's pixels follow the last's in the same packet, so lanes stay busy
// until the frame's pixels run out. kNearest: Marcher::step's.
template <bool kNearest>
HWY_NOINLINE void MarchPacketsWith(const PacketJob& job, TileBlocks& blocks, int part,
                                   LaneCounts* lanes) {
  const Marcher marcher(job, nullptr, 0);
  const DI di;
  constexpr size_t kMax = hn::MaxLanes(DI());
  const size_t n = hn::Lanes(D());
  std::array<float, kMax> red{}, green{}, blue{}, t{}, steps{}, crossings{}, hit{};
  std::array<int32_t, kMax> pixel{};  // each lane's pixel's index in the frame
  // Each lane's pixel (i, j); i -1 where the lane holds none.
  VI lane_i = SplatI(-1), lane_j = SplatI(-1);
  const VI lane_index = hn::Iota(di, 0);
  const V from_x = Splat(job.from.x), from_y = Splat(job.from.y), from_z = Splat(job.from.z);
  Frame& frame = *job.frame;

  PixelQueue queue(job, blocks, part, static_cast<int>(n));
  const int64_t pixels = blocks.tiles() * static_cast<int64_t>(n);  // at most
  Packet r;
  Relaxation x;
  Segment seg;
  HeldEdges held;
  Marcher::clear(r, x, seg);
  Marcher::clear(held);
  // Every iteration steps at least one ray, and a ray takes at most max_steps steps.
  const int64_t bound = pixels * (int64_t{job.tables->params.max_steps} + 1) + 1;
  M occupied = None();  // lanes holding a pixel
  const bool analytic = kNearest || job.tables->params.method == kMethodAnalytic;
  // Lanes wait for a new pixel until refill_at eighths of them do (refill_spread while the
  // analytic method's rays are spread over several rooms); in a scene of one room (two without
  // mirrors) no longer than `patience` steps (Tuning).
  const Tuning tune = tuning(kIsa);
  bool spread = false;  // the analytic method's rays over several rooms (Tuning::refill_spread)
  const size_t rooms_in_scene = job.tables->polygons.size();
  const bool mirrors = (job.tables->features & kFeatureMirrors) != 0u;
  int patience = 0;  // none: refill by refill_at and refill_spread only
  if ((analytic || !mirrors) && rooms_in_scene == 1) patience = tune.patience;
  if (!mirrors && rooms_in_scene == 2)
    patience = analytic ? tune.patience : tune.patience_two_rooms;
  const size_t refill_at = static_cast<size_t>(tune.refill_at) * n / 8;
  const size_t refill_spread = static_cast<size_t>(tune.refill_spread) * n / 8;
  int waited = 0;  // steps since the last refill, counted where patience applies
  for (int64_t iteration = 0; iteration < bound; ++iteration) {
    // Lanes are refilled once enough of them wait, or when none is left marching.
    const M waiting = queue.more() ? r.done : hn::And(r.done, occupied);
    const size_t count = hn::CountTrue(D(), waiting);
    if (count > 0 && (count >= (spread ? refill_spread : refill_at) || hn::AllTrue(D(), r.done) ||
                      (patience > 0 && waited >= patience))) {
      waited = 0;
      // Write out the rays that have ended, then give their lanes the next pixels.
      V cr, cg, cb;
      Shade(job.tables->params, r, cr, cg, cb);
      hn::StoreU(cr, D(), red.data());
      hn::StoreU(cg, D(), green.data());
      hn::StoreU(cb, D(), blue.data());
      hn::StoreU(r.t, D(), t.data());
      hn::StoreU(hn::ConvertTo(D(), r.steps), D(), steps.data());
      hn::StoreU(hn::ConvertTo(D(), r.crossings), D(), crossings.data());
      hn::StoreU(hn::ConvertTo(D(), r.hit), D(), hit.data());
      // Each lane's pixel's index (simd.cpp refuses frames of 2^31 pixels or more).
      hn::StoreU(hn::Add(hn::Mul(lane_j, SplatI(frame.width)), lane_i), di, pixel.data());
      for (uint64_t left = Bits(hn::And(waiting, occupied)); left != 0; left &= left - 1) {
        const size_t l = static_cast<size_t>(hwy::Num0BitsBelowLS1Bit_Nonzero64(left));
        frame.set(static_cast<size_t>(pixel[l]), red[l], green[l], blue[l], steps[l], crossings[l],
                  hit[l], t[l]);
      }
      M fresh = None();
      if (queue.take(waiting, count, lane_i, lane_j)) {
        fresh = waiting;
      } else {
        for (uint64_t left = Bits(waiting); left != 0; left &= left - 1) {
          const size_t l = static_cast<size_t>(hwy::Num0BitsBelowLS1Bit_Nonzero64(left));
          const auto here = hn::Eq(lane_index, hn::Set(di, static_cast<int32_t>(l)));
          int i = 0, j = 0;
          if (queue.pop(i, j))
            fresh = hn::Or(fresh, hn::RebindMask(D(), here));
          else
            i = -1;  // none left: the lane holds no pixel
          lane_i = hn::IfThenElse(here, hn::Set(di, i), lane_i);
          lane_j = hn::IfThenElse(here, hn::Set(di, j), lane_j);
        }
      }
      occupied = hn::RebindMask(D(), hn::Gt(lane_i, SplatI(-1)));
      if (!hn::AllFalse(D(), fresh)) {
        V dx, dy, dz;
        CameraRays(job, lane_i, lane_j, dx, dy, dz);
        marcher.start(r, x, seg, fresh, job.polygon, from_x, from_y, from_z, dx, dy, dz);
        continue;  // a ray may end as it starts (a miss): write it out before stepping
      }
    }
    if (hn::AllTrue(D(), r.done)) break;  // no pixels left and every ray written
    const int rooms = marcher.template step<kNearest>(r, x, seg, held, *lanes);
    spread = analytic && rooms > 2;
    if (patience > 0) ++waited;
  }
}

// MarchPacketsWith; where the job's exit is found by the nearest line, in a copy of its own for
// the analytic method alone. Inlined into the one loop, the nearest line gave back what it saved
// (double pentagon 0.94x, cube 0.98x) on the frames that never take it (4-square staircase
// 1.04-1.09x, L-shape 1.02-1.04x: the code around the step compiled differently, NOTES.md); in a
// copy of its own those are compiled as before. The copy is compiled only for the instruction
// sets whose tuning takes it (kModeNearestLine in Tuning::modes; every one in a probe build): a
// copy for every instruction set made this file's compile 196 -> 256 s (-O2 -g, one core; AVX-512's
// alone, 216 s).
#ifdef FLATMARCH_SIMD_TUNING_PROBE
constexpr bool kNearestLineCompiled = true;
#else
constexpr bool kNearestLineCompiled = tuning(kIsa).takes(kModeNearestLine);
#endif
// Whether a frame of `job` takes the nearest line's copy.
bool NearestLineCopy(const PacketJob& job) {
  return kNearestLineCompiled && job.exit_by_nearest_line &&
         (ModesAllowed(job) & kModeNearestLine) != 0u;
}
template <bool kCompiled>
void MarchPacketsChosen(const PacketJob& job, TileBlocks& blocks, int part, LaneCounts* lanes) {
  if constexpr (kCompiled) {
    if (NearestLineCopy(job)) {
      MarchPacketsWith<true>(job, blocks, part, lanes);
      return;
    }
  }
  MarchPacketsWith<false>(job, blocks, part, lanes);
}
void MarchPackets(const PacketJob& job, TileBlocks& blocks, int part, LaneCounts* lanes) {
  MarchPacketsChosen<kNearestLineCompiled>(job, blocks, part, lanes);
}

PacketModes Modes(const PacketJob& job) {
  return Marcher(job, nullptr, 0).modes(NearestLineCopy(job));
}

// The rays of the frame's central tile (a packet's worth, clamped to the frame), started from the
// camera.
void CentralPacket(const PacketJob& job, const Marcher& marcher, Packet& r, Relaxation& x,
                   Segment& seg) {
  const TileShape tile = tile_shape(PacketLanes());
  constexpr size_t kMax = hn::MaxLanes(DI());
  std::array<int32_t, kMax> pixel_i{}, pixel_j{};
  for (size_t l = 0; l < hn::Lanes(D()); ++l) {
    const int i = job.width / 2 - tile.width / 2 + static_cast<int>(l) % tile.width;
    const int j = job.height / 2 - tile.height / 2 + static_cast<int>(l) / tile.width;
    pixel_i[l] = std::clamp(i, 0, job.width - 1);
    pixel_j[l] = std::clamp(j, 0, job.height - 1);
  }
  V dx, dy, dz;
  const DI di;
  CameraRays(job, hn::LoadU(di, pixel_i.data()), hn::LoadU(di, pixel_j.data()), dx, dy, dz);
  Marcher::clear(r, x, seg);
  marcher.start(r, x, seg, hn::Not(None()), job.polygon, Splat(job.from.x), Splat(job.from.y),
                Splat(job.from.z), dx, dy, dz);
}

// One room's step on a full packet, `repeats` times: the central tile's rays (CentralPacket),
// each time from their start, take one step. Returns the lanes that stepped, summed: the
// lane-steps a packet takes when nothing leaves a lane idle (a ray that starts done does not
// count).
int64_t RoomSteps(const PacketJob& job, int64_t repeats) {
  const Marcher marcher(job, nullptr, 0);
  Packet start, r;
  Relaxation start_x, x;
  Segment start_seg, seg;
  CentralPacket(job, marcher, start, start_x, start_seg);
  HeldEdges held;
  Marcher::clear(held);
  LaneCounts lanes;
  V sum = Splat(0.0f);  // of the steps' results, so that none is left out as unused
  for (int64_t k = 0; k < repeats; ++k) {
    r = start;
    x = start_x;
    seg = start_seg;
    marcher.step(r, x, seg, held, lanes);
    sum = sum + r.t + r.ox + r.oy + r.oz;
  }
  volatile float sink = hn::GetLane(sum);
  static_cast<void>(sink);
  return lanes.active;
}

// Follows one ray in lane 0 of a packet, recording at most `max_events` of its events; returns
// its steps.
int TraceRay(const PacketJob& job, const Ray& ray, int max_events,
             std::vector<kernel::KernelEvent>* events) {
  const Marcher marcher(job, events, max_events);
  Packet r;
  Relaxation x;
  Segment seg;
  HeldEdges held;
  Marcher::clear(r, x, seg);
  Marcher::clear(held);
  const glm::vec3 from(ray.from), dir(ray.dir);
  marcher.start(r, x, seg, hn::FirstN(D(), 1), ray.polygon, Splat(from.x), Splat(from.y),
                Splat(from.z), Splat(dir.x), Splat(dir.y), Splat(dir.z));
  LaneCounts lanes;
  for (int i = 0; i < job.tables->params.max_steps && !hn::AllTrue(D(), r.done); ++i)
    marcher.step(r, x, seg, held, lanes);
  return hn::GetLane(r.steps);
}

#endif  // HWY_TARGET == HWY_SCALAR

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace flatmarch::simd
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace flatmarch::simd {
PacketJob packet_job(const kernel::SceneTables<float>& tables) {
  PacketJob job;
  job.tables = &tables;
  for (const auto& e : tables.edges) {
    const float abx = e.segment.z - e.segment.x, aby = e.segment.w - e.segment.y;
    const float tolerance = tables.params.vertex_tolerance * std::sqrt(e.line.w);
    job.edge_extra.emplace_back(abx, aby, tolerance, e.segment.y + aby);
    job.edge_high.push_back(1.0f + tolerance);
  }
  job.edges = edge_tables(tables, job.edge_extra);
  job.exit_by_nearest_line = tables.params.method == kMethodAnalytic &&
                             tables.polygons.size() > 1 && !job.edges.same_rooms &&
                             tables.params.convex != 0;
  return job;
}

HWY_EXPORT(PacketLanes);
HWY_EXPORT(MarchPackets);
HWY_EXPORT(TraceRay);
HWY_EXPORT(RoomSteps);
HWY_EXPORT(Modes);

int64_t compiled_targets() {
  return HWY_TARGETS;
}

PacketCode packet_code(int64_t target) {
  // HWY_DYNAMIC_DISPATCH picks from the targets hwy::SupportedTargets() reports; to force one,
  // report only it while the function pointers are taken.
  static std::mutex mutex;
  const std::lock_guard<std::mutex> lock(mutex);
  if (target != 0) hwy::SetSupportedTargetsForTest(target);
  hwy::GetChosenTarget().Update(hwy::SupportedTargets());
  PacketCode code{&HWY_DYNAMIC_DISPATCH(PacketLanes), &HWY_DYNAMIC_DISPATCH(MarchPackets),
                  &HWY_DYNAMIC_DISPATCH(TraceRay), &HWY_DYNAMIC_DISPATCH(RoomSteps),
                  &HWY_DYNAMIC_DISPATCH(Modes)};
  if (target != 0) {
    hwy::SetSupportedTargetsForTest(0);
    hwy::GetChosenTarget().Update(hwy::SupportedTargets());
  }
  return code;
}

}  // namespace flatmarch::simd
#endif
