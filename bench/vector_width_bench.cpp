// How many float additions one core does a second in vectors of 128, 256 and 512 bits: whether
// this CPU runs a 512-bit operation at once or as two 256-bit halves. On the second kind (AMD Zen
// 4) AVX-512's 16 lanes do about the work of AVX2's 8, and the SIMD backend's ceiling over one
// scalar core is about 8 lanes a core; on the first (AMD Zen 5 server parts, Intel's server
// parts) it is 16. The SIMD backend's own speed-ups are measured by simd_bench; this says what
// they are measured against.
//
//   vector_width_bench        # lane_adds_per_s per width; the ratio of two is the answer
//
// Names: width/BITS. Widths this CPU lacks are skipped, with a line on stderr.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <iostream>

#if defined(__x86_64__)
namespace {

// Independent additions in flight: more than an adder's latency times the adders a core has, so
// that throughput, not latency, bounds the loop; and few enough to stay in SSE's 16 registers.
constexpr int kChains = 12;

// `rounds` rounds of kChains additions in vectors of type V (GCC's vector extensions, lowered to
// the instruction set of the function it is inlined in), each chain a dependency of its own;
// returns part of their sum. The loops are unrolled so that the chains stay in registers, and
// each sum is made opaque to the compiler (an empty asm), which would otherwise fold additions
// that round to nothing.
template <typename V>
[[gnu::always_inline]] inline float adds(int64_t rounds) {
  V acc[kChains];
  const V step = V{} + 1e-9f;
#pragma GCC unroll 12
  for (int c = 0; c < kChains; ++c) acc[c] = V{} + static_cast<float>(c);
  for (int64_t r = 0; r < rounds; ++r) {
#pragma GCC unroll 12
    for (int c = 0; c < kChains; ++c) {
      acc[c] = acc[c] + step;
      __asm__ volatile("" : "+x"(acc[c]));
    }
  }
  V sum = acc[0];
#pragma GCC unroll 12
  for (int c = 1; c < kChains; ++c) sum = sum + acc[c];
  return sum[0];
}

using V4 = float __attribute__((vector_size(16)));
using V8 = float __attribute__((vector_size(32)));
using V16 = float __attribute__((vector_size(64)));

float adds_128(int64_t rounds) {  // SSE2: every x86-64 CPU has it
  return adds<V4>(rounds);
}
__attribute__((target("avx2"))) float adds_256(int64_t rounds) {
  return adds<V8>(rounds);
}
__attribute__((target("avx512f"))) float adds_512(int64_t rounds) {
  return adds<V16>(rounds);
}

void width(benchmark::State& state, float (*adds)(int64_t), int lanes) {
  constexpr int64_t kRounds = 1 << 20;
  for (auto _ : state) benchmark::DoNotOptimize(adds(kRounds));
  state.counters["lane_adds_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * kRounds * kChains * lanes,
                         benchmark::Counter::kIsRate);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  __builtin_cpu_init();
  benchmark::RegisterBenchmark("width/128", width, adds_128, 4);
  if (__builtin_cpu_supports("avx2"))
    benchmark::RegisterBenchmark("width/256", width, adds_256, 8);
  else
    std::cerr << "vector_width_bench: width/256 skipped: this CPU has no AVX2\n";
  if (__builtin_cpu_supports("avx512f"))
    benchmark::RegisterBenchmark("width/512", width, adds_512, 16);
  else
    std::cerr << "vector_width_bench: width/512 skipped: this CPU has no AVX-512\n";
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

#else

int main() {
  std::cerr << "vector_width_bench: measures x86-64 vector widths only; nothing to do here\n";
  return 0;
}

#endif
