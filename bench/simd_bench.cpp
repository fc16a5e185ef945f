// The SIMD backend at 640x360 from each scene's own camera: rays per second and lane utilisation
// (active lanes over lanes, summed over every pass of every packet step), per gallery scene and
// method, on all cores with the best instruction set here, and on staircases of 4, 32 and 128
// squares (scene/surfaces.hpp; rays run to max_distance 40), where rays spread over many rooms,
// and of 32 and 128 squares drawn apart (staircase_apart_N: rooms that differ in coordinates).
// For the L-shape, the double pentagon, the cube and the 32-square staircase it also runs, side by
// side in one run, the scalar backend and every instruction set on one thread and on all cores:
// bench/speedups.py turns the JSON into the ratios (SIMD over scalar on one thread per lane, the
// lane efficiency; all cores over scalar; all cores over one thread). The staircases' analytic
// method also runs every instruction set on one thread: whether time per ray stays flat from 4 to
// 128 squares depends on the vector width (crossings by slot need the tints in one or two
// vectors).
//
//   simd_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//              --benchmark_out=simd.json --benchmark_out_format=json   (one line)
//   python3 bench/speedups.py simd.json
//
// Names: scalar/METHOD/SCENE and simd/METHOD/SCENE/ISA/threads:N.
#include <benchmark/benchmark.h>

#include <oneapi/tbb/info.h>

#include <algorithm>
#include <iostream>
#include <iterator>
#include <string>

#include "backends/scalar/scalar.hpp"
#include "backends/simd/simd.hpp"
#include "bench/gallery.hpp"
#include "scene/surfaces.hpp"

namespace flatmarch {
namespace {

constexpr int kWidth = 640, kHeight = 360;
// The scenes timed beside the scalar backend, on one thread and on all cores in every instruction
// set: issue 73's lane efficiency (bench/speedups.py) is taken on these.
constexpr const char* kCompared[] = {"l_shape", "double_pentagon", "cube", "staircase_32"};

void simd_frame(benchmark::State& state, const Scene* scene, MarchParams params,
                BackendOptions options) {
  const SimdBackend simd(options);
  Frame frame;
  simd::LaneCounts lanes;
  for (auto _ : state) {
    lanes = {};
    frame = simd.render_counted(*scene, scene->camera, kWidth, kHeight, params, {}, lanes);
    benchmark::DoNotOptimize(frame.rgb.data());
  }
  bench::frame_counters(state, frame);
  reports::lane_counters(
      state, frame,
      {.lanes = simd.lanes(),
       .active = lanes.active,
       .slots = lanes.slots,
       .peak_steps_per_s = simd.peak_lane_steps(*scene, scene->camera, kWidth, kHeight, params)});
  state.counters["lanes"] = simd.lanes();
}

// The march parameters of a case: the defaults with `method`; staircases' rays run to
// max_distance 40 (they never meet anything).
MarchParams case_params(const Scene& scene, Method method) {
  MarchParams params;
  params.method = method;
  if (scene.name.rfind("staircase_", 0) == 0) params.max_distance = 40.0;
  return params;
}

void scalar_frame(benchmark::State& state, const Scene* scene, MarchParams params) {
  const ScalarBackend scalar;
  Frame frame;
  for (auto _ : state) {
    frame = scalar.render(*scene, scene->camera, kWidth, kHeight, params, {});
    benchmark::DoNotOptimize(frame.rgb.data());
  }
  bench::frame_counters(state, frame);
}

}  // namespace
}  // namespace flatmarch

int main(int argc, char** argv) {
  using namespace flatmarch;
  if (!bench::begin(argc, argv)) return 2;

  std::vector<std::unique_ptr<Scene>> scenes = bench::load_gallery();
  for (int squares : {4, 32, 128})  // named staircase_N
    scenes.push_back(std::make_unique<Scene>(staircase_surface(squares)));
  // The same surface with its squares drawn apart (rooms that differ in their coordinates):
  // staircase_apart_N.
  for (int squares : {32, 128})
    scenes.push_back(std::make_unique<Scene>(staircase_surface(squares, true)));
  const std::vector<std::string> isas = simd::isa_names(true);
  const int cores = tbb::info::default_concurrency();
  std::cerr << "simd_bench: " << cores << " cores; instruction sets here:";
  for (const std::string& isa : isas) std::cerr << " " << isa;
  std::cerr << "\n";

  const auto simd_case = [&](const Scene* scene, Method method, const std::string& isa,
                             int threads) {
    const MarchParams params = case_params(*scene, method);
    const std::string name = std::string("simd/") + to_string(method) + "/" + scene->name + "/" +
                             isa + "/threads:" + std::to_string(threads);
    BackendOptions options;
    options.isa = isa;
    options.threads = threads;
    bench::add(name.c_str(), simd_frame, scene, params, options)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  };
  for (Method method : kKernelMethods) {
    for (const auto& scene : scenes) {
      const bool compared =
          std::find(std::begin(kCompared), std::end(kCompared), scene->name) != std::end(kCompared);
      if (compared) {
        bench::add((std::string("scalar/") + to_string(method) + "/" + scene->name).c_str(),
                   scalar_frame, scene.get(), case_params(*scene, method))
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
      }
      const bool staircase = scene->name.rfind("staircase_", 0) == 0;
      if (compared || (staircase && method == Method::analytic))
        for (const std::string& isa : isas) simd_case(scene.get(), method, isa, 1);
      // The compared scenes on all cores in every instruction set (how each scales); the rest
      // in the best.
      if (compared && cores > 1)
        for (const std::string& isa : isas) simd_case(scene.get(), method, isa, cores);
      else if (!compared)
        simd_case(scene.get(), method, isas.front(), cores);
    }
  }
  return bench::run();
}
