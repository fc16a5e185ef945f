// The scalar backend: the kernel (kernels/march.glsl) compiled as plain C++ and run one ray at a
// time on one CPU core. It is the readable reference among the kernel's backends.
#pragma once

#include "backends/backend.hpp"

namespace flatmarch {

class ScalarBackend final : public Backend {
 public:
  std::string name() const override { return "scalar"; }
  std::string description() const override;
  Availability availability() const override { return {}; }
  std::vector<Method> methods() const override {
    return {kKernelMethods.begin(), kKernelMethods.end()};
  }
  Frame render(const Scene& scene, const Camera& camera, int width, int height,
               const MarchParams& params, const Progress& progress) const override;
  Trace trace(const Scene& scene, const Ray& ray, const MarchParams& params,
              int max_events) const override;
};

}  // namespace flatmarch
