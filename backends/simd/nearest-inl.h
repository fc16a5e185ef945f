// The analytic method's exit edge for a whole pass over several rooms (Rooms::whole, edges looked
// up by lane), found by the nearest line first: Walls::exit_edge's answer, bit for bit, with
// fewer edges tested for where along them the rays meet them.
//
// Walls::exit_edge keeps, over the edges a ray moves towards, the one least by a key: the least
// max(s, 0) (s: the distance to the edge's line); at a tie an edge met at s < 0 before one met at
// s >= 0, among those met at s < 0 the last, among the others the first. Each edge replaces the
// exit so far exactly when its key is less, and only edges met on the edge (on_edge: the edge
// parameter u within the tolerance) count. Without that test the same loop finds the least over
// more edges; where that edge is met on the edge it is the least of those that are, so the full
// loop ends on it too, with the same s and u. The lanes where it is not (in convex rooms, rays
// near a vertex) take the full loop.
//
// In a whole pass over several rooms the full loop reads nine numbers of each edge by lane, for
// slots that rays in other rooms move towards as well (the cube's faces and the double pentagon's
// rooms turn rays against each other: 3.36 of the cube's 4 slots tested a pass where a lane moves
// towards 2.00, NOTES.md). Here a slot costs its normal's three numbers, and the edge found its
// six more once.

// Per-target include guard: this file is included once per instruction set (hwy/foreach_target.h
// re-includes packet.cpp for each), so the guard toggles with HWY_TARGET_TOGGLE.
#if defined(FLATMARCH_BACKENDS_SIMD_NEAREST_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef FLATMARCH_BACKENDS_SIMD_NEAREST_INL_H_
#undef FLATMARCH_BACKENDS_SIMD_NEAREST_INL_H_
#else
#define FLATMARCH_BACKENDS_SIMD_NEAREST_INL_H_
#endif

#include <hwy/highway.h>

#include "backends/simd/lanes-inl.h"
#include "backends/simd/maths-inl.h"
#include "backends/simd/walls-inl.h"

HWY_BEFORE_NAMESPACE();
namespace flatmarch::simd {
namespace HWY_NAMESPACE {

// Each lane's edge of slot `k` (a lane's own number) in its room, for the lanes of `valid` (0
// elsewhere): every number looked up by lane, none read alike by slot (a slot number past those,
// kAlikeSlots, so that Walls::field looks every number up).
FLATMARCH_PACKET_INLINE Walls::Slot SlotByLane(const Rooms& rooms, M valid, VI k) {
  Walls::Slot at;
  at.edge = 0;
  at.k = kAlikeSlots;
  at.rooms = &rooms;
  at.valid = valid;
  at.edges = Select(valid, rooms.first_edge + k, SplatI(0));
  return at;
}

// Of a pair of opposite slots k and j (Walls::opposite_pairs), the one a ray of `m` moves
// towards, if any: its slot, its line's distance s, its dn, and whether the nearest-line loop
// below would take it as the first edge it tests (`first`: moved towards, s >= least, s < kFar)
// or as one tested after another (`base`: the same without s < kFar).
struct PairEdge {
  VI slot;
  V s, dn;
  M base, first;
};
FLATMARCH_PACKET_INLINE PairEdge TowardsOfPair(const Walls& walls, M m, const Rooms& rooms, int k,
                                               int j, V least, const lane::vec2& o,
                                               const lane::vec2& dh) {
  const Walls::Slot at_k = walls.slot<false>(rooms, k), at_j = walls.slot<false>(rooms, j);
  // The normals are alike in every room (broadcasts), and slot j's is slot k's negated: where
  // a ray moves towards edge k it moves away from edge j, and where it does not towards k, its
  // numbers for j are j's own. So the pair costs one line's distance, not two.
  const V nkx = walls.field<false>(at_k, kNx), nky = walls.field<false>(at_k, kNy);
  const M take_k = lane::dot(dh, lane::vec2(nkx, nky)).v > Splat(0.0f);
  const lane::vec2 n(Select(take_k, nkx, walls.field<false>(at_j, kNx)),
                     Select(take_k, nky, walls.field<false>(at_j, kNy)));
  PairEdge e;
  e.slot = Select(take_k, SplatI(k), SplatI(j));
  const Walls::Slot at = SlotByLane(rooms, m, e.slot);  // the lane's own edge
  e.dn = lane::dot(dh, n).v;
  e.s = lane::line_distance(o, n, walls.field<false>(at, kNa), e.dn).v;
  e.base = hn::AndNot(e.s < least, hn::And(m, e.dn > Splat(0.0f)));
  e.first = hn::AndNot(e.s >= Splat(kFar), e.base);
  return e;
}

// Walls::exit_edge<false> for the rays of `m` in a whole pass whose edges are looked up by lane
// (Walls::glue_by_lane, not Walls::same_rooms).
FLATMARCH_PACKET_INLINE Exit ExitByNearestLine(const Walls& walls, M m, const Rooms& rooms,
                                               float vertex_tolerance, V ox, V oy, V dhx, V dhy) {
  const lane::vec2 o(ox, oy), dh(dhx, dhy);
  const V least = Splat(-vertex_tolerance);
  V s_exit = Splat(kFar), s_line = Splat(0.0f), cosine = Splat(0.0f);
  VI k_exit = SplatI(-1);
  if (walls.opposite_pairs()) {
    // Rooms of four edges in two opposite pairs (0, 2) and (1, 3): the loop below would find
    // each lane one edge of each pair it moves towards, a and b, and take them in slot order.
    // Both are found at once, and the order applied lane by lane: where b's slot comes first,
    // a is tested after b, else b after a (an edge tested second replaces the first exactly
    // when the loop's test passes against the first's max(s, 0)).
    const PairEdge a = TowardsOfPair(walls, m, rooms, 0, 2, least, o, dh);
    const PairEdge b = TowardsOfPair(walls, m, rooms, 1, 3, least, o, dh);
    const V a_exit = Select(a.first, hn::Max(a.s, Splat(0.0f)), Splat(kFar));
    const V b_exit = Select(b.first, hn::Max(b.s, Splat(0.0f)), Splat(kFar));
    const M a_after_b = hn::AndNot(a.s >= b_exit, a.base);  // a, tested after b, replaces it
    const M b_after_a = hn::AndNot(b.s >= a_exit, b.base);  // b, tested after a, replaces it
    const M b_first = hn::RebindMask(D(), b.slot < a.slot);
    const M take_b = Select(b_first, hn::AndNot(a_after_b, b.first), b_after_a);
    const M take_a = hn::AndNot(take_b, Select(b_first, a_after_b, a.first));
    s_exit = Select(take_b, b_exit, Select(take_a, a_exit, s_exit));
    s_line = Select(take_b, b.s, Select(take_a, a.s, s_line));
    k_exit = Select(take_b, b.slot, Select(take_a, a.slot, k_exit));
    cosine = Select(take_b, b.dn, Select(take_a, a.dn, cosine));
  }
  for (int k = 0; k < rooms.most_edges && !walls.opposite_pairs(); ++k) {
    const Walls::Slot at = walls.slot<false>(rooms, k);
    const lane::vec2 n(walls.field<false>(at, kNx), walls.field<false>(at, kNy));
    const V dn = lane::dot(dh, n).v;
    const M towards = hn::And(hn::And(m, at.valid), dn > Splat(0.0f));
    // No skip of an edge no lane moves towards: in a whole pass the lanes' directions differ
    // (the cube's rooms turn them), the branch went either way, and the few operations it saved
    // cost less than its misses (cube 0.975x the time, double pentagon 0.968-0.997x). In a room's
    // own pass (Walls::exit_edge) the skip pays: without it, 1.01-1.14x.
    const V s = lane::line_distance(o, n, walls.field<false>(at, kNa), dn).v;
    const M ok = hn::AndNot(hn::Or(s < least, s >= s_exit), towards);
    s_exit = Select(ok, hn::Max(s, Splat(0.0f)), s_exit);
    s_line = Select(ok, s, s_line);
    k_exit = Select(ok, SplatI(k), k_exit);
    cosine = Select(ok, dn, cosine);
  }
  // The edge found, each lane's own: its numbers looked up by lane.
  const M found = AtLeastZero(k_exit);
  const Walls::Slot at = SlotByLane(rooms, found, k_exit);
  const V u =
      lane::edge_parameter(o + lane::real(s_line) * dh,
                           lane::vec2(walls.field<false>(at, kAx), walls.field<false>(at, kAy)),
                           lane::vec2(walls.field<false>(at, kAbx), walls.field<false>(at, kAby)),
                           walls.field<false>(at, kInvLength2))
          .v;
  const V tolerance = walls.field<false>(at, kTolerance);
  const M on = hn::And(found, lane::on_edge(u, tolerance).m);
  Exit x;
  x.s = Select(on, s_exit, Splat(kFar));
  x.edge = Select(on, k_exit, SplatI(-1));
  x.corner = hn::And(on, lane::near_end(u, tolerance).m);
  x.cosine = cosine;
  x.index = at.edges;  // known before `on`: where it fails, the lane does not cross
  // Lanes with no edge found have the full loop's answer already (it finds none either).
  const M rest = hn::AndNot(on, hn::And(m, found));
  if (Any(rest)) {
    const Exit full = walls.exit_edge<false>(rest, rooms, ox, oy, dhx, dhy);
    x.s = Select(rest, full.s, x.s);
    x.edge = Select(rest, full.edge, x.edge);
    x.corner = hn::Or(hn::AndNot(rest, x.corner), hn::And(rest, full.corner));
    x.cosine = Select(rest, full.cosine, x.cosine);
    x.index = Select(rest, full.index, x.index);
  }
  return x;
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace flatmarch::simd
HWY_AFTER_NAMESPACE();
#endif  // FLATMARCH_BACKENDS_SIMD_NEAREST_INL_H_
