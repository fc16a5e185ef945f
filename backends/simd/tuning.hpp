// The SIMD backend's choices per instruction set, in one place: every threshold the packet code
// (packet.cpp and its *-inl.h) tunes, and the strategy each target takes where its instructions
// differ. Each value was set by runs on that instruction set; the table below says which, and
// backends/simd/NOTES.md (*Tuned per instruction set*) has the figures. A machine with AVX-512 runs
// its AVX2 and SSE4 targets too, but its cores execute them unlike an AVX2-only CPU: where a value
// was measured on such a machine alone, the table says so.
#pragma once

#include <array>
#include <string>

namespace flatmarch::simd {

enum class Isa { avx512, avx2, sse4 };

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
  // The analytic method's whole passes over convex rooms not alike find their exit by the nearest
  // line first (nearest-inl.h), in a copy of the frame loop of its own, compiled only where this
  // is set (compile time: a copy for every instruction set made packet.cpp's compile 196 -> 256 s).
  bool nearest_line = false;
};

// The values, by instruction set. Each was measured on that instruction set, one thread unless
// said, on the project's 2-CPU AMD EPYC VMs (Zen 4 and Zen 5: both run AVX-512, so AVX2 and SSE4
// figures are an AVX-512 core's running those targets, not an AVX2-only CPU's). The first values
// came from AVX-512 (2 cores) and 8 lanes; issue 73 measured every one on each instruction set
// (Zen 5, `FLATMARCH_SIMD_TUNE` in a probe build, `bench/ab.py --pin 1`, best of 4-6 interleaved
// rounds, NOTES.md's *Tuned per instruction set*). This VM's single-thread figures move by up to
// 10% between runs, so a value changed only where the cases it governs moved together and the
// cases it cannot touch stayed level.
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
// | nearest_line          | on     | on   | -    | avx512: cube, double pentagon 0.94-0.98x;    |
// |                       |        |      |      | avx2 alone (most_vectors_analytic 2): double |
// |                       |        |      |      | pentagon 0.911, with 3 above                 |
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
    {.nearest_line = true},                              // avx512
    {.most_vectors_analytic = 3, .nearest_line = true},  // avx2
    {},                                                  // sse4
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
