// Rays per second and steps per ray of the kernel's backends, per gallery scene and method, at
// 320x180 from each scene's own camera. Steps are deterministic (a CI gate can trust them);
// time informs. Usage: kernel_bench [--benchmark_filter=REGEX] [--benchmark_format=json] ...
// Names are backend/method/precision/scene, and specialisation/method/torus/{specialised,generic}.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <numeric>

#include "backends/backend.hpp"
#include "bench/gallery.hpp"
#include "kernels/camera.hpp"
#include "kernels/compile.hpp"
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
  bench::frame_counters(state, frame);
}

// The torus's feature set (kernels/compile.cpp, scene_features: its hollow cube),
// and that set with the features it does not use switched on: code paths that change nothing on
// the torus (no solids besides its cube, no mirrors, walls or scaling) but a generic kernel
// would carry. Compared with the specialised kernel, it shows what specialisation saves. Bound
// to these two sets alone (kernel::bind_kernel): kernel::with_kernel would compile all 64 here.
constexpr uint kTorusFeatures = kFeatureObjects;
constexpr uint kTorusGeneric = kTorusFeatures | kFeatureMirrors | kFeatureWalls | kFeatureScaled;

template <uint kFeatures>
void extra_features(benchmark::State& state, const Scene* scene, Method method) {
  MarchParams params;
  params.method = method;
  kernel::SceneTables<float> tables = kernel::compile_scene<float>(*scene, params);
  if (tables.features != kTorusFeatures) {
    state.SkipWithError(("the torus's feature set is " + std::to_string(tables.features) +
                         " now, not the " + std::to_string(kTorusFeatures) +
                         " this benchmark is built for (bench/kernel_bench.cpp)")
                            .c_str());
    return;
  }
  tables.features = kFeatures;
  auto k = kernel::bind_kernel<float, kFeatures>(tables);
  const Camera& c = scene->camera;
  const CameraBasis<float> basis =
      camera_basis<float>(float(c.yaw_deg), float(c.pitch_deg), float(c.fov_deg), kWidth, kHeight);
  double steps = 0.0;
  for (auto _ : state) {
    steps = 0.0;
    for (int j = 0; j < kHeight; ++j)
      for (int i = 0; i < kWidth; ++i) {
        const auto r =
            k.march(c.polygon, glm::vec3(c.position), camera_ray(basis, i, j, kWidth, kHeight));
        benchmark::DoNotOptimize(k.shade(r));
        steps += r.steps;
      }
  }
  const double pixels = double(kWidth) * kHeight;
  state.counters["rays_per_s"] =
      benchmark::Counter(pixels, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["steps_mean"] = steps / pixels;
}

}  // namespace
}  // namespace flatmarch

int main(int argc, char** argv) {
  using namespace flatmarch;
  if (!bench::begin(argc, argv)) return 2;

  const std::vector<std::unique_ptr<Scene>> scenes = bench::load_gallery();

  for (const auto& backend : backends()) {
    if (backend->name() == "oracle") continue;  // not a kernel backend
    std::vector<std::string> names;
    for (Method method : backend->methods())
      for (const auto& scene : scenes)
        names.push_back(backend->name() + "/" + to_string(method) + "/f32/" + scene->name);
    if (!bench::selects_any(names)) continue;  // not started for nothing
    const Availability a = backend->availability();
    if (!a.available) {
      std::cerr << "skipping backend " << backend->name() << ": " << a.reason << "\n";
      continue;
    }
    size_t k = 0;
    for (Method method : backend->methods())
      for (const auto& scene : scenes) {
        MarchParams params;
        params.method = method;
        bench::add(names[k++], render_scene, backend.get(), scene.get(), params)
            ->Unit(benchmark::kMillisecond);
        bench::cost(reports::frame_cost(backend->name(), to_string(method), kWidth, kHeight));
      }
  }
  for (const auto& scene : scenes) {
    if (scene->name != "torus") continue;
    for (Method method : {Method::sphere, Method::analytic}) {
      const std::string m = to_string(method);
      bench::add(("specialisation/" + m + "/torus/specialised").c_str(),
                 extra_features<kTorusFeatures>, scene.get(), method)
          ->Unit(benchmark::kMillisecond);
      bench::add(("specialisation/" + m + "/torus/generic").c_str(), extra_features<kTorusGeneric>,
                 scene.get(), method)
          ->Unit(benchmark::kMillisecond);
    }
  }
  return bench::run();
}
