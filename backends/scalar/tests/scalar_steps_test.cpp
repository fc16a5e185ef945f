// Step counts of the scalar backend: the analytic method's advantage, which is deterministic.
// (The gallery against the oracle is conformance/tests/gallery_conformance_test.cpp.)
#include <gtest/gtest.h>

#include <iostream>

#include "backends/scalar/scalar.hpp"
#include "tests/gallery.hpp"

namespace flatmarch {
namespace {

double mean_steps(const Scene& scene, Method method) {
  MarchParams params;
  params.method = method;
  const Frame f = ScalarBackend().render(scene, scene.camera, 320, 180, params, {});
  double sum = 0.0;
  for (float s : f.steps) sum += s;
  return sum / static_cast<double>(f.steps.size());
}

TEST(ScalarSteps, AnalyticTakesTenTimesFewerStepsThanSphereOnTranslationSurfaces) {
  // Steps are deterministic, so this holds on any machine (bench/kernel_bench reports them too).
  for (const std::string name : {"l_shape", "double_pentagon"}) {
    const Scene& scene = test::gallery_scene(name);
    const double sphere = mean_steps(scene, Method::sphere);
    const double analytic = mean_steps(scene, Method::analytic);
    std::cout << name << ": mean steps per ray at 320x180, sphere " << sphere << ", analytic "
              << analytic << ", ratio " << sphere / analytic << "\n";
    EXPECT_GE(sphere / analytic, 10.0) << name;
  }
}

}  // namespace
}  // namespace flatmarch
