// The SIMD backend's choices per instruction set, in one place: every threshold the packet code
// (packet.cpp and its *-inl.h) tunes, and the strategy each target takes where its instructions
// differ. Each value was set by runs on that instruction set; the table below says which, and
// backends/simd/NOTES.md (*Tuned per instruction set*) has the figures. A machine with AVX-512 runs
// its AVX2 and SSE4 targets too, but its cores execute them unlike an AVX2-only CPU: where a value
// was measured on such a machine alone, the table says so.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace flatmarch::simd {

enum class Isa { avx512, avx2, sse4 };

// The packet code's modes: ways of running a step that a scene's shape allows and that save work
// there, each with a fallback that gives the same frames bit for bit (simd_test's
// EveryModeAndItsFallback runs both on every instruction set the CPU runs). What each is for,
// where it runs and what keeps it: the table of modes above kTunings.
enum Mode : uint32_t {
  // Rays over several rooms take one pass a step, each lane's edges read by its room alone
  // (Rooms::whole); fallback: passes over up to rooms_per_pass rooms, each broadcast and blended.
  kModeWhole = 1u << 0,
  // In those passes (sphere and relaxed tracing, rooms of at most five edges), each lane holds
  // its room's edges (HeldEdges); fallback: looked up in vectors, or no whole pass.
  kModeHeld = 1u << 1,
  // Rooms alike in every number (squares drawn in one place) read by broadcast, whole passes
  // without walls; fallback: each lane's edges looked up or blended.
  kModeSameRooms = 1u << 2,
  // An edge slot's number alike in every room (the cube's normals) read by broadcast, and a
  // gluing's number alike at every edge; fallback: looked up or blended by lane.
  kModeAlike = 1u << 3,
  // Crossings in scenes glued alike slot by slot read the gluing by slot (SlotGluings) where the
  // edges do not fit in vectors; fallback: a round per room and edge crossed.
  kModeBySlot = 1u << 4,
  // The analytic method's whole passes over convex rooms not alike find their exit by the
  // nearest line first (nearest-inl.h), in a copy of the frame loop that carries the exit's
  // cosine and index to the crossing; fallback: every edge tested, the crossing's own lookups.
  kModeNearestLine = 1u << 5,
  // In that search, rooms of two opposite pairs of edges (the cube's faces) measure one line a
  // pair; fallback: every line.
  kModeOppositePairs = 1u << 6,
};
inline constexpr uint32_t kEveryMode = (1u << 7) - 1;
// Each mode's name (FLATMARCH_SIMD_TUNE's and the tests').
struct ModeName {
  Mode mode;
  const char* name;
};
inline constexpr std::array<ModeName, 7> kModeNames{{{kModeWhole, "whole"},
                                                     {kModeHeld, "held"},
                                                     {kModeSameRooms, "same_rooms"},
                                                     {kModeAlike, "alike"},
                                                     {kModeBySlot, "by_slot"},
                                                     {kModeNearestLine, "nearest_line"},
                                                     {kModeOppositePairs, "opposite_pairs"}}};

struct Tuning {
  // Lanes wait for a new pixel until this many eighths of them do (packet.cpp's refill rule):
  // refilling costs a shading and a camera ray for the whole packet, waiting lanes idle. Set on 8
  // lanes (640x360, 2 cores, one run, ms at 2/8 -> 4/8): the analytic method's short rays gain
  // (cube 24.9 -> 20.4, double pentagon 13.8 -> 11.4, L-shape 8.9 -> 8.4), so does sphere tracing
  // in the cube (228 -> 183: rays refilled together start together in the camera's room), the
  // L-shape and the torus level; 5/8 lost 18% on the L-shape's sphere tracing, 1/8 spends more on
  // refills than it gains.
  int refill_at = 4;
  // The analytic method while its rays are spread over several rooms (a step's passes went over
  // more than two): refilled rays then start together in the camera's room, and the packet stays
  // in fewer rooms. Against 4/8 (AVX-512, 2 cores, best of 2): 32- and 128-square staircases
  // 27.0 -> 24.2 and 27.5 -> 24.6 ms, the gallery within 4%. Sphere tracing keeps refill_at: 6/8
  // gained a few percent on the 32-square staircase with lanes busy 0.96 -> 0.82, and lost 5-8%
  // on the 4-square staircase and the double pentagon.
  int refill_spread = 6;
  // In a scene of one room (for sphere and relaxed tracing, without mirrors; two rooms without
  // mirrors too), once this many steps have passed since the last refill the waiting lanes are
  // refilled however few: long rays (prisms: hundreds of steps) do not leave lanes idle. Against
  // none (AVX-512, 2 cores, best of 2): prisms 0.89-0.96x the time, lanes busy 0.78-0.86 ->
  // 0.86-0.99, the two-room scenes' analytic method 0.90-0.97x. In scenes of more rooms it made
  // sphere tracing on the cube 1.2x and on a 32-square staircase 1.8x slower (rays started apart
  // spread over more rooms a pass), and in mirror rooms 1.10-1.15x (a reflection takes a round
  // per mirror met): there it is not applied.
  int patience = 16;
  // Sphere and relaxed tracing in two rooms: at 16 steps they were 3-8% slower on the double
  // pentagon, its singularities and the pillowcase.
  int patience_two_rooms = 48;
  // A pass over several rooms looks each lane's edge up in at most this many vectors of the
  // scene's edges (Walls' kTable, 1 to lanes-inl.h's kLookUpVectors; beyond it, each room's record
  // is broadcast and blended by lane): sphere and relaxed tracing.
  int most_vectors = 2;
  // The same for the analytic method, whose rays cross at almost every step and whose whole
  // passes may find their exit by the nearest line where the edges are looked up (nearest_line).
  int most_vectors_analytic = 2;
  // A pass over the rays of several rooms whose edges are blended by lane takes at most this many
  // rooms (1 to lanes-inl.h's kRoomsPerPass, 8): more rooms a pass, fewer passes a step, each
  // dearer.
  int rooms_per_pass = 8;
  // Where a pass over several rooms looks their edges up in vectors (most_vectors), lanes hold
  // their rooms' edges all the same (kModeHeld): a load of a held edge against a lookup in one or
  // two vectors.
  bool held_over_lookup = true;
  // The modes (Mode, below) this instruction set may take: each where a scene allows it, its
  // fallback elsewhere. The nearest line's copy of the frame loop is compiled only where a row
  // takes it (compile time: a copy for every instruction set made packet.cpp's compile 196 ->
  // 256 s).
  uint32_t modes = kEveryMode & ~kModeNearestLine;
  constexpr bool takes(uint32_t mode) const { return (modes & mode) == mode; }
};

// The values, by instruction set. Each was measured on that instruction set, one thread unless
// said, on the project's 2-CPU AMD EPYC VMs (Zen 4 and Zen 5: both run AVX-512, so AVX2 and SSE4
// figures are an AVX-512 core's running those targets, not an AVX2-only CPU's). The first values
// came from AVX-512 (2 cores) and 8 lanes; issue 73 measured every one on each instruction set
// (Zen 5, `FLATMARCH_SIMD_TUNE` in a probe build, `bench/ab.py --pin 1`, best of 4-6 interleaved
// rounds, NOTES.md's *Tuned per instruction set*). This VM's single-thread figures move by up to
// 10% between runs, so a value changed only where the cases it governs moved together and the
// cases it cannot touch stayed level. Each mode was measured against its fallback again on an Intel
// Xeon (Emerald Rapids, 2026-12-06): each mode a row takes was level or faster there, and nothing
// measured there beyond that VM's noise argues for another value (NOTES.md).
//
// | value                 | avx512 | avx2 | sse4 | set by                                       |
// |-----------------------|--------|------|------|----------------------------------------------|
// | refill_at             | 4      | 4    | 4    | 3 and 5 slower on each: avx2 1.044 and 1.042 |
// |                       |        |      |      | (geometric means, 12 cases), sse4 1.073 and  |
// |                       |        |      |      | 1.038, avx512 1.04 both (NOTES.md)           |
// | refill_spread         | 6      | 6    | 6    | avx512 staircases; avx2 at 5: analytic cube  |
// |                       |        |      |      | 0.98, staircase 1.025 (level)                |
// | patience              | 16     | 16   | 16   | avx512 prisms; avx2 and sse4 at 8 and 32:    |
// |                       |        |      |      | within the noise, no case it governs moved   |
// |                       |        |      |      | apart from those it cannot                   |
// | patience_two_rooms    | 48     | 48   | 48   | avx512 double pentagon (16: 3-8% slower)     |
// | most_vectors          | 2      | 2    | 2    | avx2 at 3 (the cube's 24 edges looked up):   |
// |                       |        |      |      | relaxed cube 1.196, sphere 1.040; sse4 at 3  |
// |                       |        |      |      | (the double pentagon's 10): 1.10 sphere      |
// | most_vectors_analytic | 2      | 3    | 2    | avx2 at 3 with nearest_line: analytic cube   |
// |                       |        |      |      | 0.834, double pentagon 0.922 (best of 6);    |
// |                       |        |      |      | sse4 at 3 with it: 1.04 (7 of 12 slower)     |
// | rooms_per_pass        | 8      | 8    | 8    | avx512: 4 level, fewer lanes busy; sse4 at   |
// |                       |        |      |      | 1: analytic cube 1.139, double pentagon      |
// |                       |        |      |      | 0.919 (within the noise)                     |
//
// | held_over_lookup      | off    | on   | on   | avx512 off: lookups in one or two vectors    |
// |                       |        |      |      | 0.94-0.97x the time of held edges (sphere    |
// |                       |        |      |      | and relaxed: cube, pillowcase, double        |
// |                       |        |      |      | pentagon, two-room affine torus; best of 6), |
// |                       |        |      |      | controls 0.995-1.001                         |
//
// The modes (Mode), by instruction set: taken where the row has them and a scene allows, the
// fallback elsewhere. Each measured against its fallback on each instruction set (the probe,
// `bench/ab.py P P --base-env FLATMARCH_SIMD_TUNE=MODE=1 --new-env FLATMARCH_SIMD_TUNE=MODE=0
// --rounds 4 --pin 1`, one thread, Zen 5, 2026-12-05; the L-shape's one room as control, within 3%
// but where said): the time of the frames it governs without it over with it, avx512 / avx2 /
// sse4. A mode within 2% of its fallback on every instruction set measured goes.
//
// | mode           | avx512 | avx2 | sse4 | without it / with it                               |
// |----------------|--------|------|------|----------------------------------------------------|
// | whole          | on     | on   | on   | sphere: cube 1.32 / 1.35 / 1.35, double pentagon   |
// |                |        |      |      | 1.23 / 1.39 / 1.43, 32-square staircase 1.52 /     |
// |                |        |      |      | 1.30 / 1.26; analytic: cube 1.40 / 1.26 / 1.03,    |
// |                |        |      |      | double pentagon 1.18 / 1.22 / 0.98                 |
// | held           | on (a) | on   | on   | sphere: cube (a) / 1.35 / 1.33, double pentagon    |
// |                |        |      |      | (a) / 1.12 / 1.36; relaxed: cube (a) / 1.28 /      |
// |                |        |      |      | 1.28, double pentagon (a) / 1.08 / 1.42. (a): only |
// |                |        |      |      | where edges are not looked up (held_over_lookup)   |
// | same_rooms     | on     | on   | off  | 32-square staircase: sphere 1.08 (1.11 in a first  |
// |                |        |      |      | run) / 1.01 / 0.98, analytic 1.04 / 0.99 / 0.91.   |
// |                |        |      |      | sse4 off (best of 6): analytic staircases of 32    |
// |                |        |      |      | and 128 squares 0.907x the time, 4 squares 0.994,  |
// |                |        |      |      | sphere and relaxed 1.016-1.020, controls level     |
// | alike          | on     | on   | on   | analytic: cube 1.06 / 1.18 / 1.19, double pentagon |
// |                |        |      |      | 1.03 / 1.04 / 1.09 (controls 1.02-1.04); sphere:   |
// |                |        |      |      | cube 1.05 / 0.99 / 0.98 (a first run 1.07 / 1.03 / |
// |                |        |      |      | 1.06)                                              |
// | by_slot        | on     | on   | (b)  | analytic staircases of 32 and 128 squares 1.27-    |
// |                |        |      |      | 1.28 / 1.22-1.26. (b): SSE4's two vectors hold 8   |
// |                |        |      |      | tints, under the staircases' 10: never taken       |
// | nearest_line   | on     | on   | off  | analytic cube, double pentagon (2026-12-02, best   |
// |                |        |      |      | of 6): 1.02-1.06 / 1.20 and 1.08 (with             |
// |                |        |      |      | most_vectors_analytic 3) / 0.96 (7 of 12 cases     |
// |                |        |      |      | faster without); on an Intel Xeon 1.20 and 1.14 /  |
// |                |        |      |      | 1.12 and 1.19 / level (NOTES.md)                   |
// | opposite_pairs | on     | on   | -    | analytic cube 1.05 (control 1.03: level) / 1.08    |
// |                |        |      |      | (1.09 in a first run); taken with nearest_line     |
//
// And where the targets' instructions differ, each takes its own way (lanes-inl.h):
// - a lookup in two vectors: one `vpermt2ps` on AVX-512 (two and a blend for three or four); a
//   lookup in each (`vpermps` on AVX2, `pshufb` on SSE4) and a blend a vector elsewhere;
// - a lane's rank among the waiting lanes: one `vpexpandd` on AVX-512; a population count of the
//   mask's lower bits elsewhere (AVX2 and SSE4 have no compress or expand);
// - no gathers in a step but the gluing by slot's one (a gather is slow on every CPU measured:
//   6 ns for 16 lanes on Zen 5, and SSE4 has none): lookups in vectors or broadcasts blended by
//   lane instead; gluings by slot need the tints in two vectors (AVX-512, AVX2; SSE4's 4 lanes
//   hold 8, under the staircases' 10, and keep the rounds);
// - and one compile for all: packet.cpp at -O2 in every build (backends/CMakeLists.txt), since
//   -O3 took 1.14x the time on each of the three (24 cases, Zen 5; 1.01x, analytic 1.04-1.17x,
//   on a Zen 4's AVX-512).
// The rows: the defaults above where an instruction set keeps them, and what it sets apart.
inline constexpr std::array<Tuning, 3> kTunings{{
    {.held_over_lookup = false, .modes = kEveryMode},              // avx512
    {.most_vectors_analytic = 3, .modes = kEveryMode},             // avx2
    {.modes = kEveryMode & ~(kModeNearestLine | kModeSameRooms)},  // sse4
}};

// The tuning of `isa`: kTunings', or, in a build with FLATMARCH_SIMD_TUNING_PROBE defined (for
// measuring, never shipped), those values overridden by the environment's FLATMARCH_SIMD_TUNE,
// e.g. "refill_at=5,most_vectors=3" (every instruction set) or "avx2.refill_at=5".
#ifdef FLATMARCH_SIMD_TUNING_PROBE
Tuning tuning(Isa isa);
#else
constexpr Tuning tuning(Isa isa) {
  return kTunings[static_cast<size_t>(isa)];
}
#endif

// --isa's name of `isa`.
const char* isa_name(Isa isa);

}  // namespace flatmarch::simd
