#include "backends/scalar/scalar.hpp"

#include "backends/scalar/run.hpp"

namespace flatmarch {

std::string ScalarBackend::description() const {
  return "the kernel as plain C++, one ray at a time on one CPU core (f32 or f64): the reference "
         "for the other kernel backends";
}

Frame ScalarBackend::render(const Scene& scene, const Camera& camera, int width, int height,
                            const MarchParams& params, const Progress& progress) const {
  return params.precision == Precision::f64
             ? scalar::render_in<double>(scene, camera, width, height, params, progress)
             : scalar::render_in<float>(scene, camera, width, height, params, progress);
}

Trace ScalarBackend::trace(const Scene& scene, const Ray& ray, const MarchParams& params,
                           int max_events) const {
  return params.precision == Precision::f64
             ? scalar::trace_in<double>(scene, ray, params, max_events)
             : scalar::trace_in<float>(scene, ray, params, max_events);
}

}  // namespace flatmarch
