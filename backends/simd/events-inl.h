// What a step does to the rays it ends or takes across an edge (march.glsl's finish, cross_edge,
// leave_band and the hits), on packets of rays: the part of the march that marcher-inl.h's
// methods share, with the events a trace records.

// Per-target include guard: this file is included once per instruction set (hwy/foreach_target.h
// re-includes packet.cpp for each), so the guard toggles with HWY_TARGET_TOGGLE.
#if defined(FLATMARCH_BACKENDS_SIMD_EVENTS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef FLATMARCH_BACKENDS_SIMD_EVENTS_INL_H_
#undef FLATMARCH_BACKENDS_SIMD_EVENTS_INL_H_
#else
#define FLATMARCH_BACKENDS_SIMD_EVENTS_INL_H_
#endif

#include <hwy/highway.h>

#include <array>
#include <vector>

#include "backends/simd/lanes-inl.h"
#include "backends/simd/maths-inl.h"
#include "backends/simd/solids-inl.h"
#include "backends/simd/walls-inl.h"

HWY_BEFORE_NAMESPACE();
namespace flatmarch::simd {
namespace HWY_NAMESPACE {

class RayEvents {
 protected:
  RayEvents(const PacketJob& job, std::vector<kernel::KernelEvent>* events, int max_events)
      : walls_(job),
        solids_(*job.tables),
        polygons_(job.tables->polygons.data()),
        edges_(job.tables->edges.data()),
        objects_(job.tables->objects.data()),
        params_(job.tables->params),
        features_(job.tables->features),
        events_(events),
        max_events_(max_events),
        same_tint_(job.edges.same_tint) {}

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

  // The rays of `m` at their edge `edge` (of their room, in `rooms`) go through it or are
  // reflected, and are placed `push` inside the edge they are then behind. In one round where
  // each lane's gluing can be looked up (by its edge, Walls::cross_glued; by its slot,
  // Walls::cross_by_slot); else one broadcast record per edge crossed. `carried`: where not null,
  // the exit the rays found for `edge` (its cosine and index), for the one-round crossings.
  FLATMARCH_PACKET_INLINE void cross_edge(Packet& r, M m, const Rooms& rooms, VI edge, V push,
                                          const Exit* carried = nullptr) const {
    const bool by_lane = walls_.glue_by_lane() && !has(kFeatureMirrors);
    if (by_lane || walls_.glue_by_slot()) {
      if (events_ && !hn::AllFalse(D(), hn::And(m, hn::FirstN(D(), 1)))) {
        const ivec4 link = edges_[polygons_[hn::GetLane(r.polygon)].x + hn::GetLane(edge)].link;
        record(m, kEventGluing, r.polygon, edge, link.y, link.z, SplatI(-1), r);
      }
      const V* cosine = carried ? &carried->cosine : nullptr;
      if (by_lane && carried)
        walls_.cross_glued<true>(r, m, carried->index, push, cosine);
      else if (by_lane)
        walls_.cross_glued<false>(r, m, rooms.first_edge + edge, push, cosine);
      else
        walls_.cross_by_slot(r, m, edge, push, cosine);
      return;
    }
    std::array<int32_t, hn::MaxLanes(DI())> lane_edges{}, lane_rooms{};
    hn::StoreU(edge, DI(), lane_edges.data());
    hn::StoreU(r.polygon, DI(), lane_rooms.data());
    // One round per edge the rays cross (usually one or two), not per edge of their rooms; the
    // walls' tints mixed in at once after the rounds, each lane's edge's tint and cosine kept.
    lane::vec4 tint = lane::Broadcast(edges_[0].tint);
    V cosine = Splat(0.0f);
    for (M left = m; Any(left);) {
      const size_t first = static_cast<size_t>(hn::FindFirstTrue(D(), left));
      const int k = lane_edges[first], polygon = lane_rooms[first];
      const M mk = hn::And(left, hn::And(Equal(edge, k), Equal(r.polygon, polygon)));
      left = hn::AndNot(mk, left);
      const EdgeRecord& e = edges_[polygons_[polygon].x + k];
      const lane::vec2 o(r.ox, r.oy), d(r.dx, r.dy);
      cosine = Select(mk, lane::dot(d, lane::vec2(e.line.x, e.line.y)).v, cosine);
      if (!same_tint_) {
        tint.x = Select(mk, Splat(e.tint.x), tint.x.v);
        tint.y = Select(mk, Splat(e.tint.y), tint.y.v);
        tint.z = Select(mk, Splat(e.tint.z), tint.z.v);
        tint.w = Select(mk, Splat(e.tint.w), tint.w.v);
      }
      if (params_.seams.x > 0.0f)
        Seam(r, mk, params_, lane::Broadcast(e.line), lane::Broadcast(e.seam));
      lane::vec2 p = o, h = d;
      V hz = r.dz;
      if (has(kFeatureMirrors) && e.link.x == kEdgeMirror) {
        record(mk, kEventMirror, r.polygon, SplatI(k), -1, -1, SplatI(-1), r);
        const lane::vec4 line = lane::Broadcast(e.line);
        p = lane::place(o, line, push);
        h = lane::mirror_direction(d, line);
      } else {
        const ivec4 link = e.link;
        record(mk, kEventGluing, r.polygon, SplatI(k), link.y, link.z, SplatI(-1), r);
        const lane::vec4 linear = lane::Broadcast(e.map_linear);
        p = lane::place(lane::glue_point(linear, lane::Broadcast(e.map_shift), o),
                        lane::Broadcast(edges_[polygons_[link.y].x + link.z].line), push);
        h = lane::glue_direction(linear, d);
        if (has(kFeatureScaled)) Normalize(h.x.v, h.y.v, hz);
        r.polygon = Select(mk, SplatI(link.y), r.polygon);
      }
      MoveTo(r, mk, p.x.v, p.y.v, h.x.v, h.y.v, hz);
    }
    Tint(r, m, params_, tint, cosine);
    r.crossings = Select(m, r.crossings + SplatI(1), r.crossings);
  }

  // Distance along each ray to where it leaves the band.
  FLATMARCH_PACKET_INLINE V band_exit(const Packet& r) const {
    return lane::band_exit(params_.top, r.oz, r.dz).v;
  }

  // The rays of `m` reach the top or bottom of the band, `s` further on.
  FLATMARCH_PACKET_INLINE void leave_band(Packet& r, M m, V s) const {
    if (has(kFeaturePeriod)) {
      advance(r, m, s);
      Tint(r, m, params_, lane::Broadcast(params_.period_tint), r.dz);
      r.oz = Select(m, Select(r.dz > Splat(0.0f), Splat(0.0f), Splat(params_.top)), r.oz);
    } else if (has(kFeatureFloor)) {
      const M down = hn::And(m, r.dz < Splat(0.0f));
      finish(r, down, SplatI(kHitFloor), kEventFloor, SplatI(-1), s);
      SetNormal(r, down, Splat(0.0f), Splat(0.0f), Splat(1.0f));
      finish(r, hn::AndNot(down, m), SplatI(kHitEscape), kEventEscape, SplatI(-1), s);
    } else {
      finish(r, m, SplatI(kHitEscape), kEventEscape, SplatI(-1), s);
    }
  }

  // The rays of `m` end on their room's opaque wall `edge`, `s` further on.
  FLATMARCH_PACKET_INLINE void hit_wall(Packet& r, M m, const Rooms& rooms, VI edge, V s) const {
    if (!Any(m)) return;
    finish(r, m, SplatI(kHitWall), kEventWall, edge, s);
    const lane::vec2 n = walls_.wall_normal(m, rooms, edge);
    SetNormal(r, m, n.x.v, n.y.v, Splat(0.0f));
  }

  // The rays of `m` hit their `object` (an index in the object table) where they are.
  FLATMARCH_PACKET_INLINE void hit_solid(Packet& r, M m, VI object) const {
    std::array<int32_t, hn::MaxLanes(DI())> lane_objects{};
    hn::StoreU(object, DI(), lane_objects.data());
    for (M left = m; Any(left);) {
      const int k = lane_objects[static_cast<size_t>(hn::FindFirstTrue(D(), left))];
      const M mk = hn::And(left, Equal(object, k));
      left = hn::AndNot(mk, left);
      const lane::vec3 n = solids_.solid_normal(k, r.ox, r.oy, r.oz);
      const lane::vec3 surface = lane::solid_surface(lane::Broadcast(objects_[k].color), n);
      r.nx = Select(mk, n.x.v, r.nx);
      r.ny = Select(mk, n.y.v, r.ny);
      r.nz = Select(mk, n.z.v, r.nz);
      r.sr = Select(mk, surface.x.v, r.sr);
      r.sg = Select(mk, surface.y.v, r.sg);
      r.sb = Select(mk, surface.z.v, r.sb);
      finish(r, mk, SplatI(objects_[k].info.y), kEventObject, SplatI(-1), Splat(0.0f));
    }
  }

  Walls walls_;
  Solids solids_;
  const ivec4* polygons_;
  const EdgeRecord* edges_;
  const ObjectRecord* objects_;
  KernelParams params_;
  uint features_;
  std::vector<kernel::KernelEvent>* events_;
  int max_events_;
  bool same_tint_;  // every edge has the same tint
};

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace flatmarch::simd
HWY_AFTER_NAMESPACE();
#endif  // FLATMARCH_BACKENDS_SIMD_EVENTS_INL_H_
