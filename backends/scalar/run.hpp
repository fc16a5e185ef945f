// How the scalar backend runs the kernel in one precision: a frame pixel by pixel, or one ray
// with its events. Instantiated once per precision (scalar_f32.cpp, scalar_f64.cpp), so the
// kernel's 64 specialisations of each compile in parallel.
#pragma once

#include "backends/backend.hpp"
#include "backends/kernel_trace.hpp"
#include "kernels/camera.hpp"
#include "kernels/compile.hpp"

namespace flatmarch::scalar {

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
        frame.set(i, j, Vec3(k.shade(r)), r.steps, r.crossings, r.hit, r.t);
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
  int steps = 0;
  kernel::with_kernel<real>(tables, [&](auto& k) {
    k.events = &events;
    k.max_events = max_events;
    steps = k.march(ray.polygon, vec3(ray.from), vec3(ray.dir)).steps;
  });
  return kernel_trace(events, steps);
}

// Compiled in scalar_f32.cpp and scalar_f64.cpp only.
extern template Frame render_in<float>(const Scene&, const Camera&, int, int, const MarchParams&,
                                       const Progress&);
extern template Frame render_in<double>(const Scene&, const Camera&, int, int, const MarchParams&,
                                        const Progress&);
extern template Trace trace_in<float>(const Scene&, const Ray&, const MarchParams&, int);
extern template Trace trace_in<double>(const Scene&, const Ray&, const MarchParams&, int);

}  // namespace flatmarch::scalar
