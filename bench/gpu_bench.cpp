// The GPU backends, OpenGL (through EGL or OSMesa) and Vulkan (any device; here lavapipe), side
// by side: every gallery scene and method at 640x360 and 1920x1080 (BACKEND/METHOD/SCENE/WxH),
// a frame's fixed cost at each size (fixed/BACKEND/WxH: the L-shape at max_steps 0, no step
// marched: the pipeline, the camera rays, the shading and the read-back), and the original web
// app's benchmark views at 640x360 (peer/BACKEND/SCENE/METHOD). Given the
// app's shaders (--peer-shaders=DIR, regenerated as ../shared/peer-shaders.md says; or the
// environment's FLATMARCH_PEER_SHADERS), each view is also drawn by the app's own shader on the
// same OpenGL device (peer/app/SCENE), and every case of that view reports its speed-up over it
// as measured in this run (speedup_vs_app; app_ms, the app's median).
//
//   build/bench/gpu_bench --peer-shaders=DIR --benchmark_filter=peer/
//       --benchmark_repetitions=11 --benchmark_report_aggregates_only=true
//   build/bench/gpu_bench --benchmark_filter='^(opengl|vulkan)/analytic/l_shape/'
//
// llvmpipe and lavapipe use as many threads as there are cores unless LP_NUM_THREADS says
// otherwise. --device=D picks the device of both backends (an index or a part of its name, as
// `flatmarch backends` lists them), --kernel-shape=software|gpu their kernel's shape (default:
// by the device); every run is labelled with its device and shape. Timed frames are frames of the
// colour alone (Backend::render_colour), each also timed on the device: counters device_ms,
// march_ms, readback_ms and rest_ms (reports::DeviceTimes).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>

#include "backends/opengl/opengl.hpp"
#include "backends/vulkan/vulkan.hpp"
#include "bench/gallery.hpp"
#include "bench/peer_app.hpp"
#include "interop/peer_import.hpp"

namespace flatmarch::bench {

struct Size {
  int width, height;
};
constexpr Size kSizes[] = {{640, 360}, {1920, 1080}};

// The app's frame times per view in this run (ms, one a repetition), as peer/app/VIEW measures
// them; the median is what every other case of the view is compared with.
std::map<std::string, std::vector<double>> app_ms;

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

void frame(benchmark::State& state, const Backend* backend, const Scene* scene, Camera camera,
           MarchParams params, Size size, std::string view) {
  std::string label;
  if (const std::optional<DeviceInfo> d = backend->device()) label = reports::device_label(*d);
  // The first frames compile the scene's programs; they are not timed, and the counters are the
  // whole frame's. The timed ones are frames of the colour alone, as a user waits for them.
  const Frame whole = backend->render(*scene, camera, size.width, size.height, params, {});
  backend->render_colour(*scene, camera, size.width, size.height, params, {});
  reports::DeviceTimes device;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const Frame f = backend->render_colour(*scene, camera, size.width, size.height, params, {});
    benchmark::DoNotOptimize(f.srgb.data());
    device.add(*backend,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  if (!device.why().empty()) label += "; no device clock: " + device.why();
  state.SetLabel(label);
  bench::frame_counters(state, whole);
  device.counters(state);
  if (!view.empty() && !app_ms[view].empty()) {
    const double app = median(app_ms[view]);
    state.counters["app_ms"] = app;
    // The app's time per frame over ours.
    state.counters["speedup_vs_app"] =
        benchmark::Counter(app / 1000.0, benchmark::Counter::kIsIterationInvariantRate);
  }
}

void app_frame(benchmark::State& state, PeerApp* app, std::string id, std::string view, Size size) {
  state.SetLabel("device " + app->renderer() + "; the app's shader");
  try {
    app->frame(id, size.width, size.height);  // compiles the shader: not timed
    const auto start = std::chrono::steady_clock::now();
    for (auto _ : state) app->frame(id, size.width, size.height);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    app_ms[view].push_back(ms / static_cast<double>(state.iterations()));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

}  // namespace flatmarch::bench

int main(int argc, char** argv) {
  using namespace flatmarch;
  // Our own flags first: Google Benchmark reports flags it does not know.
  BackendOptions options;
  std::string peer_shaders =
      std::getenv("FLATMARCH_PEER_SHADERS") ? std::getenv("FLATMARCH_PEER_SHADERS") : "";
  const auto flags = bench::take_flags(argc, argv, {"device", "peer-shaders", "kernel-shape"});
  if (flags.count("device")) options.device = flags.at("device");
  if (flags.count("kernel-shape")) {
    options.kernel_shape = flags.at("kernel-shape");
    if (!parse_kernel_shape(options.kernel_shape, false)) {
      std::cerr << "gpu_bench: --kernel-shape=auto, software or gpu, not " << options.kernel_shape
                << "\n";
      return 2;
    }
  }
  if (flags.count("peer-shaders")) peer_shaders = flags.at("peer-shaders");
  if (!bench::begin(argc, argv)) return 2;
  const OpenGlBackend opengl(options);
  const VulkanBackend vulkan(options);
  std::vector<const Backend*> available;
  for (const Backend* b :
       {static_cast<const Backend*>(&opengl), static_cast<const Backend*>(&vulkan)})
    if (const Availability a = b->availability(); !a.available)
      std::cerr << "gpu_bench: the " << b->name()
                << " backend is unavailable here, skipped: " << a.reason << "\n";
    else
      available.push_back(b);
  if (available.empty()) return 0;
  for (const Backend* b : available) std::cerr << "gpu_bench: " << b->description() << "\n";
  std::unique_ptr<bench::PeerApp> app;
  if (peer_shaders.empty()) {
    std::cerr << "gpu_bench: no --peer-shaders: the app's views are timed without the app's own "
                 "shaders (../shared/peer-shaders.md says how to regenerate them)\n";
  } else {
    try {
      app = std::make_unique<bench::PeerApp>(peer_shaders, options.device);
      std::cerr << "gpu_bench: the app's shaders from " << peer_shaders << " on " << app->renderer()
                << "\n";
    } catch (const std::exception& e) {
      std::cerr << "gpu_bench: the app's shaders cannot be drawn, skipped: " << e.what() << "\n";
    }
  }
  const std::vector<std::unique_ptr<Scene>> scenes = bench::load_gallery();
  std::vector<std::unique_ptr<Scene>> peers;
  const bench::Size peer_size{640, 360};
  for (const bench::PeerView& view : bench::kPeerViews) {
    peers.push_back(std::make_unique<Scene>(bench::peer_scene(view)));
    if (app)
      bench::add(("peer/app/" + std::string(view.name)).c_str(), bench::app_frame, app.get(),
                 std::string(view.id), std::string(view.name), peer_size)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    for (const Backend* backend : available)
      for (Method method : kKernelMethods) {
        MarchParams params;
        params.method = method;
        bench::add(("peer/" + backend->name() + "/" + view.name + "/" + to_string(method)).c_str(),
                   bench::frame, backend, peers.back().get(), benchmark_view(peers.back()->camera),
                   params, peer_size, std::string(view.name))
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
      }
  }
  for (const bench::Size size : bench::kSizes)
    for (const auto& scene : scenes) {
      if (scene->name != "l_shape") continue;
      MarchParams params;
      params.method = Method::analytic;
      params.max_steps = 0;  // no step: what every frame costs before its march
      for (const Backend* backend : available)
        bench::add(("fixed/" + backend->name() + "/" + std::to_string(size.width) + "x" +
                    std::to_string(size.height))
                       .c_str(),
                   bench::frame, backend, scene.get(), scene->camera, params, size, std::string())
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    }
  for (const bench::Size size : bench::kSizes)
    for (Method method : kKernelMethods)
      for (const auto& scene : scenes)
        for (const Backend* backend : available) {
          MarchParams params;
          params.method = method;
          bench::add((backend->name() + "/" + to_string(method) + "/" + scene->name + "/" +
                      std::to_string(size.width) + "x" + std::to_string(size.height))
                         .c_str(),
                     bench::frame, backend, scene.get(), scene->camera, params, size, std::string())
              ->Unit(benchmark::kMillisecond)
              ->UseRealTime();
        }
  return bench::run();
}
