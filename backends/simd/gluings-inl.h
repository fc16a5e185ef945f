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
// fields 9 and 10. The caller records the event.
template <typename Glue>
FLATMARCH_PACKET_INLINE void GlueRays(Packet& r, M m, const KernelParams& params, uint features,
                                      const Glue& glue, const lane::vec4& tint, VI to, V push,
                                      const V* cosine) {
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
    const VI number = hn::ShiftRight<16>(code);
    const auto tint = [&](size_t c) FLATMARCH_PACKET_LAMBDA {
      return LookUp(D(), tint_[c].data(), two_tint_vectors_ ? 2 : 1, number);
    };
    GlueRays(r, m, params, features, glue, lane::vec4{tint(0), tint(1), tint(2), tint(3)},
             hn::And(code, SplatI(0xffff)), push, cosine);
  }

 private:
  bool on_ = false;
  bool two_tint_vectors_ = false;  // more tints than lanes
  std::array<std::array<float, kAlikeSlots>, kSlotGlueFields> glue_{};
  std::array<std::array<float, kAlikeSlots>, 4> tint_{};
  const int32_t* code_ = nullptr;
  int count_ = 0;
};

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace flatmarch::simd
HWY_AFTER_NAMESPACE();
#endif  // FLATMARCH_BACKENDS_SIMD_GLUINGS_INL_H_
