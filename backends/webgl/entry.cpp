// The WebGL backend's entry in the registry: its options, its cost (a browser's page a case), and
// the sample of cases a default report gives it where Chromium draws in software.
#include "backends/webgl/webgl.hpp"

namespace flatmarch {

BackendEntry webgl_backend_entry() {
  return {.name = WebGlBackend::kName,
          .make = [](const BackendOptions& o) { return std::make_unique<WebGlBackend>(o); },
          .options = {{"--device", &BackendOptions::device,
                       "gpu or swiftshader (default: Chromium's choice, a GPU where it can "
                       "use one, else SwiftShader)"},
                      {"--kernel-shape", &BackendOptions::kernel_shape,
                       "likewise, the page's shader (auto: by the browser's renderer)"}},
          // Its pages start with the analytic method.
          .gallery_test_methods = {Method::analytic},
          .cost = {.frame_seconds = 0.2, .startup_seconds = 0.5},
          // A browser drawing in software (SwiftShader) takes many times the other backends'
          // time a case (4.8 s against 0.3-0.6 s on a 2-core Zen 5, a prism's 20 s).
          .software_sample_why = "its WebGL draws in software here"};
}

}  // namespace flatmarch
