// The browser as a measured platform (issue 23): the original web app's benchmark views drawn in
// one headless Chromium by the app's own shaders and by our exported pages' shaders, same view,
// same size, on the page's canvas as a visitor sees them (web/peer/app/VIEW and
// web/peer/webgl/VIEW/METHOD); each of ours reports its speed-up over the app's in this run
// (speedup_vs_app; app_ms, the app's median). The app's shaders are not ours to ship: given
// --peer-shaders=DIR (regenerated as ../shared/peer-shaders.md says; or FLATMARCH_PEER_SHADERS)
// they run as three.js runs a ShaderMaterial in WebGL2, with a GLSL ES 3.00 header. Frames are
// timed by the page's clock, a one-pixel read waiting for each, not the DevTools round trip.
//
//   build/bench/web_bench --peer-shaders=DIR --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
//
// --device=D as the webgl backend's (gpu, swiftshader; default: Chromium's choice); --size=WxH
// (default 640x360). Without Chromium it says so and exits 77.
#include <stdlib.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include <nlohmann/json.hpp>

#include "backends/webgl/chromium.hpp"
#include "bench/gallery.hpp"
#include "bench/peer_app.hpp"
#include "interop/peer_import.hpp"
#include "scene/inspect.hpp"
#include "web/page.hpp"

namespace flatmarch::bench {

using nlohmann::json;

struct Size {
  int width = 640, height = 360;
};

// What every case shares: the browser, the views' pages and the app's times in this run.
struct Web {
  std::unique_ptr<webgl::Chromium> browser;
  std::filesystem::path folder;
  std::string open_page;                              // the file open now
  std::map<std::string, std::vector<double>> app_ms;  // per view, one a repetition
  std::string label;

  ~Web() {
    browser.reset();
    std::error_code ignored;
    if (!folder.empty()) std::filesystem::remove_all(folder, ignored);
  }
  // Opened as a page of one pixel's frame (?frame=1x1): it compiles the page's shader and draws
  // that pixel, where the interactive page would draw the window's size first, in software here
  // (the smoke test's run: 31 s -> 6.5 s). The timed frames set their own size.
  void open(const std::string& page) {
    if (page == open_page) return;
    browser->navigate("file://" + page + "?frame=1x1");
    open_page = page;
  }
  // One frame timed by the page (flatmarchTimeFrames, web/page.js): its seconds.
  double frame(const json& request) {
    return browser->evaluate("flatmarchTimeFrames(" + request.dump() + ")", 600.0)
               .at(0)
               .get<double>() /
           1000.0;
  }
};

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

void timed(benchmark::State& state, Web* web, const std::string& page, const json& request) {
  state.SetLabel(web->label);
  try {
    web->open(page);
    web->frame(request);  // compiles the shader: not timed
    for (auto _ : state) state.SetIterationTime(web->frame(request));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

void ours(benchmark::State& state, Web* web, std::string page, json request, std::string view) {
  timed(state, web, page, request);
  if (!web->app_ms[view].empty() && state.iterations() > 0) {
    const double app = median(web->app_ms[view]);
    state.counters["app_ms"] = app;
    // The app's time per frame over ours.
    state.counters["speedup_vs_app"] =
        benchmark::Counter(app / 1000.0, benchmark::Counter::kIsIterationInvariantRate);
  }
}

void app(benchmark::State& state, Web* web, std::string page, json request, std::string view) {
  state.SetLabel(web->label + "; the app's shader");
  try {
    web->open(page);
    web->frame(request);
    double seconds = 0.0;
    for (auto _ : state) {
      const double s = web->frame(request);
      state.SetIterationTime(s);
      seconds += s;
    }
    web->app_ms[view].push_back(1000.0 * seconds / static_cast<double>(state.iterations()));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

// The app's shader as three.js hands a ShaderMaterial's to WebGL2: GLSL ES 3.00, gl_FragColor an
// output.
std::string app_fragment(const std::string& source) {
  return "#version 300 es\nprecision highp float;\nprecision highp int;\n"
         "out highp vec4 pc_fragColor;\n#define gl_FragColor pc_fragColor\n" +
         source;
}

}  // namespace flatmarch::bench

int main(int argc, char** argv) {
  using namespace flatmarch;
  std::string device;
  std::string peer_shaders =
      std::getenv("FLATMARCH_PEER_SHADERS") ? std::getenv("FLATMARCH_PEER_SHADERS") : "";
  bench::Size size;
  const auto flags = bench::take_flags(argc, argv, {"device", "peer-shaders", "size"});
  if (flags.count("device")) device = flags.at("device");
  if (flags.count("peer-shaders")) peer_shaders = flags.at("peer-shaders");
  if (flags.count("size") && !bench::parse_size(flags.at("size"), size.width, size.height)) {
    std::cerr << "web_bench: --size wants WxH, each 1 to 8192, not " << flags.at("size") << "\n";
    return 2;
  }
  if (!bench::begin(argc, argv)) return 2;
  const std::optional<std::string> chromium = webgl::find_chromium();
  if (!chromium) {
    std::cerr << "web_bench: no Chromium here (Debian's chromium package; or FLATMARCH_CHROMIUM)\n";
    return 77;
  }
  bench::Web web;
  try {
    web.browser = std::make_unique<webgl::Chromium>(*chromium, webgl::device_flags(device));
  } catch (const std::exception& e) {
    std::cerr << "web_bench: " << e.what() << "\n";
    return 77;
  }
  char folder[] = "/tmp/flatmarch-web-bench-XXXXXX";
  if (!mkdtemp(folder)) {
    std::cerr << "web_bench: cannot make a temporary folder\n";
    return 1;
  }
  web.folder = folder;

  std::map<std::string, glm::vec3> starts;
  if (peer_shaders.empty()) {
    std::cerr << "web_bench: no --peer-shaders: our pages are timed without the app's shaders "
                 "(../shared/peer-shaders.md says how to regenerate them)\n";
  } else {
    try {
      starts = bench::app_starts(peer_shaders);
    } catch (const std::exception& e) {
      std::cerr << "web_bench: the app's shaders cannot be read, skipped: " << e.what() << "\n";
    }
  }
  for (const bench::PeerView& view : bench::kPeerViews) {
    const Scene scene = bench::peer_scene(view);
    const std::string page = (web.folder / (std::string(view.name) + ".html")).string();
    std::ofstream(page) << web::page(scene, {});
    if (web.label.empty()) {
      web.open(page);
      web.label = "browser " + web.browser->product() + "; WebGL " +
                  web.browser
                      ->evaluate(
                          "(() => { const d = gl.getExtension('WEBGL_debug_renderer_info'); "
                          "return gl.getParameter(d ? d.UNMASKED_RENDERER_WEBGL : "
                          "gl.RENDERER); })()")
                      .get<std::string>();
      std::cerr << "web_bench: " << web.label << "\n";
    }
    const std::string at = std::to_string(size.width) + "x" + std::to_string(size.height);
    if (starts.count(view.id)) {
      const bench::AppView v = bench::app_view(starts[view.id]);
      const nlohmann::json request = {
          {"fragment", bench::app_fragment(bench::app_shader(peer_shaders, view.id))},
          {"uniforms",
           {{"iResolution", {size.width, size.height}},
            {"iTime", {0.0}},
            {"rayMarchCamPos", {v.from.x, v.from.y, v.from.z}},
            {"rayMarchCamFront", {v.front.x, v.front.y, v.front.z}},
            {"rayMarchCamUp", {v.up.x, v.up.y, v.up.z}}}},
          {"w", size.width},
          {"h", size.height}};
      bench::add(("web/peer/app/" + std::string(view.name) + "/" + at).c_str(), bench::app, &web,
                 page, request, std::string(view.name))
          ->Unit(benchmark::kMillisecond)
          ->UseManualTime();
    }
    for (const Method method : kKernelMethods) {
      const nlohmann::json request = {
          {"method", to_string(method)},
          {"camera", nlohmann::json(camera_json(benchmark_view(scene.camera)))},
          {"w", size.width},
          {"h", size.height}};
      bench::add(
          ("web/peer/webgl/" + std::string(view.name) + "/" + to_string(method) + "/" + at).c_str(),
          bench::ours, &web, page, request, std::string(view.name))
          ->Unit(benchmark::kMillisecond)
          ->UseManualTime();
    }
  }
  return bench::run();
}
