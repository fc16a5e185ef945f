// What a gluing does to the packets' rays that cross it (march.glsl's cross_edge): GlueRays
// applies each lane's gluing however it was read, and SlotGluings reads the lanes' gluings by
// their edge's slot in scenes glued alike slot by slot (EdgeTables::glue_by_slot), where the
// scene's edges do not fit in vectors. Walls reads them by edge where they do.

// Per-target include guard: this file is included once per instruction set (hwy/foreach_target.h
// re-includes packet.cpp for each), so the guard toggles with HWY_TARGET_TOGGLE.
#if defined(FLATMARCH_BACKENDS_SIMD_GLUINGS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef FLATMARCH_BACKENDS_SIMD_GLUINGS_INL_H_
#undef FLATMARCH_BACKENDS_SIMD_GLUINGS_INL_H_
#else
#define FLATMARCH_BACKENDS_SIMD_GLUINGS_INL_H_
#endif

#include <hwy/highway.h>

#include <array>

#include "backends/simd/edge_tables.hpp"
#include "backends/simd/lanes-inl.h"
#include "backends/simd/maths-inl.h"

HWY_BEFORE_NAMESPACE();
namespace flatmarch::simd {
namespace HWY_NAMESPACE {

// The glued edges of `m` take their rays into the room `to` and place them `push` inside the
// edge they are then behind: `glue(f)` gives each lane's glue field f (EdgeTables), `tint` its
// edge's tint. `cosine`: the rays' component along their edges' normals where the caller has it
// (the analytic method's Exit::cosine, the same numbers), else null: then computed from glue
// fields 9 and 10. `seam_of()` gives each lane's edge's seam record, read only where the look has
// seams. The caller records the event.
template <typename Glue, typename SeamOf>
FLATMARCH_PACKET_INLINE void GlueRays(Packet& r, M m, const KernelParams& params, uint features,
                                      const Glue& glue, const SeamOf& seam_of,
                                      const lane::vec4& tint, VI to, V push, const V* cosine) {
  if (params.seams.x > 0.0f)
    Seam(r, m, params, lane::vec4{glue(9), glue(10), 0.0f, 0.0f}, seam_of());
  const lane::vec4 linear{glue(2), glue(3), glue(4), glue(5)};
  const lane::vec4 shift{glue(0), glue(1), 0.0f, 0.0f};
  const lane::vec4 to_line{glue(6), glue(7), glue(8), 0.0f};
  // Carried from the exit, the cube's analytic frames took 0.96-0.97x the time: the two
  // lookups wait on the edge's index, the last thing a step finds.
  Tint(r, m, params, tint,
       cosine ? lane::real(*cosine)
              : lane::dot(lane::vec2(r.dx, r.dy), lane::vec2(glue(9), glue(10))));
  const lane::vec2 p =
      lane::place(lane::glue_point(linear, shift, lane::vec2(r.ox, r.oy)), to_line, push);
  const lane::vec2 dh = lane::glue_direction(linear, lane::vec2(r.dx, r.dy));
  V px = p.x.v, py = p.y.v, hx = dh.x.v, hy = dh.y.v, hz = r.dz;
  if ((features & kFeatureScaled) != 0u) Normalize(hx, hy, hz);
  r.polygon = Select(m, to, r.polygon);
  MoveTo(r, m, px, py, hx, hy, hz);
  r.crossings = Select(m, r.crossings + SplatI(1), r.crossings);
}

// Gluings read by slot: a lookup in a vector for the gluing, one gather for the destination
// room and the tint's number, instead of a round per room and edge crossed.
class SlotGluings {
 public:
  // Whether crossings read gluings by slot: taken (take()).
  bool on() const { return on_; }
  // The gluings' numbers by slot, the tints by number (rgba), and each room's slots'
  // destination and tint number (EdgeTables::slot_code, the job's).
  void take(const EdgeTables& t) {
    on_ = true;
    two_tint_vectors_ = t.tints.size() > hn::Lanes(D());
    glue_ = t.slot_glue;
    // Rooms of most_edges edges each, in order: a lane's slot code is at its edge's index.
    for (size_t c = 0; c < 2; ++c) seam_[c] = t.seam[c].data();
    seam_by_slot_ = t.seam_by_slot;
    slot_seam_ = t.slot_seam;
    for (size_t c = 0; c < 4; ++c)
      for (size_t k = 0; k < t.tints.size(); ++k) tint_[c][k] = t.tints[k][static_cast<int>(c)];
    code_ = t.slot_code.data();
    count_ = t.most_edges;
  }
  // The rays of `m` go through their edge `edge` (glued; its slot in their room).
  FLATMARCH_PACKET_INLINE void cross(Packet& r, M m, VI edge, V push, const KernelParams& params,
                                     uint features, const V* cosine) const {
    const DI di;
    const VI slot = Select(m, edge, SplatI(0));
    const auto by_slot = hn::IndicesFromVec(D(), slot);
    const auto glue = [&](size_t f) FLATMARCH_PACKET_LAMBDA {
      return hn::TableLookupLanes(hn::LoadU(D(), glue_[f].data()), by_slot);
    };
    const VI at = Select(m, r.polygon * SplatI(count_) + slot, SplatI(0));
    const VI code = hn::GatherIndex(di, code_, at);
    // The tints in one vector, or two (AVX2: the staircases' ten on 8 lanes; AVX-512's 16
    // lanes hold every tint glue_by_slot allows).
    const VI number = hn::And(hn::ShiftRight<16>(code), SplatI(0xff));
    const auto tint = [&](size_t c) FLATMARCH_PACKET_LAMBDA {
      return LookUp(D(), tint_[c].data(), two_tint_vectors_ ? 2 : 1, number);
    };
    // The seam records: what the ends are from the code, where they lie by slot where the rooms
    // are drawn in one place, else by a gather each.
    const auto seam_of = [&]() FLATMARCH_PACKET_LAMBDA {
      const auto end = [&](int shift) FLATMARCH_PACKET_LAMBDA {
        return hn::ConvertTo(D(), hn::And(hn::ShiftRightSame(code, shift), SplatI(3)));
      };
      const auto place = [&](size_t c) FLATMARCH_PACKET_LAMBDA {
        return seam_by_slot_ ? hn::TableLookupLanes(hn::LoadU(D(), slot_seam_[c].data()), by_slot)
                             : hn::GatherIndex(D(), seam_[c], at);
      };
      return lane::vec4{place(0), place(1), end(24), end(26)};
    };
    GlueRays(r, m, params, features, glue, seam_of, lane::vec4{tint(0), tint(1), tint(2), tint(3)},
             hn::And(code, SplatI(0xffff)), push, cosine);
  }

 private:
  bool on_ = false;
  bool two_tint_vectors_ = false;  // more tints than lanes
  std::array<std::array<float, kAlikeSlots>, kSlotGlueFields> glue_{};
  std::array<std::array<float, kAlikeSlots>, 4> tint_{};
  const int32_t* code_ = nullptr;
  std::array<const float*, 2> seam_{};  // where the edges' ends lie (EdgeTables::seam)
  bool seam_by_slot_ = false;           // ... alike slot by slot (EdgeTables::slot_seam)
  std::array<std::array<float, kAlikeSlots>, 2> slot_seam_{};
  int count_ = 0;
};

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace flatmarch::simd
HWY_AFTER_NAMESPACE();
#endif  // FLATMARCH_BACKENDS_SIMD_GLUINGS_INL_H_
