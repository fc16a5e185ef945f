#include "backends/scalar/scalar.hpp"

#include <algorithm>

#include "kernels/camera.hpp"
#include "kernels/compile.hpp"

namespace flatmarch {

namespace {

template <typename real>
Frame render_in(const Scene& scene, const Camera& camera, int width, int height,
                const MarchParams& params, const Progress& progress) {
  using vec3 = glm::vec<3, real>;
  const kernel::SceneTables<real> tables = kernel::compile_scene<real>(scene, params);
  const CameraBasis<real> basis = camera_basis<real>(real(camera.yaw_deg), real(camera.pitch_deg),
                                                     real(camera.fov_deg), width, height);
  const vec3 from(camera.position);
  Frame frame(width, height);
  kernel::with_kernel<real>(tables, [&](auto& k) {
    constexpr int kRowsPerReport = 8;
    for (int j = 0; j < height; ++j) {
      for (int i = 0; i < width; ++i) {
        const auto r = k.march(camera.polygon, from, camera_ray(basis, i, j, width, height));
        const vec3 c = k.shade(r);
        const size_t px = frame.pixel(i, j);
        for (int n = 0; n < 3; ++n)
          frame.rgb[3 * px + static_cast<size_t>(n)] = static_cast<float>(c[n]);
        frame.steps[px] = static_cast<float>(r.steps);
        frame.crossings[px] = static_cast<float>(r.crossings);
        frame.hit[px] = static_cast<float>(r.hit);
        frame.t[px] = static_cast<float>(r.t);
      }
      if (progress && ((j + 1) % kRowsPerReport == 0 || j + 1 == height))
        progress(static_cast<double>(j + 1) / height);
    }
  });
  return frame;
}

template <typename real>
Trace trace_in(const Scene& scene, const Ray& ray, const MarchParams& params, int max_events) {
  using vec3 = glm::vec<3, real>;
  const kernel::SceneTables<real> tables = kernel::compile_scene<real>(scene, params);
  std::vector<kernel::KernelEvent> events;
  Trace trace;
  kernel::with_kernel<real>(tables, [&](auto& k) {
    k.events = &events;
    k.max_events = max_events;
    trace.steps = k.march(ray.polygon, vec3(ray.from), vec3(ray.dir)).steps;
  });
  for (const kernel::KernelEvent& e : events)
    trace.events.push_back({.kind = static_cast<EventKind>(e.kind),
                            .polygon = e.polygon,
                            .edge = e.edge,
                            .to_polygon = e.to_polygon,
                            .to_edge = e.to_edge,
                            .object = e.object,
                            .t = e.t,
                            .at = e.at});
  return trace;
}

}  // namespace

std::string ScalarBackend::description() const {
  return "the kernel as plain C++, one ray at a time on one CPU core (f32 or f64): the reference "
         "for the other kernel backends";
}

Frame ScalarBackend::render(const Scene& scene, const Camera& camera, int width, int height,
                            const MarchParams& params, const Progress& progress) const {
  return params.precision == Precision::f64
             ? render_in<double>(scene, camera, width, height, params, progress)
             : render_in<float>(scene, camera, width, height, params, progress);
}

Trace ScalarBackend::trace(const Scene& scene, const Ray& ray, const MarchParams& params,
                           int max_events) const {
  return params.precision == Precision::f64 ? trace_in<double>(scene, ray, params, max_events)
                                            : trace_in<float>(scene, ray, params, max_events);
}

}  // namespace flatmarch
