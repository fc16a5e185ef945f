// Rays per second and steps per ray of the kernel's backends, per gallery scene and method, at
// 320x180 from each scene's own camera. Steps are deterministic (a CI gate can trust them);
// time informs. Usage: kernel_bench [--benchmark_filter=REGEX] [--benchmark_format=json] ...
// Names are backend/method/precision/scene.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <numeric>

#include "backends/backend.hpp"
#include "scene/load.hpp"

namespace flatmarch {
namespace {

constexpr int kWidth = 320, kHeight = 180;

void render_scene(benchmark::State& state, const Backend* backend, const Scene* scene,
                  MarchParams params) {
  Frame frame;
  for (auto _ : state) {
    frame = backend->render(*scene, scene->camera, kWidth, kHeight, params, {});
    benchmark::DoNotOptimize(frame.rgb.data());
  }
  std::vector<float> steps = frame.steps;
  std::sort(steps.begin(), steps.end());
  const double pixels = static_cast<double>(steps.size());
  state.counters["rays_per_s"] =
      benchmark::Counter(pixels, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["steps_mean"] = std::accumulate(steps.begin(), steps.end(), 0.0) / pixels;
  state.counters["steps_p99"] = steps[static_cast<size_t>(0.99 * (pixels - 1))];
  state.counters["out_of_steps"] =
      static_cast<double>(std::count(frame.hit.begin(), frame.hit.end(), float(kHitMaxSteps))) /
      pixels;
}

}  // namespace
}  // namespace flatmarch

int main(int argc, char** argv) {
  using namespace flatmarch;
  namespace fs = std::filesystem;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;

  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(fs::path(FLATMARCH_SOURCE_DIR) / "scenes"))
    if (entry.path().extension() == ".json") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  std::vector<std::unique_ptr<Scene>> scenes;
  for (const fs::path& f : files) scenes.push_back(std::make_unique<Scene>(load_scene(f)));

  for (const auto& backend : backends()) {
    if (backend->name() == "oracle") continue;  // not a kernel backend
    const Availability a = backend->availability();
    if (!a.available) {
      std::cerr << "skipping backend " << backend->name() << ": " << a.reason << "\n";
      continue;
    }
    for (Method method : backend->methods())
      for (const auto& scene : scenes) {
        MarchParams params;
        params.method = method;
        const std::string name = backend->name() + "/" + to_string(method) + "/f32/" + scene->name;
        benchmark::RegisterBenchmark(name.c_str(), render_scene, backend.get(), scene.get(), params)
            ->Unit(benchmark::kMillisecond);
      }
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
