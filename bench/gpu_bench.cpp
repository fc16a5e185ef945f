// The GPU backends, OpenGL (OSMesa) and Vulkan (any device; here lavapipe), side by side: every
// gallery scene and method at 640x360 and 1920x1080 (BACKEND/METHOD/SCENE/WIDTHxHEIGHT), and the
// original web app's benchmark views at 640x360 (peer/BACKEND/SCENE/METHOD), where each case also
// reports its speed-up over the app's own shader as measured on this machine kind.
//
//   build/bench/gpu_bench --benchmark_filter=peer/opengl/ --benchmark_repetitions=11
//       --benchmark_report_aggregates_only=true
//   build/bench/gpu_bench --benchmark_filter='^(opengl|vulkan)/analytic/l_shape/'
//
// llvmpipe and lavapipe use as many threads as there are cores unless LP_NUM_THREADS says
// otherwise; the app's figures were measured with LP_NUM_THREADS=2. --device picks the Vulkan
// device (an index or a part of its name, as `flatmarch backends` lists them).
#include <cmath>
#include <iostream>

#include "backends/opengl/opengl.hpp"
#include "backends/vulkan/vulkan.hpp"
#include "bench/gallery.hpp"
#include "scene/peer_import.hpp"

namespace flatmarch {
namespace {

struct Size {
  int width, height;
};
constexpr Size kSizes[] = {{640, 360}, {1920, 1080}};

void frame(benchmark::State& state, const Backend* backend, const Scene* scene, Camera camera,
           MarchParams params, Size size, double peer_ms) {
  // The first frame compiles the scene's program; it is not timed.
  Frame f = backend->render(*scene, camera, size.width, size.height, params, {});
  for (auto _ : state) {
    f = backend->render(*scene, camera, size.width, size.height, params, {});
    benchmark::DoNotOptimize(f.rgb.data());
  }
  bench::frame_counters(state, f);
  if (peer_ms > 0.0) {
    state.counters["peer_ms"] = peer_ms;
    // The app's time per frame over ours.
    state.counters["speedup_vs_peer"] =
        benchmark::Counter(peer_ms / 1000.0, benchmark::Counter::kIsIterationInvariantRate);
  }
}

// The app's benchmark views, with its frame times on this machine kind (Mesa 22.3 llvmpipe,
// LP_NUM_THREADS=2, 640x360, median of 11 frames, its shaders unchanged; issue 5).
struct PeerView {
  const char* file;  // in tests/data/peer-geometries
  const char* name;
  double peer_ms;
};
constexpr PeerView kPeerViews[] = {{"L_shape.json", "l_shape", 241.0},
                                   {"DoublePentagonTranslation.json", "double_pentagon", 473.0},
                                   {"torus.json", "torus", 352.0},
                                   {"L_shapePrism.json", "l_shape_prism", 1116.0},
                                   {"equilateralTriangle.json", "equilateral_triangle", 1929.0},
                                   {"irrationalTriangle.json", "triangle_1rad", 1992.0},
                                   {"cube.json", "cube", 4226.0}};

// The app's view: from its start point + (0.5, 0, 0.5), looking along normalize(1, 0, 0.3) in its
// coordinates (y up). The importer maps its (x, y, z) to our (x, z, y + wall height) and its
// field of view to ours, so the view is the scene's camera moved by (0.5, 0.5, 0) and turned to
// yaw atan2(0.3, 1), level. (Our image is the app's mirrored left to right: the same rays.)
Camera peer_camera(const Scene& scene) {
  Camera camera = scene.camera;
  camera.position += Vec3(0.5, 0.5, 0.0);
  camera.yaw_deg = glm::degrees(std::atan2(0.3, 1.0));
  camera.pitch_deg = 0.0;
  return camera;
}

}  // namespace
}  // namespace flatmarch

int main(int argc, char** argv) {
  using namespace flatmarch;
  // Our own flag first: Google Benchmark reports flags it does not know.
  BackendOptions vulkan_options;
  for (int k = 1; k < argc; ++k)
    if (std::string(argv[k]).rfind("--device=", 0) == 0) {
      vulkan_options.device = std::string(argv[k]).substr(9);
      std::copy(argv + k + 1, argv + argc + 1, argv + k);
      --argc;
      break;
    }
  if (!bench::begin(argc, argv)) return 2;
  const OpenGlBackend opengl;
  const VulkanBackend vulkan(vulkan_options);
  std::vector<const Backend*> available;
  for (const Backend* b :
       {static_cast<const Backend*>(&opengl), static_cast<const Backend*>(&vulkan)})
    if (const Availability a = b->availability(); !a.available)
      std::cerr << "gpu_bench: the " << b->name()
                << " backend is unavailable here, skipped: " << a.reason << "\n";
    else
      available.push_back(b);
  if (available.empty()) return 0;
  if (!opengl.renderer().empty()) std::cerr << "gpu_bench: opengl on " << opengl.renderer() << "\n";
  if (vulkan.availability().available) std::cerr << "gpu_bench: " << vulkan.description() << "\n";
  const std::vector<std::unique_ptr<Scene>> scenes = bench::load_gallery();
  std::vector<std::unique_ptr<Scene>> peers;
  for (const PeerView& view : kPeerViews) {
    const PeerImport imported = import_peer_file(std::filesystem::path(FLATMARCH_SOURCE_DIR) /
                                                 "tests" / "data" / "peer-geometries" / view.file);
    peers.push_back(std::make_unique<Scene>(scene_from_json(imported.scene, view.file)));
    for (const Backend* backend : available)
      for (Method method : {Method::sphere, Method::relaxed, Method::analytic}) {
        MarchParams params;
        params.method = method;
        benchmark::RegisterBenchmark(
            ("peer/" + backend->name() + "/" + view.name + "/" + to_string(method)).c_str(), frame,
            backend, peers.back().get(), peer_camera(*peers.back()), params, Size{640, 360},
            view.peer_ms)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
      }
  }
  for (const Size size : kSizes)
    for (Method method : {Method::sphere, Method::relaxed, Method::analytic})
      for (const auto& scene : scenes)
        for (const Backend* backend : available) {
          MarchParams params;
          params.method = method;
          benchmark::RegisterBenchmark(
              (backend->name() + "/" + to_string(method) + "/" + scene->name + "/" +
               std::to_string(size.width) + "x" + std::to_string(size.height))
                  .c_str(),
              frame, backend, scene.get(), scene->camera, params, size, 0.0)
              ->Unit(benchmark::kMillisecond)
              ->UseRealTime();
        }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
