// The kernel of kernels/march.glsl run on packets of rays with Google Highway: one ray per lane,
// a packet covering a small tile of pixels (packet.hpp's tile_shape), its march state in vectors.
// The functions mirror march.glsl's one for one, with the same names, operations and order of
// floating-point operations (and no fused multiply-add: this file is compiled with
// -ffp-contract=off), so that a lane takes exactly the steps the scalar backend takes.
//
// What differs is control flow. Where the kernel branches, a packet computes under masks and
// blends. The tables are read per room, not per lane: rays in one room read its records by
// broadcast (a coherent tile's rays mostly are); rays over several rooms take one whole pass
// where each lane's edges can be read by its room alone (held by the lane, or looked up in one
// or two vectors: Walls::whole), else passes over a few rooms each, their records broadcast and
// blended (no gathers). A lane whose ray has ended is masked off until it takes the next pixel;
// the share of lanes doing work in a pass is the lane utilisation the benchmark reports.
// What a step does to the rays it ends or takes across an edge is events-inl.h's.
//
// Included by packet.cpp once per instruction set.

// Per-target include guard: this file is included once per instruction set (hwy/foreach_target.h
// re-includes packet.cpp for each), so the guard toggles with HWY_TARGET_TOGGLE.
#if defined(FLATMARCH_BACKENDS_SIMD_MARCHER_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef FLATMARCH_BACKENDS_SIMD_MARCHER_INL_H_
#undef FLATMARCH_BACKENDS_SIMD_MARCHER_INL_H_
#else
#define FLATMARCH_BACKENDS_SIMD_MARCHER_INL_H_
#endif

#include <hwy/highway.h>

#include <algorithm>
#include <array>
#include <vector>

#include "backends/simd/events-inl.h"
#include "backends/simd/lanes-inl.h"
#include "backends/simd/maths-inl.h"
#include "backends/simd/nearest-inl.h"
#include "backends/simd/solids-inl.h"
#include "backends/simd/walls-inl.h"

HWY_BEFORE_NAMESPACE();
namespace flatmarch::simd {
namespace HWY_NAMESPACE {

class Marcher : private RayEvents {
 public:
  Marcher(const PacketJob& job, std::vector<kernel::KernelEvent>* events, int max_events)
      : RayEvents(job, events, max_events),
        whole_((ModesAllowed(job) & kModeWhole) != 0u && job.tables->polygons.size() > 1 &&
               solids_.by_lane() && walls_.whole(params_.method == kMethodAnalytic)),
        one_room_(job.tables->polygons.size() == 1),
        nearest_(whole_ && walls_.glue_by_lane() && !walls_.same_rooms()),
        rooms_per_pass_(std::clamp(tuning(kIsa).rooms_per_pass, 1, kRoomsPerPass)) {}

  // What a frame of this job takes (PacketModes); `nearest`: in the frame loop's copy that finds
  // the analytic method's exit by the nearest line (MarchPacketsWith<true>).
  PacketModes modes(bool nearest) const {
    PacketModes m;
    const bool analytic = params_.method == kMethodAnalytic;
    const auto take = [&](Mode mode, bool taken) {
      if (taken) m.modes |= mode;
    };
    take(kModeWhole, whole_);
    take(kModeHeld, whole_ && !analytic && walls_.held() && !walls_.same_rooms());
    take(kModeSameRooms, !one_room_ && walls_.same_rooms());
    take(kModeAlike, !one_room_ && walls_.alike());
    take(kModeBySlot, walls_.glue_by_slot());
    take(kModeNearestLine, nearest && analytic && nearest_);
    take(kModeOppositePairs, nearest && analytic && nearest_ && walls_.opposite_pairs());
    m.passes = one_room_ ? "one room" : walls_.passes();
    m.vectors = one_room_ ? 0 : walls_.vectors();
    return m;
  }

  // Edges held by no lane.
  static void clear(HeldEdges& held) {
    held.polygon = SplatI(-1);
    held.first_edge = held.edge_count = SplatI(0);
    for (auto& edge : held.number) edge.fill(Splat(0.0f));
  }

  // A packet with no rays: every lane done.
  static void clear(Packet& r, Relaxation& x, Segment& seg) {
    r.polygon = r.steps = r.crossings = r.hit = SplatI(0);
    r.ox = r.oy = r.oz = r.dx = r.dy = r.dz = r.t = Splat(0.0f);
    r.nx = r.ny = r.nz = r.sr = r.sg = r.sb = r.lr = r.lg = r.lb = r.clear = Splat(0.0f);
    r.done = hn::Not(None());
    x.omega = x.last_radius = x.last_step = Splat(0.0f);
    seg.known = seg.exit.corner = None();
    seg.exit.s = seg.exit.cosine = seg.solids = Splat(0.0f);
    seg.exit.edge = SplatI(-1);
    seg.exit.index = SplatI(0);
  }

  // The start of march.glsl's march(): the lanes of `m` begin a ray from (fx, fy, fz) in
  // `polygon` along (dx, dy, dz). The other lanes are left as they are.
  FLATMARCH_PACKET_INLINE void start(Packet& r, Relaxation& x, Segment& seg, M m, int polygon, V fx,
                                     V fy, V fz, V dx, V dy, V dz) const {
    r.polygon = Select(m, SplatI(polygon), r.polygon);
    Normalize(dx, dy, dz);
    MoveTo(r, m, fx, fy, dx, dy, dz);
    r.oz = Select(m, fz, r.oz);
    r.t = hn::IfThenZeroElse(m, r.t);
    r.steps = Select(m, SplatI(0), r.steps);
    r.crossings = Select(m, SplatI(0), r.crossings);
    r.hit = Select(m, SplatI(kHitMaxSteps), r.hit);
    r.done = hn::AndNot(m, r.done);
    r.lr = hn::IfThenZeroElse(m, r.lr);
    r.lg = hn::IfThenZeroElse(m, r.lg);
    r.lb = hn::IfThenZeroElse(m, r.lb);
    r.clear = Select(m, Splat(1.0f), r.clear);
    // The normal and surface colour are left: only a ray that hits a solid, a wall or the floor
    // reads them, and the hit sets them.
    if (has(kFeaturePeriod)) {
      r.oz = Select(m, lane::mod(r.oz, params_.top).v, r.oz);
    } else {
      const M below = hn::Lt(r.oz, Splat(0.0f)), above = hn::Gt(r.oz, Splat(params_.height));
      enter_band(r, hn::And(m, hn::Or(below, above)));
    }
    relax(x, m);
    seg.known = hn::AndNot(m, seg.known);
    seg.exit.s = Select(m, Splat(kFar), seg.exit.s);
    seg.exit.edge = Select(m, SplatI(-1), seg.exit.edge);
    seg.exit.corner = hn::AndNot(m, seg.exit.corner);
    seg.solids = Select(m, Splat(kFar), seg.solids);
  }

  // One iteration of march.glsl's march() loop for every lane not done: a step, then the end
  // of the rays that have taken max_steps. Where whole_, rays over several rooms take one whole
  // pass (Rooms::whole). Otherwise a step runs in passes of up to kRoomsPerPass rooms (usually
  // one). Returns the rooms its passes went over, summed (a whole pass counts two). kNearest:
  // the analytic method's whole passes find their exit edge by the nearest line
  // (ExitByNearestLine), where their edges are looked up by lane.
  template <bool kNearest = false>
  FLATMARCH_PACKET_INLINE int step(Packet& r, Relaxation& x, Segment& seg, HeldEdges& held,
                                   LaneCounts& lanes) const {
    int rooms_seen = 0;
    const M active = hn::Not(r.done);
    r.steps = Select(active, r.steps + SplatI(1), r.steps);
    std::array<int32_t, hn::MaxLanes(DI())> lane_rooms{};
    if (!one_room_) hn::StoreU(r.polygon, DI(), lane_rooms.data());
    M pending = active;
    const bool analytic = kNearest || params_.method == kMethodAnalytic;  // kNearest: analytic
    if (whole_ && Any(pending)) {
      // Rays over several rooms take one pass, reading the edges they hold or looking them up
      // by their rooms; rays in one room take the one-room pass below.
      const int first = lane_rooms[static_cast<size_t>(hn::FindFirstTrue(D(), pending))];
      if (!hn::AllFalse(D(), hn::AndNot(Equal(r.polygon, first), pending))) {
        const bool hold = !analytic && walls_.held() && !walls_.same_rooms();
        const Rooms rooms = walls_.whole_pass(r.polygon, pending, hold ? &held : nullptr);
        count_lanes(lanes, pending);
        // Three calls, so that each inlined copy knows whether it reads held edges.
        if (analytic)
          analytic_step<false, kNearest, kNearest>(r, seg, pending, rooms);
        else if (hold)
          sphere_step<false>(r, x, pending, rooms, &held);
        else
          sphere_step<false>(r, x, pending, rooms, nullptr);
        pending = None();
        // Counted as two rooms whatever their number: a whole pass costs the same over any
        // number, so the packet need not wait to refill its rays together (Tuning::refill_spread).
        rooms_seen = 2;
      }
    }
    while (Any(pending)) {
      Rooms rooms;
      M pass = None();
      rooms.first_edge = rooms.edge_count = SplatI(0);
      const int most_rooms = walls_.merge() ? rooms_per_pass_ : 1;
      if (one_room_) {  // the scene's one room: no search
        rooms.count = 1;
        rooms.lanes[0] = pass = pending;
        rooms.most_edges = polygons_[0].y;
        rooms.first_edge = SplatI(polygons_[0].x);
        rooms.edge_count = SplatI(polygons_[0].y);
      }
      for (M left = pending; !one_room_ && Any(left) && rooms.count < most_rooms; ++rooms.count) {
        const int polygon = lane_rooms[static_cast<size_t>(hn::FindFirstTrue(D(), left))];
        const M in = hn::And(left, Equal(r.polygon, polygon));
        const ivec4 poly = polygons_[polygon];
        rooms.polygon[static_cast<size_t>(rooms.count)] = polygon;
        rooms.lanes[static_cast<size_t>(rooms.count)] = in;
        rooms.most_edges = std::max(rooms.most_edges, poly.y);
        rooms.first_edge = Select(in, SplatI(poly.x), rooms.first_edge);
        rooms.edge_count = Select(in, SplatI(poly.y), rooms.edge_count);
        pass = hn::Or(pass, in);
        left = hn::AndNot(in, left);
      }
      rooms.all = pass;
      count_lanes(lanes, pass);
      if (rooms.count == 1 && analytic) {
        analytic_step<true, false, kNearest>(r, seg, pass, rooms);
      } else if (rooms.count == 1) {
        sphere_step<true>(r, x, pass, rooms, nullptr);
      } else if (analytic) {
        analytic_step<false, false, kNearest>(r, seg, pass, rooms);
      } else {
        sphere_step<false>(r, x, pass, rooms, nullptr);
      }
      pending = hn::AndNot(pass, pending);
      rooms_seen += rooms.count;
    }
    const M out = hn::AndNot(r.done, hn::RebindMask(D(), r.steps == SplatI(params_.max_steps)));
    finish(r, out, SplatI(kHitMaxSteps), kEventMaxSteps, SplatI(-1), Splat(0.0f));
    return rooms_seen;
  }

 private:
  // A pass over the lanes of `pass`.
  static void count_lanes(LaneCounts& lanes, M pass) {
    lanes.active += static_cast<int64_t>(hn::CountTrue(D(), pass));
    lanes.slots += static_cast<int64_t>(hn::Lanes(D()));
  }

  // ---- Methods -------------------------------------------------------------------------------

  FLATMARCH_PACKET_INLINE void relax(Relaxation& x, M m) const {
    const V omega = Splat(params_.method == kMethodRelaxed ? params_.omega : 1.0f);
    x.omega = Select(m, omega, x.omega);
    x.last_radius = hn::IfThenZeroElse(m, x.last_radius);
    x.last_step = hn::IfThenZeroElse(m, x.last_step);
  }

  // One iteration of sphere or over-relaxed sphere tracing for the rays of `m`, in `rooms`.
  // `held`: the edges the lanes hold, in a whole pass (else null).
  template <bool kOneRoom>
  FLATMARCH_PACKET_INLINE void sphere_step(Packet& r, Relaxation& x, M m, const Rooms& rooms,
                                           const HeldEdges* held) const {
    const WallDistance wall = walls_.wall_distance<kOneRoom>(rooms, held, r.ox, r.oy);
    const SolidDistance solid = solids_.nearest_solid(rooms, r.ox, r.oy, r.oz);
    const V radius = hn::Min(wall.d, solid.d);
    // Over-relaxed steps whose unbounding spheres do not overlap are taken back. In relaxed
    // tracing, whether any lane of a pass is taken back goes either way at random, so the few
    // operations run in every pass rather than after a branch that mispredicts: relaxed frames
    // 0.87-0.99x the time (cube 0.87-0.97, double pentagon 0.95-0.99, 32-square staircase
    // 0.94; the L-shape 0.99-1.06, level), sphere tracing level (NOTES.md).
    const M back = hn::And(hn::And(m, x.omega > Splat(1.0f)), radius + x.last_radius < x.last_step);
    M rest = hn::AndNot(back, m);
    if (params_.method == kMethodRelaxed || Any(back)) {
      advance(r, back, x.last_radius - x.last_step);
      x.last_step = Select(back, x.last_radius, x.last_step);
      x.omega = Select(back, Splat(1.0f), x.omega);
    }
    const V wall_d = hn::Abs(wall.d);
    const V eps = Splat(params_.eps);
    const M hit = hn::And(rest, hn::And(solid.d < eps, solid.d <= wall_d));
    if (Any(hit)) {
      hit_solid(r, hit, solid.object);
      rest = hn::AndNot(hit, rest);
    }
    const M near = hn::And(rest, wall_d < eps);
    if (Any(near)) {
      const M corner = hn::And(near, wall.next_edge() < eps);
      finish(r, corner, SplatI(kHitVertex), kEventVertex, SplatI(-1), Splat(0.0f));
      const M walls = hn::AndNot(corner, hn::And(near, walls_.is_wall(rooms, wall.edge)));
      hit_wall(r, walls, rooms, wall.edge, Splat(0.0f));
      const M cross = hn::AndNot(hn::Or(corner, walls), near);
      if (Any(cross)) {
        cross_edge(r, cross, rooms, wall.edge, Splat(params_.offset));
        relax(x, cross);
      }
      rest = hn::AndNot(near, rest);
    }
    const V safe = hn::Abs(radius);
    const V band = band_exit(r);
    const V remaining = Splat(params_.max_distance) - r.t;
    const M far = hn::And(rest, remaining <= hn::Min(safe, band));
    finish(r, far, SplatI(kHitMaxDistance), kEventMaxDistance, SplatI(-1), remaining);
    rest = hn::AndNot(far, rest);
    const M leave = hn::And(rest, band <= safe);
    if (Any(leave)) {
      leave_band(r, leave, band);
      relax(x, leave);
      rest = hn::AndNot(leave, rest);
    }
    x.last_radius = Select(rest, safe, x.last_radius);
    x.last_step = Select(rest, hn::Min(x.omega * safe, hn::Min(band, remaining)), x.last_step);
    advance(r, rest, x.last_step);
  }

  static FLATMARCH_PACKET_INLINE void move_in_segment(Packet& r, Segment& seg, M m, V s) {
    advance(r, m, s);
    seg.exit.s = Select(m, seg.exit.s - s, seg.exit.s);
    seg.solids = Select(m, hn::Max(seg.solids - s, Splat(0.0f)), seg.solids);
  }

  // One iteration of the analytic method for the rays of `m`, in `rooms`. kNearest: the exit by
  // the nearest line (step's); kCarry: the step's copy (step<true>), where a crossing reads its
  // tint's cosine and its edge's index from the exit (Exit::cosine, Exit::index), whatever pass
  // found it.
  template <bool kOneRoom, bool kNearest = false, bool kCarry = false>
  FLATMARCH_PACKET_INLINE void analytic_step(Packet& r, Segment& seg, M m,
                                             const Rooms& rooms) const {
    const M unknown = hn::AndNot(seg.known, m);
    if (Any(unknown)) {
      const Exit x = kNearest && nearest_
                         ? ExitByNearestLine(walls_, unknown, rooms, params_.vertex_tolerance, r.ox,
                                             r.oy, r.dx, r.dy)
                         : walls_.exit_edge<kOneRoom>(unknown, rooms, r.ox, r.oy, r.dx, r.dy);
      seg.exit.s = Select(unknown, x.s, seg.exit.s);
      seg.exit.edge = Select(unknown, x.edge, seg.exit.edge);
      seg.exit.corner = Select(unknown, x.corner, seg.exit.corner);
      if (kCarry) {
        seg.exit.cosine = Select(unknown, x.cosine, seg.exit.cosine);
        seg.exit.index = Select(unknown, x.index, seg.exit.index);
      }
      if (has(kFeatureObjects))
        seg.solids = Select(unknown, solids_.solid_entry(rooms, r), seg.solids);
      else
        seg.solids = Select(unknown, Splat(kFar), seg.solids);
      seg.known = hn::Or(seg.known, unknown);
    }
    const V max_distance = Splat(params_.max_distance);
    V remaining = max_distance - r.t;
    V band = band_exit(r);  // recomputed below for the rays that move
    M rest = m;
    if (has(kFeatureObjects)) {
      const M solids = hn::And(m, seg.solids < hn::Min(hn::Min(seg.exit.s, band), remaining));
      if (Any(solids)) {
        move_in_segment(r, seg, solids, seg.solids);
        band = Select(solids, band_exit(r), band);
        const SolidDistance solid = solids_.nearest_solid(rooms, r.ox, r.oy, r.oz);
        const M hit = hn::And(solids, solid.d < Splat(params_.eps));
        hit_solid(r, hit, solid.object);
        const M on = hn::AndNot(hit, solids);
        remaining = Select(on, max_distance - r.t, remaining);
        const M step = hn::And(on, solid.d < hn::Min(hn::Min(seg.exit.s, band), remaining));
        move_in_segment(r, seg, step, solid.d);
        rest = hn::AndNot(hn::Or(hit, step), rest);
      }
    }
    const M far = hn::And(rest, remaining < hn::Min(seg.exit.s, band));
    finish(r, far, SplatI(kHitMaxDistance), kEventMaxDistance, SplatI(-1), remaining);
    rest = hn::AndNot(far, rest);
    const M leave = hn::And(rest, band <= seg.exit.s);
    if (Any(leave)) {
      leave_band(r, leave, band);
      seg.known = hn::AndNot(leave, seg.known);
      rest = hn::AndNot(leave, rest);
    }
    const M no_edge = hn::RebindMask(D(), seg.exit.edge < SplatI(0));
    const M vertex = hn::And(rest, hn::Or(no_edge, seg.exit.corner));
    finish(r, vertex, SplatI(kHitVertex), kEventVertex, SplatI(-1),
           hn::IfThenZeroElse(no_edge, seg.exit.s));
    rest = hn::AndNot(vertex, rest);
    const M wall = hn::And(rest, walls_.is_wall(rooms, seg.exit.edge));
    hit_wall(r, wall, rooms, seg.exit.edge, seg.exit.s);
    rest = hn::AndNot(wall, rest);
    if (Any(rest)) {
      advance(r, rest, seg.exit.s);
      // The exit (its cosine and index) carried in the nearest line's copy alone
      // (MarchPacketsWith<true>): the cosine carried in the other too, its sphere and relaxed
      // tracing, which never read it, were 1.02-1.04x slower.
      cross_edge(r, rest, rooms, seg.exit.edge, Splat(0.0f), kCarry ? &seg.exit : nullptr);
      seg.known = hn::AndNot(rest, seg.known);
    }
  }

  // ---- A whole ray ---------------------------------------------------------------------------

  // The rays of `m`, outside the band, enter the first polygon whose footprint they cross.
  FLATMARCH_PACKET_INLINE void enter_band(Packet& r, M m) const {
    if (!Any(m)) return;
    const V height = Splat(params_.height), max_distance = Splat(params_.max_distance);
    const M above = r.oz > height;
    const V s = lane::band_entry(height, r.oz, r.dz, max_distance).v;
    const V qx = r.ox + s * r.dx, qy = r.oy + s * r.dy;
    M open = hn::And(m, s < max_distance);
    for (int k = 0; k < params_.polygon_count && Any(open); ++k) {
      const M in = hn::And(open, walls_.inside_polygon(k, qx, qy));
      if (!Any(in)) continue;
      r.polygon = Select(in, SplatI(k), r.polygon);
      M enter = in;
      if (has(kFeatureFloor)) {  // the underside of the floor
        const M under = hn::AndNot(above, in);
        finish(r, under, SplatI(kHitFloor), kEventFloor, SplatI(-1), s);
        SetNormal(r, under, Splat(0.0f), Splat(0.0f), Splat(-1.0f));
        enter = hn::AndNot(under, in);
      }
      advance(r, enter, s);
      record(enter, kEventEnter, SplatI(k), SplatI(-1), -1, -1, SplatI(-1), r);
      open = hn::AndNot(in, open);
      m = hn::AndNot(in, m);
    }
    if (!Any(m)) return;
    advance(r, m, s);
    r.hit = Select(m, SplatI(kHitMiss), r.hit);
    r.done = hn::Or(r.done, m);
    record(m, kEventMiss, SplatI(-1), SplatI(-1), -1, -1, SplatI(-1), r);
  }

  // Rays over several rooms take one whole pass a step, whatever their rooms (Rooms::whole):
  // in scenes of several rooms and few solids whose edges the lanes can hold or look up
  // (Walls::whole).
  bool whole_;
  bool one_room_;       // the scene has one room: a step's pass needs no search for rooms
  bool nearest_;        // whole passes look their edges up by lane (ExitByNearestLine applies)
  int rooms_per_pass_;  // Tuning::rooms_per_pass
};

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace flatmarch::simd
HWY_AFTER_NAMESPACE();
#endif  // FLATMARCH_BACKENDS_SIMD_MARCHER_INL_H_
