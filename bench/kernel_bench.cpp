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

// The kernel on a scene's tables with extra features switched on: code paths the scene does not
// use (solids, mirrors, walls, scaling change nothing on a scene without them) but a generic
// kernel would carry. Compared with the specialised kernel, it shows what specialisation saves.
void extra_features(benchmark::State& state, const Scene* scene, Method method, uint extra) {
  MarchParams params;
  params.method = method;
  kernel::SceneTables<float> tables = kernel::compile_scene<float>(*scene, params);
  tables.features |= extra;
  const Camera& c = scene->camera;
  const CameraBasis<float> basis =
      camera_basis<float>(float(c.yaw_deg), float(c.pitch_deg), float(c.fov_deg), kWidth, kHeight);
  double steps = 0.0;
  for (auto _ : state) {
    steps = 0.0;
    kernel::with_kernel<float>(tables, [&](auto& k) {
      for (int j = 0; j < kHeight; ++j)
        for (int i = 0; i < kWidth; ++i) {
          const auto r =
              k.march(c.polygon, glm::vec3(c.position), camera_ray(basis, i, j, kWidth, kHeight));
          benchmark::DoNotOptimize(k.shade(r));
          steps += r.steps;
        }
    });
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
        bench::add(name.c_str(), render_scene, backend.get(), scene.get(), params)
            ->Unit(benchmark::kMillisecond);
        bench::cost(reports::frame_cost(backend->name(), to_string(method), kWidth, kHeight));
      }
  }
  for (const auto& scene : scenes) {
    if (scene->name != "torus") continue;
    const uint unused = kFeatureObjects | kFeatureMirrors | kFeatureWalls | kFeatureScaled;
    for (Method method : {Method::sphere, Method::analytic})
      for (const auto& [label, extra] :
           {std::pair{"specialised", 0u}, std::pair{"generic", unused}})
        bench::add(("specialisation/" + std::string(to_string(method)) + "/torus/" + label).c_str(),
                   extra_features, scene.get(), method, extra)
            ->Unit(benchmark::kMillisecond);
  }
  return bench::run();
}
