// The OpenGL backend (OSMesa; llvmpipe here) at 640x360: every gallery scene and method, and the
// original web app's benchmark views (issue 5), where each case also reports its speed-up over
// the app's own shader as measured on this machine kind.
//
//   build/bench/opengl_bench --benchmark_filter=peer/ --benchmark_repetitions=11
//       --benchmark_report_aggregates_only=true
//
// llvmpipe uses as many threads as there are cores unless LP_NUM_THREADS says otherwise; the app's
// figures were measured with LP_NUM_THREADS=2.
#include <cmath>
#include <iostream>

#include "backends/opengl/opengl.hpp"
#include "bench/gallery.hpp"
#include "scene/peer_import.hpp"

namespace flatmarch {
namespace {

constexpr int kWidth = 640, kHeight = 360;

const OpenGlBackend& opengl() {
  static const OpenGlBackend backend;
  return backend;
}

void frame(benchmark::State& state, const Scene* scene, Camera camera, MarchParams params,
           double peer_ms) {
  // The first frame compiles the scene's program; it is not timed.
  Frame f = opengl().render(*scene, camera, kWidth, kHeight, params, {});
  for (auto _ : state) {
    f = opengl().render(*scene, camera, kWidth, kHeight, params, {});
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
  if (!bench::begin(argc, argv)) return 2;
  if (const Availability a = opengl().availability(); !a.available) {
    std::cerr << "opengl_bench: the opengl backend is unavailable here: " << a.reason << "\n";
    return 0;
  }
  std::cerr << "opengl_bench: " << opengl().renderer() << "\n";
  const std::vector<std::unique_ptr<Scene>> scenes = bench::load_gallery();
  std::vector<std::unique_ptr<Scene>> peers;
  for (const PeerView& view : kPeerViews) {
    const PeerImport imported = import_peer_file(std::filesystem::path(FLATMARCH_SOURCE_DIR) /
                                                 "tests" / "data" / "peer-geometries" / view.file);
    peers.push_back(std::make_unique<Scene>(scene_from_json(imported.scene, view.file)));
    for (Method method : {Method::sphere, Method::relaxed, Method::analytic}) {
      MarchParams params;
      params.method = method;
      benchmark::RegisterBenchmark(
          (std::string("peer/") + view.name + "/" + to_string(method)).c_str(), frame,
          peers.back().get(), peer_camera(*peers.back()), params, view.peer_ms)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    }
  }
  for (Method method : {Method::sphere, Method::relaxed, Method::analytic})
    for (const auto& scene : scenes) {
      MarchParams params;
      params.method = method;
      benchmark::RegisterBenchmark(
          (std::string("opengl/") + to_string(method) + "/" + scene->name).c_str(), frame,
          scene.get(), scene->camera, params, 0.0)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
