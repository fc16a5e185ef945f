// Every backend x method x gallery scene (the oracle too: what the truth costs), from the
// scene's own camera (BACKEND/METHOD/SCENE/WxH, 640x360 by default): rays_per_s, steps_mean,
// steps_p99, crossings_mean, out_of_steps, and lane_utilisation for the SIMD backend. The JSON
// output (--benchmark_out=FILE --benchmark_out_format=json) carries the machine's fingerprint in
// its context; `flatmarch report` writes the same cases. Unavailable backends are skipped, with
// the reason, on stderr.
//
//   build/bench/backend_bench --benchmark_filter='^simd/analytic/' --benchmark_repetitions=5
//   build/bench/backend_bench --size=320x180 --benchmark_out=bench.json
#include <cstdio>
#include <iostream>

#include "bench/gallery.hpp"
#include "reports/fingerprint.hpp"
#include "reports/matrix.hpp"

int main(int argc, char** argv) {
  using namespace flatmarch;
  // Our own flag first: Google Benchmark reports flags it does not know.
  int width = 640, height = 360;
  const auto flags = bench::take_flags(argc, argv, {"size"});
  if (flags.count("size") && !bench::parse_size(flags.at("size"), width, height)) {
    std::cerr << "backend_bench: --size=WxH, each 1 to 8192\n";
    return 2;
  }
  if (!bench::begin(argc, argv)) return 2;
  reports::add_to_benchmark_context(reports::hardware_fingerprint());
  const std::vector<std::unique_ptr<Scene>> scenes = bench::load_gallery();
  std::vector<std::unique_ptr<Backend>> available;
  for (const std::string& name : backend_names()) {
    std::unique_ptr<Backend> b = make_backend(name, {});
    std::vector<std::string> names;  // as Google Benchmark names them: manual time
    for (Method method : b->methods())
      for (const auto& scene : scenes)
        names.push_back(reports::case_name(name, method, scene->name, width, height) +
                        "/manual_time");
    if (!bench::selects_any(names)) continue;  // not started for nothing
    if (const Availability a = b->availability(); !a.available)
      std::cerr << "backend_bench: the " << name
                << " backend is unavailable here, skipped: " << a.reason << "\n";
    else
      available.push_back(std::move(b));
  }
  for (const auto& backend : available)
    for (Method method : backend->methods())
      for (const auto& scene : scenes) {
        MarchParams params;
        params.method = method;
        reports::register_frame_benchmark(*backend, *scene, scene->camera, params, width, height, 0,
                                          0.0);
        bench::note(reports::case_name(backend->name(), method, scene->name, width, height));
        bench::cost(reports::frame_cost(backend->name(), to_string(method), width, height));
      }
  return bench::run();
}
