// The kernel of kernels/march.glsl run on packets of rays with Google Highway: one ray per lane,
// a packet covering a small tile of pixels (packet.hpp's tile_shape), its march state in vectors.
// The functions mirror march.glsl's one for one, with the same names, operations and order of
// floating-point operations (and no fused multiply-add: this file is compiled with
// -ffp-contract=off), so that a lane takes exactly the steps the scalar backend takes.
//
// What differs is control flow. Where the kernel branches, a packet computes under masks and
// blends. The tables are read per room, not per lane: a step runs in passes over a few rooms
// among the packet's unfinished rays, and a table read is one record per room, broadcast and
// blended (a coherent tile's rays are mostly in one room, so this is usually one broadcast; no
// gathers). A lane whose ray has ended is masked off until it takes the next pixel; the share
// of lanes doing work in a pass is the lane utilisation the benchmark reports.
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

#include "backends/simd/packet.hpp"

// The marcher's functions are inlined into one loop, but under the sanitizers GCC then takes
// over ten minutes on that one function: there it decides what to inline.
#ifndef FLATMARCH_PACKET_INLINE
#ifdef FLATMARCH_SANITIZE_BUILD
#define FLATMARCH_PACKET_INLINE inline
#else
#define FLATMARCH_PACKET_INLINE HWY_INLINE
#endif
#endif

HWY_BEFORE_NAMESPACE();
namespace flatmarch::simd {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using kernel::ivec4;
using D = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<D>;
using V = hn::Vec<D>;
using VI = hn::Vec<DI>;
using M = hn::Mask<D>;
using EdgeRecord = kernel::Tables<float>::EdgeRecord;
using ObjectRecord = kernel::Tables<float>::ObjectRecord;
using KernelParams = kernel::Tables<float>::KernelParams;

HWY_INLINE V Splat(float x) {
  return hn::Set(D(), x);
}
HWY_INLINE VI SplatI(int x) {
  return hn::Set(DI(), x);
}
HWY_INLINE M None() {
  return hn::FirstN(D(), 0);
}
HWY_INLINE M Equal(VI a, int b) {
  return hn::RebindMask(D(), a == SplatI(b));
}
HWY_INLINE M AtLeastZero(VI a) {
  return hn::RebindMask(D(), a > SplatI(-1));
}
// m ? a : b, lane by lane.
HWY_INLINE V Select(M m, V a, V b) {
  return hn::IfThenElse(m, a, b);
}
HWY_INLINE VI Select(M m, VI a, VI b) {
  return hn::IfThenElse(hn::RebindMask(DI(), m), a, b);
}
HWY_INLINE M Select(M m, M a, M b) {
  return hn::Or(hn::And(m, a), hn::AndNot(m, b));
}
HWY_INLINE bool Any(M m) {
  return !hn::AllFalse(D(), m);
}

// What a packet of rays is doing (march.glsl's Ray, one lane per ray).
struct Packet {
  VI polygon;
  V ox, oy, oz;  // point, in the coordinates of `polygon`
  V dx, dy, dz;  // unit direction
  V t;
  VI steps, crossings, hit;
  M done;
  V nx, ny, nz;  // normal of the solid hit
  V sr, sg, sb;  // colour of the solid hit
};

struct WallDistance {
  V d;
  VI edge;
  V second;
};

struct Exit {
  V s;
  VI edge;
  M corner;
};

struct SolidDistance {
  V d;
  VI object;
};

struct Relaxation {
  V omega, last_radius, last_step;
};

struct Segment {
  M known;
  Exit exit;
  V solids;
};

// The rooms of one pass: the polygons its rays are in (at most kRoomsPerPass) and the lanes in
// each. A table read gives every lane its own room's record: in one room a broadcast, in several
// a lookup of each lane's edge in vectors holding the scene's edges (Marcher::lookup_; scenes
// whose edges do not fit in a vector take one room a pass). Coherent rays are mostly in one room;
// rays split between a few (the double pentagon's two, at every crossing) still take one pass a
// step, not one per room.
constexpr int kRoomsPerPass = 4;
struct Rooms {
  int count = 0;
  int most_edges = 0;
  std::array<int, kRoomsPerPass> polygon{};
  std::array<M, kRoomsPerPass> lanes;  // the lanes in each
  M all;                               // the lanes of the pass
  VI first_edge, edge_count;           // of each lane's room, when there are several
};

// The numbers of an edge the packet code reads, by name.
enum Field { kAx, kAy, kAbx, kAby, kAyAby, kNx, kNy, kNa, kInvLength2, kTolerance, kFields };
inline float edge_number(Field f, const kernel::Tables<float>::EdgeRecord& e, glm::vec4 extra) {
  switch (f) {
    case kAx:
      return e.segment.x;
    case kAy:
      return e.segment.y;
    case kAbx:
      return extra.x;
    case kAby:
      return extra.y;
    case kAyAby:
      return extra.w;
    case kNx:
      return e.line.x;
    case kNy:
      return e.line.y;
    case kNa:
      return e.line.z;
    case kInvLength2:
      return e.line.w;
    case kTolerance:
      return extra.z;
    case kFields:
      break;
  }
  return 0.0f;
}

class Marcher {
 public:
  Marcher(const kernel::SceneTables<float>& tables, const std::vector<glm::vec4>& edge_extra,
          std::vector<kernel::KernelEvent>* events, int max_events)
      : polygons_(tables.polygons.data()),
        edges_(tables.edges.data()),
        extra_(edge_extra.data()),
        objects_(tables.objects.data()),
        params_(tables.params),
        features_(tables.features),
        events_(events),
        max_events_(max_events) {
    // Passes over several rooms read the edges by lane from vectors: possible when the scene's
    // edges fit in one.
    merge_ = tables.edges.size() <= hn::Lanes(D());
    if (!merge_) return;
    for (size_t f = 0; f < kFields; ++f)
      for (size_t e = 0; e < tables.edges.size(); ++e)
        lookup_[f][e] = edge_number(static_cast<Field>(f), tables.edges[e], edge_extra[e]);
    // What a gluing does to the rays at each edge, for crossings in one round (cross_glued).
    for (size_t p = 0; p < tables.polygons.size(); ++p) first_edge_[p] = tables.polygons[p].x;
    for (size_t e = 0; e < tables.edges.size(); ++e) {
      const EdgeRecord& edge = tables.edges[e];
      const ivec4 link = edge.link;
      const glm::vec4 to = link.x == kEdgeGlued
                               ? tables
                                     .edges[static_cast<size_t>(
                                         tables.polygons[static_cast<size_t>(link.y)].x + link.z)]
                                     .line
                               : glm::vec4(0.0f);
      const std::array<float, kGlueFields> glue{edge.map_shift.x,
                                                edge.map_shift.y,
                                                edge.map_linear.x,
                                                edge.map_linear.y,
                                                edge.map_linear.z,
                                                edge.map_linear.w,
                                                to.x,
                                                to.y,
                                                to.z};
      for (size_t f = 0; f < kGlueFields; ++f) glue_[f][e] = glue[f];
      to_polygon_[e] = link.x == kEdgeGlued ? link.y : 0;
      if (link.x == kEdgeGlued && edge.map_linear != glm::vec4(1.0f, 0.0f, 0.0f, 1.0f))
        translations_ = false;
    }
  }

  // A packet with no rays: every lane done.
  static void clear(Packet& r, Relaxation& x, Segment& seg) {
    r.polygon = r.steps = r.crossings = r.hit = SplatI(0);
    r.ox = r.oy = r.oz = r.dx = r.dy = r.dz = r.t = Splat(0.0f);
    r.nx = r.ny = r.nz = r.sr = r.sg = r.sb = Splat(0.0f);
    r.done = hn::Not(None());
    x.omega = x.last_radius = x.last_step = Splat(0.0f);
    seg.known = seg.exit.corner = None();
    seg.exit.s = seg.solids = Splat(0.0f);
    seg.exit.edge = SplatI(-1);
  }

  // The start of march.glsl's march(): the lanes of `m` begin a ray from (fx, fy, fz) in
  // `polygon` along (dx, dy, dz). The other lanes are left as they are.
  FLATMARCH_PACKET_INLINE void start(Packet& r, Relaxation& x, Segment& seg, M m, int polygon, V fx,
                                     V fy, V fz, V dx, V dy, V dz) const {
    r.polygon = Select(m, SplatI(polygon), r.polygon);
    r.ox = Select(m, fx, r.ox);
    r.oy = Select(m, fy, r.oy);
    r.oz = Select(m, fz, r.oz);
    const V inv = Splat(1.0f) / hn::Sqrt(dx * dx + dy * dy + dz * dz);  // normalize
    r.dx = Select(m, dx * inv, r.dx);
    r.dy = Select(m, dy * inv, r.dy);
    r.dz = Select(m, dz * inv, r.dz);
    r.t = hn::IfThenZeroElse(m, r.t);
    r.steps = Select(m, SplatI(0), r.steps);
    r.crossings = Select(m, SplatI(0), r.crossings);
    r.hit = Select(m, SplatI(kHitMaxSteps), r.hit);
    r.done = hn::AndNot(m, r.done);
    // The normal and surface colour are left: only a ray that hits a solid reads them, and the
    // hit sets them.
    if (has(kFeaturePeriod)) {
      const V top = Splat(params_.top);
      r.oz = Select(m, r.oz - top * hn::Floor(r.oz / top), r.oz);  // mod
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
  // of the rays that have taken max_steps. A step runs in passes of up to kRoomsPerPass rooms
  // (usually one pass); the rays a pass moves to another room are already out of `pending`.
  FLATMARCH_PACKET_INLINE void step(Packet& r, Relaxation& x, Segment& seg,
                                    LaneCounts& lanes) const {
    const M active = hn::Not(r.done);
    r.steps = Select(active, r.steps + SplatI(1), r.steps);
    std::array<int32_t, hn::MaxLanes(DI())> lane_rooms{};
    hn::StoreU(r.polygon, DI(), lane_rooms.data());
    M pending = active;
    while (Any(pending)) {
      Rooms rooms;
      M pass = None();
      rooms.first_edge = rooms.edge_count = SplatI(0);
      const int most_rooms = merge_ ? kRoomsPerPass : 1;
      for (M left = pending; Any(left) && rooms.count < most_rooms; ++rooms.count) {
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
      lanes.active += static_cast<int64_t>(hn::CountTrue(D(), pass));
      lanes.slots += static_cast<int64_t>(hn::Lanes(D()));
      const bool analytic = params_.method == kMethodAnalytic;
      if (rooms.count == 1 && analytic)
        analytic_step<true>(r, seg, pass, rooms);
      else if (rooms.count == 1)
        sphere_step<true>(r, x, pass, rooms);
      else if (analytic)
        analytic_step<false>(r, seg, pass, rooms);
      else
        sphere_step<false>(r, x, pass, rooms);
      pending = hn::AndNot(pass, pending);
    }
    const M out = hn::AndNot(r.done, hn::RebindMask(D(), r.steps == SplatI(params_.max_steps)));
    finish(r, out, SplatI(kHitMaxSteps), kEventMaxSteps, SplatI(-1), Splat(0.0f));
  }

  // march.glsl's shade(): the linear colour of finished rays. transmittance[c] is
  // (1 - wall_tint)^c as shade computes it, for the first crossing counts.
  FLATMARCH_PACKET_INLINE void shade(const Packet& r, const std::vector<float>& transmittance,
                                     V& red, V& green, V& blue) const {
    V cr = Splat(params_.background.x), cg = Splat(params_.background.y);
    V cb = Splat(params_.background.z);
    const M object = AtLeastZero(r.hit);
    cr = Select(object, r.sr, cr);
    cg = Select(object, r.sg, cg);
    cb = Select(object, r.sb, cb);
    const M wall = Equal(r.hit, kHitWall);
    const V grey = Splat(kWallGrey);
    cr = Select(wall, grey, cr);
    cg = Select(wall, grey, cg);
    cb = Select(wall, grey, cb);
    const M floor = Equal(r.hit, kHitFloor);
    if (Any(floor)) {
      const V check = hn::Floor(r.ox / Splat(kFloorCheck)) + hn::Floor(r.oy / Splat(kFloorCheck));
      const V two = Splat(2.0f);
      const V parity = check - two * hn::Floor(check / two);  // mod
      const V tone = Select(parity >= Splat(1.0f), Splat(kFloorDarkGrey), grey);
      cr = Select(floor, tone, cr);
      cg = Select(floor, tone, cg);
      cb = Select(floor, tone, cb);
    }
    const M black = hn::Or(Equal(r.hit, kHitMaxSteps), Equal(r.hit, kHitVertex));
    cr = hn::IfThenZeroElse(black, cr);
    cg = hn::IfThenZeroElse(black, cg);
    cb = hn::IfThenZeroElse(black, cb);
    const int last = static_cast<int>(transmittance.size()) - 1;
    V tr = hn::GatherIndex(D(), transmittance.data(), hn::Min(r.crossings, SplatI(last)));
    if (!hn::AllFalse(DI(), r.crossings > SplatI(last))) {  // beyond the table
      std::array<int32_t, hn::MaxLanes(DI())> crossings{};
      std::array<float, hn::MaxLanes(D())> factor{};
      hn::StoreU(r.crossings, DI(), crossings.data());
      hn::StoreU(tr, D(), factor.data());
      for (size_t l = 0; l < hn::Lanes(D()); ++l)
        if (crossings[l] > last)
          factor[l] = glm::pow(1.0f - params_.wall_tint, static_cast<float>(crossings[l]));
      tr = hn::LoadU(D(), factor.data());
    }
    const V fog = Splat(1.0f) - tr;
    red = tr * cr + fog * Splat(params_.fog.x);
    green = tr * cg + fog * Splat(params_.fog.y);
    blue = tr * cb + fog * Splat(params_.fog.z);
  }

 private:
  bool has(uint feature) const { return (features_ & feature) != 0u; }

  // Records an event of lane 0 (the one a trace follows) when it is in `m`.
  FLATMARCH_PACKET_INLINE void record(M m, int kind, VI polygon, VI edge, int to_polygon,
                                      int to_edge, VI hit, const Packet& r) const {
    if (!events_ || static_cast<int>(events_->size()) >= max_events_ ||
        hn::AllFalse(D(), hn::And(m, hn::FirstN(D(), 1))))
      return;
    const int h = hn::GetLane(hit);
    events_->push_back({kind, hn::GetLane(polygon), hn::GetLane(edge), to_polygon, to_edge,
                        h >= 0 ? h : -1, static_cast<double>(hn::GetLane(r.t)),
                        glm::dvec3(hn::GetLane(r.ox), hn::GetLane(r.oy), hn::GetLane(r.oz))});
  }

  static FLATMARCH_PACKET_INLINE void advance(Packet& r, M m, V s) {
    r.ox = Select(m, r.ox + s * r.dx, r.ox);
    r.oy = Select(m, r.oy + s * r.dy, r.oy);
    r.oz = Select(m, r.oz + s * r.dz, r.oz);
    r.t = Select(m, r.t + s, r.t);
  }

  // Ends the rays of `m` `s` further on.
  FLATMARCH_PACKET_INLINE void finish(Packet& r, M m, VI hit, int event, VI edge, V s) const {
    if (!Any(m)) return;
    advance(r, m, s);
    r.hit = Select(m, hit, r.hit);
    r.done = hn::Or(r.done, m);
    record(m, event, r.polygon, edge, -1, -1, hit, r);
  }

  // ---- Walls ---------------------------------------------------------------------------------

  // Edge k of each lane's room: its index in the edge table (0 where the room has fewer
  // edges), and the lanes whose room has one.
  struct Slot {
    int edge;  // in one room
    VI edges;  // in several
    M valid;
  };
  template <bool kOneRoom>
  FLATMARCH_PACKET_INLINE Slot slot(const Rooms& rooms, int k) const {
    Slot at;
    if constexpr (kOneRoom) {
      at.edge = polygons_[rooms.polygon[0]].x + k;
      at.valid = rooms.lanes[0];
    } else {
      at.edge = 0;
      at.valid = hn::And(rooms.all, hn::RebindMask(D(), SplatI(k) < rooms.edge_count));
      at.edges = Select(at.valid, rooms.first_edge + SplatI(k), SplatI(0));
    }
    return at;
  }

  // Number `f` of each lane's edge in `at`: in one room a broadcast, in several a lookup in
  // the scene's edge numbers held in vectors (lookup_).
  template <bool kOneRoom>
  FLATMARCH_PACKET_INLINE V field(const Slot& at, Field f) const {
    if constexpr (kOneRoom) return Splat(edge_number(f, edges_[at.edge], extra_[at.edge]));
    return hn::TableLookupLanes(hn::LoadU(D(), lookup_[f].data()),
                                hn::IndicesFromVec(D(), at.edges));
  }

  // Whether the horizontal ray from p in +x crosses the edge from a to a + ab; ap = p - a,
  // ay_aby = a.y + ab.y.
  static FLATMARCH_PACKET_INLINE M crosses(V ay, V ay_aby, V abx, V aby, V py, V apx, V apy) {
    const M over_a = py >= ay;
    const M under_b = py < ay_aby;
    const M left = abx * apy > aby * apx;
    return hn::Or(hn::And(hn::And(over_a, under_b), left),
                  hn::Not(hn::Or(hn::Or(over_a, under_b), left)));
  }

  FLATMARCH_PACKET_INLINE M inside_polygon(int polygon, V px, V py) const {
    const ivec4 poly = polygons_[polygon];
    M inside = None();
    for (int k = poly.x; k < poly.x + poly.y; ++k) {
      const glm::vec4 s = edges_[k].segment;
      const glm::vec4 x = extra_[k];
      const V apx = px - Splat(s.x), apy = py - Splat(s.y);
      inside =
          hn::Xor(inside, crosses(Splat(s.y), Splat(x.w), Splat(x.x), Splat(x.y), py, apx, apy));
    }
    return inside;
  }

  template <bool kOneRoom>
  FLATMARCH_PACKET_INLINE WallDistance wall_distance(const Rooms& rooms, V px, V py) const {
    V best = Splat(kFar), second = Splat(kFar);
    VI edge = SplatI(-1);
    M inside = None();
    for (int k = 0; k < rooms.most_edges; ++k) {
      const Slot at = slot<kOneRoom>(rooms, k);
      const M valid = at.valid;
      const V ax = field<kOneRoom>(at, kAx);
      const V ay = field<kOneRoom>(at, kAy);
      const V abx = field<kOneRoom>(at, kAbx);
      const V aby = field<kOneRoom>(at, kAby);
      const V w = field<kOneRoom>(at, kInvLength2);
      const V ay_aby = field<kOneRoom>(at, kAyAby);
      const V apx = px - ax, apy = py - ay;
      const V h = hn::Min(hn::Max((apx * abx + apy * aby) * w, Splat(0.0f)), Splat(1.0f));
      const V qx = apx - h * abx, qy = apy - h * aby;
      const V d2 = qx * qx + qy * qy;
      const M nearest = hn::And(valid, d2 < best);
      second = Select(nearest, best, Select(hn::And(valid, d2 < second), d2, second));
      best = Select(nearest, d2, best);
      edge = Select(nearest, SplatI(k), edge);
      inside = hn::Xor(inside, hn::And(valid, crosses(ay, ay_aby, abx, aby, py, apx, apy)));
    }
    WallDistance w;
    const V root = hn::Sqrt(best);
    w.d = Select(inside, root, hn::Neg(root));
    w.edge = edge;
    w.second = hn::Sqrt(second);
    return w;
  }

  // For the rays of `m`; an edge none of them moves towards is skipped.
  template <bool kOneRoom>
  FLATMARCH_PACKET_INLINE Exit exit_edge(M m, const Rooms& rooms, V ox, V oy, V dhx, V dhy) const {
    Exit x;
    x.s = Splat(kFar);
    x.edge = SplatI(-1);
    V u_exit = Splat(0.5f), tolerance_exit = Splat(0.0f);  // of the exit edge found so far
    const V vertex_tolerance = Splat(params_.vertex_tolerance);
    for (int k = 0; k < rooms.most_edges; ++k) {
      const Slot at = slot<kOneRoom>(rooms, k);
      const V nx = field<kOneRoom>(at, kNx);
      const V ny = field<kOneRoom>(at, kNy);
      const V dn = dhx * nx + dhy * ny;
      const M towards = hn::And(hn::And(m, at.valid), dn > Splat(0.0f));
      if (!Any(towards)) continue;
      const V nz = field<kOneRoom>(at, kNa);
      const V s = (nz - (ox * nx + oy * ny)) / dn;
      M ok = hn::AndNot(hn::Or(s < hn::Neg(vertex_tolerance), s >= x.s), towards);
      if (!Any(ok)) continue;  // no ray meets this edge's line before its exit so far
      const V ax = field<kOneRoom>(at, kAx);
      const V ay = field<kOneRoom>(at, kAy);
      const V abx = field<kOneRoom>(at, kAbx);
      const V aby = field<kOneRoom>(at, kAby);
      const V w = field<kOneRoom>(at, kInvLength2);
      const V u = (((ox + s * dhx) - ax) * abx + ((oy + s * dhy) - ay) * aby) * w;
      const V tolerance = field<kOneRoom>(at, kTolerance);
      ok =
          hn::AndNot(hn::Or(hn::Lt(u, hn::Neg(tolerance)), hn::Gt(u, Splat(1.0f) + tolerance)), ok);
      x.s = Select(ok, hn::Max(s, Splat(0.0f)), x.s);
      x.edge = Select(ok, SplatI(k), x.edge);
      u_exit = Select(ok, u, u_exit);
      tolerance_exit = Select(ok, tolerance, tolerance_exit);
    }
    x.corner = hn::Or(u_exit <= tolerance_exit, u_exit >= Splat(1.0f) - tolerance_exit);
    return x;
  }

  FLATMARCH_PACKET_INLINE V band_exit(V oz, V dz) const {
    const M up = dz > Splat(0.0f);
    const V s = Select(up, Splat(params_.top) - oz, hn::Neg(oz)) / dz;  // one division for both
    return Select(up, s, Select(dz < Splat(0.0f), s, Splat(kFar)));
  }

  // Moves p along the normal of an edge's line so that it lies `inside` within it.
  static FLATMARCH_PACKET_INLINE void place(V& px, V& py, const glm::vec4& line, V inside) {
    const V nx = Splat(line.x), ny = Splat(line.y);
    const V k = ((px * nx + py * ny) - Splat(line.z)) + inside;
    px = px - k * nx;
    py = py - k * ny;
  }

  // The rays of `m` at their edge `edge` (of their room) go through it or are reflected, and are
  // placed `push` inside the edge they are then behind. One broadcast record per edge.
  FLATMARCH_PACKET_INLINE void cross_edge(Packet& r, M m, VI edge, V push) const {
    if (merge_ && !has(kFeatureMirrors)) {
      cross_glued(r, m, edge, push);
      return;
    }
    std::array<int32_t, hn::MaxLanes(DI())> lane_edges{}, lane_rooms{};
    hn::StoreU(edge, DI(), lane_edges.data());
    hn::StoreU(r.polygon, DI(), lane_rooms.data());
    // One round per edge the rays cross (usually one or two), not per edge of their rooms.
    for (M left = m; Any(left);) {
      const size_t first = static_cast<size_t>(hn::FindFirstTrue(D(), left));
      const int k = lane_edges[first], polygon = lane_rooms[first];
      const M mk = hn::And(left, hn::And(Equal(edge, k), Equal(r.polygon, polygon)));
      left = hn::AndNot(mk, left);
      const EdgeRecord& e = edges_[polygons_[polygon].x + k];
      V px = r.ox, py = r.oy;
      V hx = r.dx, hy = r.dy, hz = r.dz;
      if (has(kFeatureMirrors) && e.link.x == kEdgeMirror) {
        record(mk, kEventMirror, r.polygon, SplatI(k), -1, -1, SplatI(-1), r);
        const V nx = Splat(e.line.x), ny = Splat(e.line.y);
        place(px, py, e.line, push);
        const V twice = Splat(2.0f) * (hx * nx + hy * ny);
        hx = hx - twice * nx;
        hy = hy - twice * ny;
      } else {
        const ivec4 link = e.link;
        record(mk, kEventGluing, r.polygon, SplatI(k), link.y, link.z, SplatI(-1), r);
        const glm::vec4 a = e.map_linear;
        if (a == glm::vec4(1.0f, 0.0f, 0.0f, 1.0f)) {  // a translation: what the map gives
          px = r.ox + Splat(e.map_shift.x);
          py = r.oy + Splat(e.map_shift.y);
        } else {
          const V mx = Splat(a.x), my = Splat(a.y), mz = Splat(a.z), mw = Splat(a.w);
          px = (mx * r.ox + mz * r.oy) + Splat(e.map_shift.x);
          py = (my * r.ox + mw * r.oy) + Splat(e.map_shift.y);
          hx = mx * r.dx + mz * r.dy;
          hy = my * r.dx + mw * r.dy;
        }
        place(px, py, edges_[polygons_[link.y].x + link.z].line, push);
        if (has(kFeatureScaled)) {  // normalize
          const V inv = Splat(1.0f) / hn::Sqrt(hx * hx + hy * hy + hz * hz);
          hx = hx * inv;
          hy = hy * inv;
          hz = hz * inv;
        }
        r.polygon = Select(mk, SplatI(link.y), r.polygon);
      }
      r.ox = Select(mk, px, r.ox);
      r.oy = Select(mk, py, r.oy);
      r.dx = Select(mk, hx, r.dx);
      r.dy = Select(mk, hy, r.dy);
      r.dz = Select(mk, hz, r.dz);
    }
    r.crossings = Select(m, r.crossings + SplatI(1), r.crossings);
  }

  // cross_edge when every edge the rays cross is glued and the scene's edges fit in a vector:
  // each lane looks its edge's gluing up (glue_), all in one round.
  FLATMARCH_PACKET_INLINE void cross_glued(Packet& r, M m, VI edge, V push) const {
    const DI di;
    if (events_ && !hn::AllFalse(D(), hn::And(m, hn::FirstN(D(), 1)))) {
      const ivec4 link = edges_[polygons_[hn::GetLane(r.polygon)].x + hn::GetLane(edge)].link;
      record(m, kEventGluing, r.polygon, edge, link.y, link.z, SplatI(-1), r);
    }
    const VI first = hn::TableLookupLanes(hn::LoadU(di, first_edge_.data()),
                                          hn::IndicesFromVec(di, Select(m, r.polygon, SplatI(0))));
    const auto at = hn::IndicesFromVec(D(), Select(m, first + edge, SplatI(0)));
    const auto glue = [&](size_t f) HWY_ATTR {
      return hn::TableLookupLanes(hn::LoadU(D(), glue_[f].data()), at);
    };
    V px, py, hx = r.dx, hy = r.dy, hz = r.dz;
    if (translations_) {
      px = r.ox + glue(0);
      py = r.oy + glue(1);
    } else {
      const V mx = glue(2), my = glue(3), mz = glue(4), mw = glue(5);
      px = (mx * r.ox + mz * r.oy) + glue(0);
      py = (my * r.ox + mw * r.oy) + glue(1);
      hx = mx * r.dx + mz * r.dy;
      hy = my * r.dx + mw * r.dy;
    }
    const V nx = glue(6), ny = glue(7);
    const V k = ((px * nx + py * ny) - glue(8)) + push;  // place
    px = px - k * nx;
    py = py - k * ny;
    if (has(kFeatureScaled)) {  // normalize
      const V inv = Splat(1.0f) / hn::Sqrt(hx * hx + hy * hy + hz * hz);
      hx = hx * inv;
      hy = hy * inv;
      hz = hz * inv;
    }
    const VI to = hn::TableLookupLanes(hn::LoadU(di, to_polygon_.data()),
                                       hn::IndicesFromVec(di, Select(m, first + edge, SplatI(0))));
    r.polygon = Select(m, to, r.polygon);
    r.ox = Select(m, px, r.ox);
    r.oy = Select(m, py, r.oy);
    r.dx = Select(m, hx, r.dx);
    r.dy = Select(m, hy, r.dy);
    r.dz = Select(m, hz, r.dz);
    r.crossings = Select(m, r.crossings + SplatI(1), r.crossings);
  }

  // Which lanes' `edge` of their room is an opaque wall.
  FLATMARCH_PACKET_INLINE M is_wall(const Rooms& rooms, VI edge) const {
    M wall = None();
    if (!has(kFeatureWalls)) return wall;
    for (size_t i = 0; i < static_cast<size_t>(rooms.count); ++i) {
      const ivec4 poly = polygons_[rooms.polygon[i]];
      for (int k = 0; k < poly.y; ++k)
        if (edges_[poly.x + k].link.x == kEdgeWall)
          wall = hn::Or(wall, hn::And(rooms.lanes[i], Equal(edge, k)));
    }
    return wall;
  }

  // The rays of `m` reach the top or bottom of the band, `s` further on.
  FLATMARCH_PACKET_INLINE void leave_band(Packet& r, M m, V s) const {
    if (has(kFeaturePeriod)) {
      advance(r, m, s);
      r.oz = Select(m, Select(r.dz > Splat(0.0f), Splat(0.0f), Splat(params_.top)), r.oz);
    } else if (has(kFeatureFloor)) {
      const M down = hn::And(m, r.dz < Splat(0.0f));
      finish(r, down, SplatI(kHitFloor), kEventFloor, SplatI(-1), s);
      r.nz = Select(down, Splat(1.0f), r.nz);
      finish(r, hn::AndNot(down, m), SplatI(kHitEscape), kEventEscape, SplatI(-1), s);
    } else {
      finish(r, m, SplatI(kHitEscape), kEventEscape, SplatI(-1), s);
    }
  }

  // ---- Solids --------------------------------------------------------------------------------

  FLATMARCH_PACKET_INLINE V solid_distance(int k, V px, V py, V pz) const {
    const ObjectRecord& o = objects_[k];
    const V qx = px - Splat(o.center.x), qy = py - Splat(o.center.y);
    const V qz = pz - Splat(o.center.z);
    const int solid = o.info.x;
    if (solid == kSolidSphere) return hn::Sqrt(qx * qx + qy * qy + qz * qz) - Splat(o.shape.x);
    const V zero = Splat(0.0f);
    if (solid == kSolidCylinder) {
      const V wx = hn::Sqrt(qx * qx + qy * qy) - Splat(o.shape.x);
      const V wy = hn::Abs(qz) - Splat(o.shape.y);
      const V mx = hn::Max(wx, zero), my = hn::Max(wy, zero);
      return hn::Min(hn::Max(wx, wy), zero) + hn::Sqrt(mx * mx + my * my);
    }
    const V wx = hn::Abs(qx) - Splat(o.shape.x), wy = hn::Abs(qy) - Splat(o.shape.y);
    const V wz = hn::Abs(qz) - Splat(o.shape.z);
    const V mx = hn::Max(wx, zero), my = hn::Max(wy, zero), mz = hn::Max(wz, zero);
    const V box =
        hn::Sqrt(mx * mx + my * my + mz * mz) + hn::Min(hn::Max(wx, hn::Max(wy, wz)), zero);
    if (solid == kSolidBox) return box;
    return hn::Max(box, Splat(o.shape.w) - hn::Sqrt(qx * qx + qy * qy + qz * qz));
  }

  FLATMARCH_PACKET_INLINE SolidDistance nearest_solid(const Rooms& rooms, V px, V py, V pz) const {
    SolidDistance best;
    best.d = Splat(kFar);
    best.object = SplatI(-1);
    if (!has(kFeatureObjects)) return best;
    for (size_t i = 0; i < static_cast<size_t>(rooms.count); ++i) {
      const ivec4 poly = polygons_[rooms.polygon[i]];
      for (int k = poly.z; k < poly.z + poly.w; ++k) {
        const V dk = solid_distance(k, px, py, pz);
        const M nearer = hn::And(rooms.lanes[i], dk < best.d);
        best.d = Select(nearer, dk, best.d);
        best.object = Select(nearer, SplatI(k), best.object);
      }
    }
    return best;
  }

  // Where a ray first comes within eps of a solid's bounding sphere in its room, or kFar.
  FLATMARCH_PACKET_INLINE V solid_entry(const Rooms& rooms, const Packet& r) const {
    V first = Splat(kFar);
    M inside = None();
    for (size_t i = 0; i < static_cast<size_t>(rooms.count); ++i) {
      const ivec4 poly = polygons_[rooms.polygon[i]];
      for (int k = poly.z; k < poly.z + poly.w; ++k) {
        const glm::vec4 c = objects_[k].center;
        const V ocx = r.ox - Splat(c.x), ocy = r.oy - Splat(c.y), ocz = r.oz - Splat(c.z);
        const float radius = c.w + params_.eps;
        const V b = ocx * r.dx + ocy * r.dy + ocz * r.dz;
        const V cc = (ocx * ocx + ocy * ocy + ocz * ocz) - Splat(radius * radius);
        inside = hn::Or(inside, hn::And(rooms.lanes[i], cc <= Splat(0.0f)));
        const V disc = b * b - cc;
        const M ahead = hn::And(rooms.lanes[i], hn::And(b < Splat(0.0f), disc >= Splat(0.0f)));
        first = Select(ahead, hn::Min(first, hn::Neg(b) - hn::Sqrt(disc)), first);
      }
    }
    return hn::IfThenZeroElse(inside, first);
  }

  // The gradient of solid k's distance at p by central differences on a tetrahedron.
  FLATMARCH_PACKET_INLINE void solid_normal(int k, V px, V py, V pz, V& nx, V& ny, V& nz) const {
    const V h = Splat(params_.normal_step);
    const V s1 = solid_distance(k, px + h, py - h, pz - h);  // (1, -1, -1)
    const V s2 = solid_distance(k, px - h, py - h, pz + h);  // (-1, -1, 1)
    const V s3 = solid_distance(k, px - h, py + h, pz - h);  // (-1, 1, -1)
    const V s4 = solid_distance(k, px + h, py + h, pz + h);  // (1, 1, 1)
    const V gx = ((s1 - s2) - s3) + s4;
    const V gy = ((hn::Neg(s1) - s2) + s3) + s4;
    const V gz = ((hn::Neg(s1) + s2) - s3) + s4;
    const V inv = Splat(1.0f) / hn::Sqrt(gx * gx + gy * gy + gz * gz);
    nx = gx * inv;
    ny = gy * inv;
    nz = gz * inv;
  }

  // The rays of `m` hit their `object` (an index in the object table) where they are.
  FLATMARCH_PACKET_INLINE void hit_solid(Packet& r, M m, VI object) const {
    std::array<int32_t, hn::MaxLanes(DI())> lane_objects{};
    hn::StoreU(object, DI(), lane_objects.data());
    for (M left = m; Any(left);) {
      const int k = lane_objects[static_cast<size_t>(hn::FindFirstTrue(D(), left))];
      const M mk = hn::And(left, Equal(object, k));
      left = hn::AndNot(mk, left);
      V nx, ny, nz;
      solid_normal(k, r.ox, r.oy, r.oz, nx, ny, nz);
      r.nx = Select(mk, nx, r.nx);
      r.ny = Select(mk, ny, r.ny);
      r.nz = Select(mk, nz, r.nz);
      const glm::vec4 c = objects_[k].color;
      const V half = Splat(0.5f);
      r.sr = Select(mk, c.w > 0.0f ? Splat(c.x) : half + half * nx, r.sr);
      r.sg = Select(mk, c.w > 0.0f ? Splat(c.y) : half + half * ny, r.sg);
      r.sb = Select(mk, c.w > 0.0f ? Splat(c.z) : half + half * nz, r.sb);
      finish(r, mk, SplatI(objects_[k].info.y), kEventObject, SplatI(-1), Splat(0.0f));
    }
  }

  // ---- Methods -------------------------------------------------------------------------------

  FLATMARCH_PACKET_INLINE void relax(Relaxation& x, M m) const {
    const V omega = Splat(params_.method == kMethodRelaxed ? params_.omega : 1.0f);
    x.omega = Select(m, omega, x.omega);
    x.last_radius = hn::IfThenZeroElse(m, x.last_radius);
    x.last_step = hn::IfThenZeroElse(m, x.last_step);
  }

  // One iteration of sphere or over-relaxed sphere tracing for the rays of `m`, in `rooms`.
  template <bool kOneRoom>
  FLATMARCH_PACKET_INLINE void sphere_step(Packet& r, Relaxation& x, M m,
                                           const Rooms& rooms) const {
    const WallDistance wall = wall_distance<kOneRoom>(rooms, r.ox, r.oy);
    const SolidDistance solid = nearest_solid(rooms, r.ox, r.oy, r.oz);
    const V radius = hn::Min(wall.d, solid.d);
    // Over-relaxed steps whose unbounding spheres do not overlap are taken back.
    const M back = hn::And(hn::And(m, x.omega > Splat(1.0f)), radius + x.last_radius < x.last_step);
    M rest = hn::AndNot(back, m);
    if (Any(back)) {
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
      const M corner = hn::And(near, wall.second < eps);
      finish(r, corner, SplatI(kHitVertex), kEventVertex, SplatI(-1), Splat(0.0f));
      const M walls = hn::AndNot(corner, hn::And(near, is_wall(rooms, wall.edge)));
      finish(r, walls, SplatI(kHitWall), kEventWall, wall.edge, Splat(0.0f));
      const M cross = hn::AndNot(hn::Or(corner, walls), near);
      if (Any(cross)) {
        cross_edge(r, cross, wall.edge, Splat(params_.offset));
        relax(x, cross);
      }
      rest = hn::AndNot(near, rest);
    }
    const V safe = hn::Abs(radius);
    const V band = band_exit(r.oz, r.dz);
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

  // One iteration of the analytic method for the rays of `m`, in `rooms`.
  template <bool kOneRoom>
  FLATMARCH_PACKET_INLINE void analytic_step(Packet& r, Segment& seg, M m,
                                             const Rooms& rooms) const {
    const M unknown = hn::AndNot(seg.known, m);
    if (Any(unknown)) {
      const Exit x = exit_edge<kOneRoom>(unknown, rooms, r.ox, r.oy, r.dx, r.dy);
      seg.exit.s = Select(unknown, x.s, seg.exit.s);
      seg.exit.edge = Select(unknown, x.edge, seg.exit.edge);
      seg.exit.corner = Select(unknown, x.corner, seg.exit.corner);
      if (has(kFeatureObjects))
        seg.solids = Select(unknown, solid_entry(rooms, r), seg.solids);
      else
        seg.solids = Select(unknown, Splat(kFar), seg.solids);
      seg.known = hn::Or(seg.known, unknown);
    }
    const V max_distance = Splat(params_.max_distance);
    V remaining = max_distance - r.t;
    V band = band_exit(r.oz, r.dz);  // recomputed below for the rays that move
    M rest = m;
    if (has(kFeatureObjects)) {
      const M solids = hn::And(m, seg.solids < hn::Min(hn::Min(seg.exit.s, band), remaining));
      if (Any(solids)) {
        move_in_segment(r, seg, solids, seg.solids);
        band = Select(solids, band_exit(r.oz, r.dz), band);
        const SolidDistance solid = nearest_solid(rooms, r.ox, r.oy, r.oz);
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
    const M wall = hn::And(rest, is_wall(rooms, seg.exit.edge));
    finish(r, wall, SplatI(kHitWall), kEventWall, seg.exit.edge, seg.exit.s);
    rest = hn::AndNot(wall, rest);
    if (Any(rest)) {
      advance(r, rest, seg.exit.s);
      cross_edge(r, rest, seg.exit.edge, Splat(0.0f));
      seg.known = hn::AndNot(rest, seg.known);
    }
  }

  // ---- A whole ray ---------------------------------------------------------------------------

  // The rays of `m`, outside the band, enter the first polygon whose footprint they cross.
  FLATMARCH_PACKET_INLINE void enter_band(Packet& r, M m) const {
    if (!Any(m)) return;
    const V height = Splat(params_.height), max_distance = Splat(params_.max_distance);
    const M above = r.oz > height;
    const M toward = Select(above, r.dz<Splat(0.0f), r.dz> Splat(0.0f));
    V s = Select(toward, (hn::IfThenElseZero(above, height) - r.oz) / r.dz, max_distance);
    s = Select(s > max_distance, max_distance, s);
    const V qx = r.ox + s * r.dx, qy = r.oy + s * r.dy;
    M open = hn::And(m, s < max_distance);
    for (int k = 0; k < params_.polygon_count && Any(open); ++k) {
      const M in = hn::And(open, inside_polygon(k, qx, qy));
      if (!Any(in)) continue;
      r.polygon = Select(in, SplatI(k), r.polygon);
      M enter = in;
      if (has(kFeatureFloor)) {  // the underside of the floor
        const M under = hn::AndNot(above, in);
        finish(r, under, SplatI(kHitFloor), kEventFloor, SplatI(-1), s);
        r.nz = Select(under, Splat(-1.0f), r.nz);
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

  const ivec4* polygons_;
  const EdgeRecord* edges_;
  const glm::vec4* extra_;  // per edge: b - a (x, y), vertex tolerance in u (z), a.y + (b - a).y
  bool merge_ = false;      // whether a pass may span several rooms
  std::array<std::array<float, hn::MaxLanes(D())>, kFields> lookup_{};  // [field][edge]
  // Of each edge: its gluing map's shift (2) and linear part (4), the destination edge's line
  // (3); the destination polygon; and whether every gluing is a translation.
  static constexpr size_t kGlueFields = 9;
  std::array<std::array<float, hn::MaxLanes(D())>, kGlueFields> glue_{};
  std::array<int32_t, hn::MaxLanes(DI())> to_polygon_{}, first_edge_{};
  bool translations_ = true;
  const ObjectRecord* objects_;
  KernelParams params_;
  uint features_;
  std::vector<kernel::KernelEvent>* events_;
  int max_events_;
};

// Number of lanes of this target's vectors: the packet size.
int PacketLanes() {
  return static_cast<int>(hn::Lanes(D()));
}

// camera_ray for each lane's pixel (i, j): through the pixel's centre, normalised.
HWY_INLINE void CameraRays(const PacketJob& job, const int32_t* i, const int32_t* j, V& dx, V& dy,
                           V& dz) {
  const DI di;
  const CameraBasis<float>& c = job.basis;
  const V px = hn::ConvertTo(D(), hn::LoadU(di, i)) + Splat(0.5f);
  const V py = hn::ConvertTo(D(), hn::LoadU(di, j)) + Splat(0.5f);
  const V u =
      ((Splat(2.0f) * px / Splat(static_cast<float>(job.width)) - Splat(1.0f)) * Splat(c.aspect)) *
      Splat(c.tan_half_fov);
  const V v = (Splat(1.0f) - Splat(2.0f) * py / Splat(static_cast<float>(job.height))) *
              Splat(c.tan_half_fov);
  dx = (Splat(c.forward.x) + u * Splat(c.right.x)) + v * Splat(c.up.x);
  dy = (Splat(c.forward.y) + u * Splat(c.right.y)) + v * Splat(c.up.y);
  dz = (Splat(c.forward.z) + u * Splat(c.right.z)) + v * Splat(c.up.z);
  const V inv = Splat(1.0f) / hn::Sqrt(dx * dx + dy * dy + dz * dz);
  dx = dx * inv;
  dy = dy * inv;
  dz = dz * inv;
}

// Lanes wait for a new pixel until this many eighths of them do: refilling costs a shading and a
// camera ray for the whole packet, and waiting lanes idle. Measured on 8 lanes, 640x360, 2 cores,
// one run (ms at 2/8 -> 4/8): the analytic method's short rays refill often and gain (cube
// 24.9 -> 20.4, double pentagon 13.8 -> 11.4, L-shape 8.9 -> 8.4); so does sphere tracing in the
// cube (228 -> 183: rays refilled together start together in the camera's room, and stay in
// fewer rooms a packet), while on the L-shape and the torus it is level (86.7 -> 87.8, 52.1 ->
// 52.1; a recheck in three interleaved rounds: the L-shape up to 5% slower, within this machine's
// noise); 5/8 loses 18% on the L-shape's sphere tracing, 1/8 spends more on refills than it gains.
constexpr size_t kRefillAt = 4;

// Marches the pixels of the tiles in rows [row0, row1) and columns [col0, col1) of the frame's
// grid of tiles and writes them. The lanes of one packet take the chunk's pixels tile by tile,
// and a lane whose ray has ended takes a next pixel soon (kRefillAt), so that a few long rays do
// not hold up the rest of their tile (lanes stay busy until the chunk's pixels run out).
void MarchPackets(const PacketJob& job, int row0, int row1, int col0, int col1, LaneCounts* lanes) {
  const TileShape tile = tile_shape(PacketLanes());
  const Marcher marcher(*job.tables, job.edge_extra, nullptr, 0);
  const DI di;
  constexpr size_t kMax = hn::MaxLanes(DI());
  const size_t n = hn::Lanes(D());
  std::array<float, kMax> red{}, green{}, blue{}, t{};
  std::array<int32_t, kMax> steps{}, crossings{}, hit{}, fresh{};
  std::array<int32_t, kMax> pixel_i{}, pixel_j{};
  pixel_i.fill(-1);  // -1: the lane holds no pixel
  const V from_x = Splat(job.from.x), from_y = Splat(job.from.y), from_z = Splat(job.from.z);

  // The chunk's pixels in queue order: tile by tile, row-major; lane order within a tile.
  const int tiles_across = col1 - col0;
  const int64_t queue = int64_t{row1 - row0} * tiles_across * tile.width * tile.height;
  int64_t next = 0;
  Packet r;
  Relaxation x;
  Segment seg;
  Marcher::clear(r, x, seg);
  // Every iteration steps at least one ray, and a ray takes at most max_steps steps.
  const int64_t bound = queue * (int64_t{job.tables->params.max_steps} + 1) + 1;
  M occupied = None();  // lanes holding a pixel
  for (int64_t iteration = 0; iteration < bound; ++iteration) {
    // Lanes are refilled once enough of them wait, or when none is left marching.
    const M waiting = next < queue ? r.done : hn::And(r.done, occupied);
    const size_t count = hn::CountTrue(D(), waiting);
    bool refill = false;
    if (count > 0 && (count >= kRefillAt * n / 8 || hn::AllTrue(D(), r.done))) {
      // Write out the rays that have ended, then give their lanes the next pixels.
      V cr, cg, cb;
      marcher.shade(r, job.transmittance, cr, cg, cb);
      hn::StoreU(cr, D(), red.data());
      hn::StoreU(cg, D(), green.data());
      hn::StoreU(cb, D(), blue.data());
      hn::StoreU(r.t, D(), t.data());
      hn::StoreU(r.steps, di, steps.data());
      hn::StoreU(r.crossings, di, crossings.data());
      hn::StoreU(r.hit, di, hit.data());
      fresh.fill(0);
      uint8_t bits[8] = {};
      hn::StoreMaskBits(D(), waiting, bits);
      uint64_t lanes_waiting = 0;
      for (size_t b = 0; b < 8; ++b) lanes_waiting |= uint64_t{bits[b]} << (8 * b);
      for (; lanes_waiting != 0; lanes_waiting &= lanes_waiting - 1) {
        const size_t l = static_cast<size_t>(hwy::Num0BitsBelowLS1Bit_Nonzero64(lanes_waiting));
        if (pixel_i[l] >= 0)
          job.frame->set(pixel_i[l], pixel_j[l], Vec3(red[l], green[l], blue[l]), steps[l],
                         crossings[l], hit[l], t[l]);
        pixel_i[l] = -1;
        while (next < queue && pixel_i[l] < 0) {
          const int64_t tile_index = next / static_cast<int64_t>(n);
          const int lane = static_cast<int>(next % static_cast<int64_t>(n));
          ++next;
          const int i =
              (col0 + static_cast<int>(tile_index % tiles_across)) * tile.width + lane % tile.width;
          const int j = (row0 + static_cast<int>(tile_index / tiles_across)) * tile.height +
                        lane / tile.width;
          if (i >= job.width || j >= job.height) continue;
          pixel_i[l] = i;
          pixel_j[l] = j;
          fresh[l] = -1;
          refill = true;
        }
      }
      occupied = hn::RebindMask(D(), hn::Gt(hn::LoadU(di, pixel_i.data()), SplatI(-1)));
    }
    if (refill) {
      const M m = hn::RebindMask(D(), hn::MaskFromVec(hn::LoadU(di, fresh.data())));
      V dx, dy, dz;
      CameraRays(job, pixel_i.data(), pixel_j.data(), dx, dy, dz);
      marcher.start(r, x, seg, m, job.polygon, from_x, from_y, from_z, dx, dy, dz);
      continue;  // a ray may end as it starts (a miss): write it out before stepping
    }
    if (hn::AllTrue(D(), r.done)) break;  // no pixels left and every ray written
    marcher.step(r, x, seg, *lanes);
  }
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
  CameraRays(job, pixel_i.data(), pixel_j.data(), dx, dy, dz);
  Marcher::clear(r, x, seg);
  marcher.start(r, x, seg, hn::Not(None()), job.polygon, Splat(job.from.x), Splat(job.from.y),
                Splat(job.from.z), dx, dy, dz);
}

// One room's step on a full packet, `repeats` times: the central tile's rays (CentralPacket),
// each time from their start, take one step. Returns the lanes that stepped, summed: the
// lane-steps a packet takes when nothing leaves a lane idle (a ray that starts done does not
// count).
int64_t RoomSteps(const PacketJob& job, int64_t repeats) {
  const Marcher marcher(*job.tables, job.edge_extra, nullptr, 0);
  Packet start, r;
  Relaxation start_x, x;
  Segment start_seg, seg;
  CentralPacket(job, marcher, start, start_x, start_seg);
  LaneCounts lanes;
  V sum = Splat(0.0f);  // of the steps' results, so that none is left out as unused
  for (int64_t k = 0; k < repeats; ++k) {
    r = start;
    x = start_x;
    seg = start_seg;
    marcher.step(r, x, seg, lanes);
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
  const Marcher marcher(*job.tables, job.edge_extra, events, max_events);
  Packet r;
  Relaxation x;
  Segment seg;
  Marcher::clear(r, x, seg);
  const glm::vec3 from(ray.from), dir(ray.dir);
  marcher.start(r, x, seg, hn::FirstN(D(), 1), ray.polygon, Splat(from.x), Splat(from.y),
                Splat(from.z), Splat(dir.x), Splat(dir.y), Splat(dir.z));
  LaneCounts lanes;
  for (int i = 0; i < job.tables->params.max_steps && !hn::AllTrue(D(), r.done); ++i)
    marcher.step(r, x, seg, lanes);
  return hn::GetLane(r.steps);
}

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
    job.edge_extra.emplace_back(abx, aby, tables.params.vertex_tolerance * std::sqrt(e.line.w),
                                e.segment.y + aby);
  }
  return job;
}

HWY_EXPORT(PacketLanes);
HWY_EXPORT(MarchPackets);
HWY_EXPORT(TraceRay);
HWY_EXPORT(RoomSteps);

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
                  &HWY_DYNAMIC_DISPATCH(TraceRay), &HWY_DYNAMIC_DISPATCH(RoomSteps)};
  if (target != 0) {
    hwy::SetSupportedTargetsForTest(0);
    hwy::GetChosenTarget().Update(hwy::SupportedTargets());
  }
  return code;
}

}  // namespace flatmarch::simd
#endif
