// The SIMD backend's vocabulary, per instruction set: the vector types (one lane per ray), the
// few helpers the packet code reads as words (Splat, Select, Any), the march state of a packet
// (march.glsl's Ray and the methods' state, one lane per ray), the rooms of a pass, and the
// edges a lane holds (the numbers of an edge by field are edge_tables.hpp's).

// The marcher's functions are inlined into one loop, but under the sanitizers GCC then takes
// over ten minutes on that one function: there it decides what to inline.
#ifndef FLATMARCH_PACKET_INLINE
#ifdef FLATMARCH_SANITIZE_BUILD
#define FLATMARCH_PACKET_INLINE inline
#else
#define FLATMARCH_PACKET_INLINE HWY_INLINE
#endif
#endif
// A lambda inside them is inlined the same way. Left to GCC, at -O3 the two that read an edge's
// numbers were called out of line and the frames took 1.12-1.23x the time of -O2's (1.01x with
// them inlined, over 18 cases).
#ifndef FLATMARCH_PACKET_LAMBDA
#ifdef FLATMARCH_SANITIZE_BUILD
#define FLATMARCH_PACKET_LAMBDA HWY_ATTR
#else
#define FLATMARCH_PACKET_LAMBDA HWY_ATTR __attribute__((always_inline))
#endif
#endif

// Per-target include guard: this file is included once per instruction set (hwy/foreach_target.h
// re-includes packet.cpp for each), so the guard toggles with HWY_TARGET_TOGGLE.
#if defined(FLATMARCH_BACKENDS_SIMD_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef FLATMARCH_BACKENDS_SIMD_LANES_INL_H_
#undef FLATMARCH_BACKENDS_SIMD_LANES_INL_H_
#else
#define FLATMARCH_BACKENDS_SIMD_LANES_INL_H_
#endif

#include <hwy/highway.h>

#include <array>

#include "backends/simd/packet.hpp"
#include "backends/simd/tuning.hpp"

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
// The lanes of `m` as bits, lane l in bit l.
HWY_INLINE uint64_t Bits(M m) {
  uint8_t bytes[8] = {};
  hn::StoreMaskBits(D(), m, bytes);
  uint64_t bits = 0;
  for (size_t b = 0; b < 8; ++b) bits |= uint64_t{bytes[b]} << (8 * b);
  return bits;
}
// Each lane of `m`: how many lanes of `m` are below it (the other lanes: any number).
HWY_INLINE VI Rank(M m) {
  const DI di;
#if HWY_ARCH_X86 && HWY_TARGET <= HWY_AVX3
  if constexpr (hn::MaxLanes(di) == 16)  // one instruction: the lane numbers expanded into `m`
    return VI{_mm512_maskz_expand_epi32(m.raw, hn::Iota(di, 0).raw)};
#endif
  const hn::RebindToUnsigned<DI> du;
  const auto below = (hn::Set(du, 1u) << hn::Iota(du, 0)) - hn::Set(du, 1u);
  const auto bits = hn::Set(du, static_cast<uint32_t>(Bits(m)));
  return hn::BitCast(di, hn::PopulationCount(hn::And(bits, below)));
}

// This target's row of tuning.hpp's table.
constexpr Isa kIsa = HWY_TARGET <= HWY_AVX3   ? Isa::avx512
                     : HWY_TARGET == HWY_AVX2 ? Isa::avx2
                                              : Isa::sse4;
// The modes (tuning.hpp's Mode) a frame of `job` may take on this target: its row's, less those
// the job leaves to their fallbacks.
inline uint32_t ModesAllowed(const PacketJob& job) {
  return tuning(kIsa).modes & ~job.modes_off;
}
// The most vectors LookUp takes (Tuning::most_vectors is held to it).
constexpr size_t kLookUpVectors = 4;

// Entry `index` of `table` for each lane, the table held in `vectors` vectors (1 to
// kLookUpVectors): in several, a lookup in each (or in each pair) and the lane's own kept.
template <class DT, typename T>
FLATMARCH_PACKET_INLINE hn::Vec<DT> LookUp(DT d, const T* table, size_t vectors, VI index) {
  if (vectors == 1) return hn::TableLookupLanes(hn::LoadU(d, table), hn::IndicesFromVec(d, index));
  const int lanes = static_cast<int>(hn::Lanes(d));
#if HWY_ARCH_X86 && HWY_TARGET <= HWY_AVX3
  // AVX-512 looks up in two vectors in one instruction (Highway 1.0.3 has no
  // TwoTablesLookupLanes): the cube's analytic frames 0.93-0.94x the time of two lookups and
  // a blend (5 interleaved rounds), the double pentagon's 0.95-0.99x.
  if constexpr (sizeof(T) == 4 && hn::MaxLanes(d) == 16) {
    const auto pair = [&](const T* at) FLATMARCH_PACKET_LAMBDA {
      const auto low = hn::LoadU(d, at), high = hn::LoadU(d, at + lanes);
      if constexpr (hwy::IsFloat<T>())
        return hn::Vec<DT>{_mm512_permutex2var_ps(low.raw, index.raw, high.raw)};
      else
        return hn::Vec<DT>{_mm512_permutex2var_epi32(low.raw, index.raw, high.raw)};
    };
    if (vectors == 2) return pair(table);
    const auto upper = hn::RebindMask(d, hn::Gt(index, SplatI(2 * lanes - 1)));
    return hn::IfThenElse(upper, pair(table + 2 * lanes), pair(table));
  }
#endif
  const auto low = hn::IndicesFromVec(d, hn::And(index, SplatI(lanes - 1)));
  auto v = hn::TableLookupLanes(hn::LoadU(d, table), low);
  for (size_t k = 1; k < vectors && k < kLookUpVectors; ++k) {
    const auto beyond = hn::RebindMask(d, hn::Gt(index, SplatI(static_cast<int>(k) * lanes - 1)));
    v = hn::IfThenElse(beyond, hn::TableLookupLanes(hn::LoadU(d, table + k * lanes), low), v);
  }
  return v;
}

// What a packet of rays is doing (march.glsl's Ray, one lane per ray).
struct Packet {
  VI polygon;
  V ox, oy, oz;  // point, in the coordinates of `polygon`
  V dx, dy, dz;  // unit direction
  V t;
  VI steps, crossings, hit;
  M done;
  V nx, ny, nz;  // normal of the solid, wall or floor hit
  V sr, sg, sb;  // colour of the solid hit
  V lr, lg, lb;  // what the walls crossed give (march.glsl's Ray.light)
  V clear;       // the share of light beyond them they let through
};

// The rays of `m` go on from (px, py) (their height unchanged) along (hx, hy, hz): where a
// crossing or a bounce leaves them.
HWY_INLINE void MoveTo(Packet& r, M m, V px, V py, V hx, V hy, V hz) {
  r.ox = Select(m, px, r.ox);
  r.oy = Select(m, py, r.oy);
  r.dx = Select(m, hx, r.dx);
  r.dy = Select(m, hy, r.dy);
  r.dz = Select(m, hz, r.dz);
}

// The rays of `m` end on a surface of unit normal (nx, ny, nz).
HWY_INLINE void SetNormal(Packet& r, M m, V nx, V ny, V nz) {
  r.nx = Select(m, nx, r.nx);
  r.ny = Select(m, ny, r.ny);
  r.nz = Select(m, nz, r.nz);
}

struct WallDistance {
  V d;
  VI edge;
  // The next edge's distance, or its square where `second_squared` (nearest_edge's: a step
  // needs it only at an edge, where next_edge() takes its root, saving a square root a step).
  V second;
  bool second_squared = false;
  HWY_INLINE V next_edge() const { return second_squared ? hn::Sqrt(second) : second; }
};

struct Exit {
  V s;
  VI edge;
  M corner;
  // The component of the ray's direction along the edge's normal (its dn): the tint of the
  // crossing reads it, and the direction does not change before it (a room segment).
  V cosine;
  // The edge's index in the edge table (its room's first edge plus `edge`), 0 where none: the
  // crossing's lookups by it need not wait for the tests that settle `edge`.
  VI index;
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
// each. A table read gives every lane its own room's record: in one room a broadcast; in several
// a lookup of each lane's edge in one or two vectors holding the scene's edges (Walls::lookup_),
// or, where the edges do not fit in two, each room's record broadcast and blended by lane (scenes
// of over Walls::kMostEdges edges take one room a pass). Coherent rays are mostly in one room; rays
// split between a few (the double pentagon's two, at every crossing) or spread over many (the
// cube, a staircase) still take one pass a step, not one per room (where Walls::whole, one whole
// pass whatever their number: Rooms::whole). 8 rooms a pass against 4:
// frames level, lanes busy 0.84 -> 0.90 on the cube and 0.83 -> 0.96 on 32- and 128-square
// staircases (sphere tracing, 640x360, one run).
constexpr int kRoomsPerPass = 8;
struct Rooms {
  int count = 0;
  int most_edges = 0;
  std::array<int, kRoomsPerPass> polygon{};
  std::array<M, kRoomsPerPass> lanes;  // the lanes in each
  M all;                               // the lanes of the pass
  VI first_edge, edge_count;           // of each lane's room, when there are several
  // A pass over every unfinished lane whatever its room (Marcher::step's whole passes): `count`
  // is 0, each lane's room is in `polygons`, and its edges are held (HeldEdges) or looked up in
  // vectors by first_edge and edge_count (Walls::whole).
  bool whole = false;
  VI polygons;
};

// Sphere and relaxed tracing in scenes of several rooms of at most kHeldEdges edges each (the
// cube, the staircases drawn apart): each lane holds the numbers of its room's edges that a step
// reads (kHeldSegments or kHeldLines), taken when a pass over several rooms first finds the lane in
// a room it does not hold (Walls::hold), so that such a pass reads each lane's edges with a load
// instead of a lookup or a broadcast per room blended by lane. A ray crosses once every 20-100
// steps there, so a lane's edges are taken far less often than they are read. With the whole passes
// this allows (Rooms::whole), against passes of up to eight rooms blended or looked up (640x360, 2
// cores, AVX-512, interleaved rounds): staircases of 32 and 128 squares 0.56-0.60x the time,
// the cube 0.74x, the pillowcase 0.88x; the double pentagon's five edges 0.85-0.92x (0.80x on
// AVX2, 0.73x on SSE4). The analytic method crosses at almost every step, and holding its edges
// made it 1.05-1.2x slower. Rooms alike in every number (Walls::same_rooms: a staircase whose
// squares are drawn in one place) hold nothing: their edges are read by broadcast.
constexpr int kHeldEdges = 5;
// The segments' numbers, or where every room is convex the lines' (Walls::wall_distance).
constexpr std::array<Field, 6> kHeldSegments{kAx, kAy, kAbx, kAby, kAyAby, kInvLength2};
constexpr std::array<Field, 3> kHeldLines{kNx, kNy, kNa};
struct HeldEdges {
  VI polygon;                                             // the room each lane holds, -1: none
  VI first_edge, edge_count;                              // its edges in the edge table
  std::array<std::array<V, kFields>, kHeldEdges> number;  // [edge][field], those held only
};
// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace flatmarch::simd
HWY_AFTER_NAMESPACE();
#endif  // FLATMARCH_BACKENDS_SIMD_LANES_INL_H_
