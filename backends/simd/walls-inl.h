// The walls of a pass's rooms for packets of rays: distances to them, where rays leave by them,
// which are opaque, and what a gluing does to the rays that cross one (march.glsl's "Walls"; the
// gluing's map itself is in gluings-inl.h). A pass's table reads are one broadcast record per
// room, or, where a pass spans several rooms, a broadcast of numbers alike in every room, a load
// of the edges each lane holds (HeldEdges: sphere and relaxed tracing in rooms of at most
// kHeldEdges edges), a lookup of each lane's edge in one or two vectors holding the scene's
// edges, or, for more edges, a broadcast per room blended by lane.

// Per-target include guard: this file is included once per instruction set (hwy/foreach_target.h
// re-includes packet.cpp for each), so the guard toggles with HWY_TARGET_TOGGLE.
#if defined(FLATMARCH_BACKENDS_SIMD_WALLS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef FLATMARCH_BACKENDS_SIMD_WALLS_INL_H_
#undef FLATMARCH_BACKENDS_SIMD_WALLS_INL_H_
#else
#define FLATMARCH_BACKENDS_SIMD_WALLS_INL_H_
#endif

#include <hwy/highway.h>

#include <algorithm>
#include <array>
#include <vector>

#include "backends/simd/gluings-inl.h"
#include "backends/simd/lanes-inl.h"
#include "backends/simd/maths-inl.h"

HWY_BEFORE_NAMESPACE();
namespace flatmarch::simd {
namespace HWY_NAMESPACE {

class Walls {
 public:
  // The scene's edges as the packets read them (edge_tables.hpp's EdgeTables, worked out once a
  // frame) copied into the object's arrays: as far as this instruction set's lookups load, and
  // only room 0's numbers where the rooms are alike (the rest are never read).
  explicit Walls(const PacketJob& job)
      : polygons_(job.tables->polygons.data()),
        edges_(job.tables->edges.data()),
        extra_(job.edge_extra.data()),
        high_(job.edge_high.data()),
        params_(job.tables->params),
        features_(job.tables->features) {
    // Passes over several rooms read each lane's edge from the scene's edge numbers: by a lookup
    // in up to Tuning::most_vectors vectors when the edges fit in them, else by a broadcast per
    // room blended by lane (cheaper than a gather), for scenes of up to kMostEdges edges.
    const kernel::SceneTables<float>& tables = *job.tables;
    const EdgeTables& t = job.edges;
    const size_t edges = tables.edges.size(), lanes = hn::Lanes(D());
    vectors_ = (std::max(edges, tables.polygons.size()) + lanes - 1) / lanes;
    const Tuning tune = tuning(kIsa);
    const uint32_t modes = ModesAllowed(job);
    const size_t most_vectors = static_cast<size_t>(std::clamp(
        tables.params.method == kMethodAnalytic ? tune.most_vectors_analytic : tune.most_vectors, 1,
        static_cast<int>(kLookUpVectors)));
    mode_ = vectors_ <= most_vectors ? kTable : edges <= kMostEdges ? kBlend : kSingle;
    if ((modes & kModeBySlot) != 0u && mode_ != kTable && t.glue_by_slot &&
        static_cast<size_t>(t.most_edges) <= lanes && t.tints.size() <= 2 * lanes)
      by_slot_.take(t);
    if (mode_ == kSingle) return;
    most_edges_ = t.most_edges;
    held_ = (modes & kModeHeld) != 0u && (tune.held_over_lookup || mode_ != kTable) &&
            tables.params.method != kMethodAnalytic && tables.polygons.size() > 1 &&
            std::all_of(tables.polygons.begin(), tables.polygons.end(),
                        [](const ivec4& p) { return p.y <= kHeldEdges; });
    same_first_edge_ = t.same_first_edge;
    same_count_ = t.same_count;
    same_rooms_ = (modes & kModeSameRooms) != 0u && t.same_rooms;
    if ((modes & kModeAlike) != 0u) {
      alike_ = t.alike;
      alike_number_ = t.alike_number;
    }
    if (mode_ == kBlend) {  // broadcasts of the edges' numbers: no zeros needed past them
      const size_t from = same_rooms_ ? static_cast<size_t>(same_first_edge_) : 0;
      const size_t count = same_rooms_ ? static_cast<size_t>(most_edges_) : edges;
      for (size_t f = 0; f < kFields; ++f)
        std::copy_n(t.number[f].begin() + static_cast<std::ptrdiff_t>(from), count,
                    lookup_[f].begin() + static_cast<std::ptrdiff_t>(from));
      return;
    }
    // Zero up to whole vectors, for the lookup's loads.
    const size_t filled = std::max(edges, vectors_ * lanes);
    const auto copy = [&](auto& table, const auto& numbers) {
      std::fill_n(table.begin(), filled, 0);
      std::copy_n(numbers.begin(), edges, table.begin());
    };
    for (size_t f = 0; f < kFields; ++f) copy(lookup_[f], t.number[f]);
    // Each room's edges, for whole passes (whole_pass).
    std::fill_n(first_edge_.begin(), filled, 0);
    std::fill_n(edge_count_.begin(), filled, 0);
    for (size_t p = 0; p < tables.polygons.size(); ++p) {
      first_edge_[p] = tables.polygons[p].x;
      edge_count_[p] = tables.polygons[p].y;
    }
    // What a gluing does to the rays at each edge, for crossings in one round (cross_glued).
    copy(wall_, t.wall);
    copy(to_polygon_, t.to_polygon);
    for (size_t f = 0; f < kGlueFields; ++f) copy(glue_[f], t.glue[f]);
    for (size_t f = 0; f < 4; ++f) copy(seam_[f], t.seam[f]);
    if ((modes & kModeAlike) != 0u) {
      glue_alike_ = t.glue_alike;
      glue_number_ = t.glue_number;
    }
    const auto opposite = [&](size_t k, size_t j) {
      const uint32_t both = (1u << k) | (1u << j);
      return (alike_[kNx] & both) == both && (alike_[kNy] & both) == both &&
             alike_number_[kNx][j] == -alike_number_[kNx][k] &&
             alike_number_[kNy][j] == -alike_number_[kNy][k];
    };
    opposite_pairs_ = (modes & kModeOppositePairs) != 0u && most_edges_ == 4 && same_count_ &&
                      opposite(0, 2) && opposite(1, 3);
  }

  // Whether a pass may span several rooms (up to kMostEdges edges in the scene).
  bool merge() const { return mode_ != kSingle; }
  // How a pass over several rooms reads its lanes' edges (PacketModes::passes), and in how many
  // vectors where it looks them up.
  const char* passes() const {
    return mode_ == kTable ? "lookup" : mode_ == kBlend ? "blend" : "single";
  }
  int vectors() const { return mode_ == kTable ? static_cast<int>(vectors_) : 0; }
  // Whether passes over several rooms read some number alike in every room by broadcast
  // (kModeAlike): an edge's, or a gluing's in crossings looked up by lane.
  bool alike() const {
    const bool edge_alike =
        merge() && !same_rooms_ &&
        std::any_of(alike_.begin(), alike_.end(), [](uint32_t bits) { return bits != 0u; });
    return edge_alike || (glue_by_lane() && glue_alike_ != 0u);
  }
  // Whether whole passes read the edges each lane holds (HeldEdges) rather than look them up:
  // sphere and relaxed tracing in scenes of several rooms of at most kHeldEdges edges (kModeHeld),
  // where the edges cannot be looked up in vectors unless the row holds them all the same
  // (Tuning::held_over_lookup).
  bool held() const { return held_; }
  // Where held(): the lanes of `m` in `polygon` take their room's edges where they do not hold
  // them yet, one broadcast per number of each room taken.
  FLATMARCH_PACKET_INLINE void hold(HeldEdges& held, VI polygon, M m) const {
    const M stale = hn::AndNot(hn::RebindMask(D(), held.polygon == polygon), m);
    if (!Any(stale)) return;
    std::array<int32_t, hn::MaxLanes(DI())> lane_rooms{};
    hn::StoreU(polygon, DI(), lane_rooms.data());
    for (M left = stale; Any(left);) {  // bounded: every turn takes at least one lane
      const int p = lane_rooms[static_cast<size_t>(hn::FindFirstTrue(D(), left))];
      const M in = hn::And(left, Equal(polygon, p));
      left = hn::AndNot(in, left);
      const ivec4 poly = polygons_[p];
      for (int k = 0; k < poly.y; ++k) {
        const auto take = [&](Field f) FLATMARCH_PACKET_LAMBDA {
          V& v = held.number[static_cast<size_t>(k)][f];
          v = Select(in, Splat(lookup_[f][static_cast<size_t>(poly.x + k)]), v);
        };
        if (params_.convex != 0) {
          for (const Field f : kHeldLines) take(f);
        } else {
          for (const Field f : kHeldSegments) take(f);
        }
      }
      held.first_edge = Select(in, SplatI(poly.x), held.first_edge);
      held.edge_count = Select(in, SplatI(poly.y), held.edge_count);
    }
    held.polygon = Select(stale, polygon, held.polygon);
  }

  // Whether crossings look each lane's gluing up in vectors (cross_glued). Where the edges do
  // not fit in two, a crossing takes a round per edge crossed: a gather of each lane's gluing
  // made the cube's and the staircases' analytic frames 1.4-1.5x slower (measured).
  bool glue_by_lane() const { return mode_ == kTable; }
  // Whether a pass over several rooms may read each lane's edges by its room alone (a whole
  // pass, Rooms::whole): where they are held (held()) or looked up in vectors (glue_by_lane()).
  // Where the scene has walls, only the lookup says which edges are walls.
  bool whole(bool analytic) const {
    if (mode_ == kTable || (same_rooms_ && !has(kFeatureWalls))) return true;
    return !analytic && held_ && !has(kFeatureWalls);
  }
  // Whether every room has four edges whose normals are alike in every room, slot 2's slot 0's
  // negated and slot 3's slot 1's (parallelograms drawn alike: the cube's faces, squares): a
  // ray moves towards one edge of each pair at most (ExitByNearestLine).
  bool opposite_pairs() const { return opposite_pairs_; }
  // Whether the rooms are alike in every number a step reads (each edge's numbers the same in
  // every room): lanes need not hold their edges.
  bool same_rooms() const { return same_rooms_; }
  // A whole pass over the lanes of `m` in their rooms `polygon`: each lane's edges held, taken
  // now where the lane does not hold them yet (`held` not null, held()), or its room's first
  // edge and edge count looked up (glue_by_lane()).
  FLATMARCH_PACKET_INLINE Rooms whole_pass(VI polygon, M m, HeldEdges* held) const {
    Rooms rooms;
    rooms.whole = true;
    rooms.all = m;
    rooms.polygons = polygon;
    rooms.most_edges = most_edges_;
    if (held) {
      hold(*held, polygon, m);
      rooms.first_edge = held->first_edge;
      rooms.edge_count = held->edge_count;
    } else if (mode_ == kTable) {
      const VI at = Select(m, polygon, SplatI(0));
      rooms.first_edge = lookup(DI(), first_edge_, at);
      rooms.edge_count = same_count_ ? SplatI(most_edges_) : lookup(DI(), edge_count_, at);
    } else {  // same_rooms(): every number is read by broadcast, the first room's (field)
      rooms.first_edge = SplatI(same_first_edge_);
      rooms.edge_count = SplatI(most_edges_);
    }
    return rooms;
  }

  // Edge k of each lane's room: its index in the edge table (0 where the room has fewer
  // edges), and the lanes whose room has one.
  struct Slot {
    int edge;  // in one room
    VI edges;  // in several
    M valid;
    int k;               // the slot's number in each room
    const Rooms* rooms;  // in several
  };
  template <bool kOneRoom>
  FLATMARCH_PACKET_INLINE Slot slot(const Rooms& rooms, int k) const {
    Slot at;
    at.k = k;
    at.rooms = &rooms;
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
  // the scene's edge numbers (lookup_).
  template <bool kOneRoom>
  FLATMARCH_PACKET_INLINE V field(const Slot& at, Field f) const {
    if constexpr (kOneRoom) return Splat(edge_number(f, edges_[at.edge], extra_[at.edge]));
    if (same_rooms_) return Splat(lookup_[f][static_cast<size_t>(same_first_edge_ + at.k)]);
    if (at.k < kAlikeSlots && ((alike_[f] >> at.k) & 1u) != 0u)
      return Splat(alike_number_[f][static_cast<size_t>(at.k)]);
    if (mode_ == kTable) return lookup(D(), lookup_[f], at.edges);
    // The few rooms' numbers broadcast and blended: cheaper than a gather.
    V v = Splat(0.0f);
    for (size_t i = 0; i < static_cast<size_t>(at.rooms->count); ++i) {
      const ivec4 poly = polygons_[at.rooms->polygon[i]];
      if (at.k < poly.y)
        v = Select(at.rooms->lanes[i], Splat(lookup_[f][static_cast<size_t>(poly.x + at.k)]), v);
    }
    return v;
  }

  FLATMARCH_PACKET_INLINE M inside_polygon(int polygon, V px, V py) const {
    const ivec4 poly = polygons_[polygon];
    M inside = None();
    for (int k = poly.x; k < poly.x + poly.y; ++k) {
      const glm::vec4 s = edges_[k].segment;
      const glm::vec4 x = extra_[k];
      const lane::vec2 ap(px - Splat(s.x), py - Splat(s.y));
      inside = hn::Xor(inside, lane::crosses(py, s.y, x.w, ap, lane::vec2(x.x, x.y)).m);
    }
    return inside;
  }

  // `held`: the edges the lanes hold, read instead of the tables where not null (a whole pass).
  // Where the rooms are convex, the nearest edge's line gives the distance, and the segments
  // are measured only where some lane is within eps of two lines (march.glsl's wall_distance).
  template <bool kOneRoom>
  FLATMARCH_PACKET_INLINE WallDistance wall_distance(const Rooms& rooms, const HeldEdges* held,
                                                     V px, V py) const {
    if (params_.convex == 0) return nearest_edge<kOneRoom>(rooms, held, px, py);
    WallDistance w{Splat(kFar), SplatI(-1), Splat(kFar)};
    M lanes = None();
    const lane::vec2 p(px, py);
    const int most = held ? kHeldEdges : rooms.most_edges;
    for (int k = 0; k < most; ++k) {
      if (held && k >= rooms.most_edges) break;
      const Slot at = slot<kOneRoom>(rooms, k);
      const auto read = [&](Field f) FLATMARCH_PACKET_LAMBDA {
        if (!kOneRoom && held) return held->number[static_cast<size_t>(k)][f];
        return field<kOneRoom>(at, f);
      };
      V gap = lane::line_gap(p, lane::vec4{read(kNx), read(kNy), read(kNa), 0.0f}).v;
      // Lanes whose room has no edge k: none (in one room, or rooms of as many edges, every
      // lane of the pass has it, and the rest are not read).
      if (!kOneRoom && !same_count_) gap = Select(at.valid, gap, Splat(kFar));
      // The least two by min and max (w.d <= w.second throughout): the selects they replace
      // gave the same numbers.
      w.edge = Select(gap < w.d, SplatI(k), w.edge);
      w.second = hn::Min(hn::Max(gap, w.d), w.second);
      w.d = hn::Min(gap, w.d);
      lanes = hn::Or(lanes, at.valid);
    }
    const V eps = Splat(params_.eps);
    const M close = hn::And(lanes, hn::And(w.d < eps, w.second < eps));
    if (Any(close)) {
      // The nearest segment's edge and the next segment's distance (march.glsl's: two collinear
      // edges' lines are both near where only one segment is).
      V best = Splat(kFar), next = Splat(kFar);
      VI nearest = w.edge;
      for (int k = 0; k < most; ++k) {
        if (held && k >= rooms.most_edges) break;
        const Slot at = slot<kOneRoom>(rooms, k);
        // Lanes hold their lines only (hold): a gather of the segments, rare enough (corners).
        const auto read = [&](Field f) FLATMARCH_PACKET_LAMBDA {
          if (!kOneRoom && held) return hn::GatherIndex(D(), lookup_[f].data(), at.edges);
          return field<kOneRoom>(at, f);
        };
        const lane::vec2 ap(px - read(kAx), py - read(kAy)), ab(read(kAbx), read(kAby));
        const V d2 = lane::segment_distance2(ap, ab, read(kInvLength2)).v;
        const M in = hn::And(close, at.valid);
        const M nearer = hn::And(in, d2 < best);
        next = Select(in, Select(nearer, best, hn::Min(next, d2)), next);
        best = Select(nearer, d2, best);
        nearest = Select(nearer, SplatI(k), nearest);
      }
      w.second = Select(close, hn::Sqrt(next), w.second);
      w.edge = Select(close, nearest, w.edge);
    }
    return w;
  }

  // March.glsl's wall_distance by its search of every edge.
  template <bool kOneRoom>
  FLATMARCH_PACKET_INLINE WallDistance nearest_edge(const Rooms& rooms, const HeldEdges* held, V px,
                                                    V py) const {
    V best = Splat(kFar), second = Splat(kFar);
    VI edge = SplatI(-1);
    M inside = None();
    // Held edges: a loop of a constant count, unrolled.
    const int most = held ? kHeldEdges : rooms.most_edges;
    for (int k = 0; k < most; ++k) {
      if (held && k >= rooms.most_edges) break;
      const Slot at = slot<kOneRoom>(rooms, k);
      const M valid = at.valid;
      const auto read = [&](Field f) FLATMARCH_PACKET_LAMBDA {
        if (!kOneRoom && held) return held->number[static_cast<size_t>(k)][f];
        return field<kOneRoom>(at, f);
      };
      const V ax = read(kAx);
      const V ay = read(kAy);
      const V abx = read(kAbx);
      const V aby = read(kAby);
      const V w = read(kInvLength2);
      const V ay_aby = read(kAyAby);
      const lane::vec2 ap(px - ax, py - ay), ab(abx, aby);
      V d2 = lane::segment_distance2(ap, ab, w).v;
      // As in wall_distance: lanes without edge k masked only where rooms differ in edge
      // count, the least two by min and max.
      const bool every_lane = kOneRoom || same_count_;
      if (!every_lane) d2 = Select(valid, d2, Splat(kFar));
      edge = Select(d2 < best, SplatI(k), edge);
      second = hn::Min(hn::Max(d2, best), second);
      best = hn::Min(d2, best);
      const M crosses = lane::crosses(py, ay, ay_aby, ap, ab).m;
      inside = hn::Xor(inside, every_lane ? crosses : hn::And(valid, crosses));
    }
    WallDistance w;
    const V root = hn::Sqrt(best);
    w.d = Select(inside, root, hn::Neg(root));
    w.edge = edge;
    w.second = second;
    w.second_squared = true;
    return w;
  }

  // For the rays of `m`; an edge none of them moves towards is skipped.
  template <bool kOneRoom>
  FLATMARCH_PACKET_INLINE Exit exit_edge(M m, const Rooms& rooms, V ox, V oy, V dhx, V dhy) const {
    Exit x;
    x.s = Splat(kFar);
    x.edge = SplatI(-1);
    x.cosine = Splat(0.0f);
    V u_exit = Splat(0.5f), tolerance_exit = Splat(0.0f);  // of the exit edge found so far
    const V least = Splat(-params_.vertex_tolerance);
    const lane::vec2 o(ox, oy), dh(dhx, dhy);
    // In one room every lane of the pass has each edge.
    const M open = kOneRoom ? hn::And(m, rooms.lanes[0]) : m;
    for (int k = 0; k < rooms.most_edges; ++k) {
      const Slot at = slot<kOneRoom>(rooms, k);
      const lane::vec2 n(field<kOneRoom>(at, kNx), field<kOneRoom>(at, kNy));
      const V dn = lane::dot(dh, n).v;
      const M towards = hn::And(kOneRoom ? open : hn::And(open, at.valid), dn > Splat(0.0f));
      if (!Any(towards)) continue;
      const V nz = field<kOneRoom>(at, kNa);
      const V s = lane::line_distance(o, n, nz, dn).v;
      // No test whether any ray meets this edge's line before its exit so far: the branch
      // mispredicts in packets whose rays are at different steps of their march (with it, the
      // analytic frames were 2-6% slower).
      M ok = hn::AndNot(hn::Or(s < least, s >= x.s), towards);
      const V ax = field<kOneRoom>(at, kAx);
      const V ay = field<kOneRoom>(at, kAy);
      const V abx = field<kOneRoom>(at, kAbx);
      const V aby = field<kOneRoom>(at, kAby);
      const V w = field<kOneRoom>(at, kInvLength2);
      const V u =
          lane::edge_parameter(o + lane::real(s) * dh, lane::vec2(ax, ay), lane::vec2(abx, aby), w)
              .v;
      const V tolerance = field<kOneRoom>(at, kTolerance);
      // on_edge, its upper bound read in one room (job.edge_high), not added for every edge.
      const V high = kOneRoom ? Splat(high_[at.edge]) : Splat(1.0f) + tolerance;
      ok = hn::And(ok, lane::on_edge_within(u, hn::Neg(tolerance), high).m);
      x.s = Select(ok, hn::Max(s, Splat(0.0f)), x.s);
      x.edge = Select(ok, SplatI(k), x.edge);
      x.cosine = Select(ok, dn, x.cosine);
      u_exit = Select(ok, u, u_exit);
      tolerance_exit = Select(ok, tolerance, tolerance_exit);
    }
    x.corner = lane::near_end(u_exit, tolerance_exit).m;
    x.index = Select(AtLeastZero(x.edge), rooms.first_edge + x.edge, SplatI(0));
    return x;
  }

  // Which lanes' `edge` of their room is an opaque wall.
  FLATMARCH_PACKET_INLINE M is_wall(const Rooms& rooms, VI edge) const {
    M wall = None();
    if (!has(kFeatureWalls)) return wall;
    if (rooms.whole) {  // by lookup (whole())
      const M valid = hn::And(rooms.all, AtLeastZero(edge));
      const VI at = Select(valid, rooms.first_edge + edge, SplatI(0));
      return hn::And(valid, hn::RebindMask(D(), lookup(DI(), wall_, at) != SplatI(0)));
    }
    for (size_t i = 0; i < static_cast<size_t>(rooms.count); ++i) {
      const ivec4 poly = polygons_[rooms.polygon[i]];
      for (int k = 0; k < poly.y; ++k)
        if (edges_[poly.x + k].link.x == kEdgeWall)
          wall = hn::Or(wall, hn::And(rooms.lanes[i], Equal(edge, k)));
    }
    return wall;
  }

  // The inward unit normal of each lane's opaque wall `edge` of its room (for the rays of `m`).
  FLATMARCH_PACKET_INLINE lane::vec2 wall_normal(M m, const Rooms& rooms, VI edge) const {
    V nx = Splat(0.0f), ny = Splat(0.0f);
    if (rooms.whole) {  // by lookup (whole()): the edge's line's normal is in glue_
      const VI at = Select(m, rooms.first_edge + edge, SplatI(0));
      return {hn::Neg(lookup(D(), glue_[9], at)), hn::Neg(lookup(D(), glue_[10], at))};
    }
    for (size_t i = 0; i < static_cast<size_t>(rooms.count); ++i) {
      const ivec4 poly = polygons_[rooms.polygon[i]];
      for (int k = 0; k < poly.y; ++k) {
        const EdgeRecord& e = edges_[poly.x + k];
        if (e.link.x != kEdgeWall) continue;
        const M at = hn::And(m, hn::And(rooms.lanes[i], Equal(edge, k)));
        nx = Select(at, Splat(-e.line.x), nx);
        ny = Select(at, Splat(-e.line.y), ny);
      }
    }
    return {nx, ny};
  }

  // The rays of `m` go through their edge `edge` (glued; its index in the edge table) into the
  // glued room and are placed `push` inside the edge they are then behind: march.glsl's
  // cross_edge when every edge is glued and the scene's edges fit in a vector (merge()), each
  // lane looking its edge's gluing up (glue_), all in one round. `cosine`: the rays' component
  // along the edges' normals where known (Exit::cosine), else null. kInTable: `edge` is an index
  // of the table in every lane (Exit::index), so the lookups need not wait for `m`. The caller
  // records the event.
  template <bool kInTable>
  FLATMARCH_PACKET_INLINE void cross_glued(Packet& r, M m, VI edge, V push, const V* cosine) const {
    const VI at = kInTable ? edge : Select(m, edge, SplatI(0));
    const auto glue = [&](size_t f) FLATMARCH_PACKET_LAMBDA {
      return ((glue_alike_ >> f) & 1u) != 0u ? Splat(glue_number_[f]) : lookup(D(), glue_[f], at);
    };
    const lane::vec4 tint{glue(11), glue(12), glue(13), glue(14)};
    const auto seam_of = [&]() FLATMARCH_PACKET_LAMBDA {
      return lane::vec4{lookup(D(), seam_[0], at), lookup(D(), seam_[1], at),
                        lookup(D(), seam_[2], at), lookup(D(), seam_[3], at)};
    };
    GlueRays(r, m, params_, features_, glue, seam_of, tint, lookup(DI(), to_polygon_, at), push,
             cosine);
  }

  // Whether crossings read each lane's gluing by its slot (EdgeTables::glue_by_slot), in scenes
  // whose edges do not fit in vectors: a lookup in a vector for the gluing, one gather for the
  // destination room and the tint's number, instead of a round per room and edge crossed.
  bool glue_by_slot() const { return by_slot_.on(); }
  // The rays of `m` go through their edge `edge` (glued; its slot in their room), as
  // cross_glued.
  FLATMARCH_PACKET_INLINE void cross_by_slot(Packet& r, M m, VI edge, V push,
                                             const V* cosine) const {
    by_slot_.cross(r, m, edge, push, params_, features_, cosine);
  }

 private:
  bool has(uint feature) const { return (features_ & feature) != 0u; }

  const ivec4* polygons_;
  const EdgeRecord* edges_;
  const glm::vec4* extra_;  // per edge: b - a (x, y), vertex tolerance in u (z), a.y + (b - a).y
  const float* high_;       // per edge: 1 + that tolerance
  // The tables are arrays in the object, not on the heap: with std::vector the frames of the
  // torus and the L-shape, which never read them, were 10-20% slower (measured).
  static constexpr size_t kMostEdges = 512;
  template <typename T>
  using Table = std::array<T, kMostEdges>;

  template <class DT, typename T>
  FLATMARCH_PACKET_INLINE hn::Vec<DT> lookup(DT d, const Table<T>& table, VI index) const {
    return LookUp(d, table.data(), vectors_, index);
  }

  // How a pass over several rooms reads its lanes' edges.
  enum Mode { kSingle, kTable, kBlend } mode_ = kSingle;
  bool held_ = false;  // held()
  int most_edges_ = 0;
  // Where number f of edge k is alike in every room, bit k of alike_[f], and the number.
  std::array<uint32_t, kFields> alike_{};
  std::array<std::array<float, kAlikeSlots>, kFields> alike_number_{};
  bool same_rooms_ = false;  // same_rooms()
  int same_first_edge_ = 0;  // where same_rooms(), the first room's first edge, read for all
  size_t vectors_ = 1;
  std::array<Table<float>, kFields> lookup_;  // [field][edge]
  // Of each edge: its gluing's numbers (kGlueFields); and the destination polygon.
  std::array<Table<float>, kGlueFields> glue_;
  uint32_t glue_alike_ = 0;  // bit f: number f of glue_ alike at every glued edge, glue_number_[f]
  std::array<float, kGlueFields> glue_number_{};
  bool same_count_ = false;      // every room has most_edges_ edges
  bool opposite_pairs_ = false;  // opposite_pairs()
  Table<int32_t> to_polygon_, first_edge_, edge_count_;
  Table<int32_t> wall_;  // of each edge: -1 an opaque wall, else 0
  SlotGluings by_slot_;  // glue_by_slot()
  KernelParams params_;
  uint features_;
  // Of each edge: its seam record (EdgeRecord::seam), read by crossings where the look has seams.
  // Last: placed among the tables above, the AVX2 frames took 1.14-1.23x the time even with seams
  // off, here the same (SSE4's took 1.15-1.20x either way: not understood; backends/simd/NOTES.md).
  std::array<Table<float>, 4> seam_;
};

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace flatmarch::simd
HWY_AFTER_NAMESPACE();
#endif  // FLATMARCH_BACKENDS_SIMD_WALLS_INL_H_
