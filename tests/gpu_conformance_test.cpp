// The GPU backends, OpenGL (headless, OSMesa) and Vulkan (under the validation layer), against
// the oracle and against the scalar backend, for every gallery scene and method: the hit AOV
// agrees with the oracle on at least 99% of the pixels of a 160x90 frame (the scalar backend's
// named out-of-steps exceptions aside), with the scalar backend on at least 99.5%, and generic
// probe rays follow the oracle's events. Labelled `conformance`: it checks results, not memory,
// so the sanitizer stage leaves it out. A backend that is unavailable here is skipped, visibly.
#include <gtest/gtest.h>

#include <iostream>
#include <map>

#include "backends/scalar/scalar.hpp"
#include "tests/gallery.hpp"
#include "tests/opengl_backend.hpp"
#include "tests/oracle_compare.hpp"
#include "tests/vulkan_backend.hpp"

namespace flatmarch {
namespace {

struct Case {
  std::string backend;  // opengl or vulkan
  std::string scene;
  Method method;
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.backend << " " << c.scene << " " << to_string(c.method);
}

class GpuConformance : public testing::TestWithParam<Case> {
 protected:
  const Backend& backend() const {
    if (GetParam().backend == "opengl") return test::opengl();
    return test::vulkan();
  }
};

#define SKIP_UNAVAILABLE()                                           \
  if (const Availability a = backend().availability(); !a.available) \
  GTEST_SKIP() << "the " << GetParam().backend << " backend is unavailable here: " << a.reason

TEST_P(GpuConformance, HitAovAgreesWithTheOracleAndScalar) {
  SKIP_UNAVAILABLE();
  const Scene& scene = test::gallery_scene(GetParam().scene);
  MarchParams params;
  params.method = GetParam().method;
  constexpr int kWidth = 160, kHeight = 90;
  const Frame truth = OracleBackend().render(scene, scene.camera, kWidth, kHeight, {}, {});
  const std::vector<std::set<int>> answers = test::oracle_answers(scene, kWidth, kHeight);
  const Frame scalar = ScalarBackend().render(scene, scene.camera, kWidth, kHeight, params, {});
  const Frame got = backend().render(scene, scene.camera, kWidth, kHeight, params, {});
  ASSERT_EQ(got.hit.size(), truth.hit.size());
  const double pixels = static_cast<double>(truth.hit.size());
  size_t acceptable = 0, gave_up = 0, same_as_scalar = 0, same_steps = 0;
  std::map<std::pair<int, int>, int> confusion;  // (oracle's hit, the backend's) -> pixels
  for (size_t px = 0; px < truth.hit.size(); ++px) {
    const int hit = static_cast<int>(got.hit[px]);
    const bool fine = answers[px].count(hit) > 0;
    acceptable += fine;
    gave_up += !fine && hit == kHitMaxSteps;
    same_as_scalar += got.hit[px] == scalar.hit[px];
    same_steps += got.steps[px] == scalar.steps[px];
    if (hit != static_cast<int>(truth.hit[px])) ++confusion[{static_cast<int>(truth.hit[px]), hit}];
    EXPECT_LE(got.steps[px], static_cast<float>(params.max_steps));
  }
  const double fraction = static_cast<double>(acceptable) / pixels;
  std::cout << "[ figures  ] " << GetParam().backend << " " << scene.name << " "
            << to_string(params.method) << ": oracle " << 100.0 * fraction
            << "% (ambiguous pixels allowed), scalar hit "
            << 100.0 * static_cast<double>(same_as_scalar) / pixels << "%, steps "
            << 100.0 * static_cast<double>(same_steps) / pixels << "%;";
  for (const auto& [hits, count] : confusion)
    std::cout << "  " << hits.first << "->" << hits.second << ": " << count;
  std::cout << "\n";
  EXPECT_GE(static_cast<double>(same_as_scalar) / pixels, 0.995);
  if (!test::out_of_steps_exception(scene.name, params.method)) {
    EXPECT_GE(fraction, 0.99);
  } else {  // as the scalar backend: short only by rays that ran out of steps
    EXPECT_GE(fraction + static_cast<double>(gave_up) / pixels, 0.99);
  }
}

TEST_P(GpuConformance, GenericRaysFollowTheOraclesEvents) {
  SKIP_UNAVAILABLE();
  const Scene& scene = test::gallery_scene(GetParam().scene);
  const std::vector<Ray> rays = test::generic_rays(scene);
  ASSERT_EQ(static_cast<int>(rays.size()), test::kRaysPerScene);
  MarchParams params;
  params.method = GetParam().method;
  for (size_t k = 0; k < rays.size(); ++k) {
    const Trace truth = OracleBackend().trace(scene, rays[k], {}, test::kEvents);
    const Trace got = backend().trace(scene, rays[k], params, test::kEvents);
    ASSERT_EQ(got.events.size(), truth.events.size()) << "ray " << k;
    for (size_t i = 0; i < truth.events.size(); ++i) {
      const Event &a = truth.events[i], &b = got.events[i];
      ASSERT_EQ(test::describe(b), test::describe(a)) << "ray " << k << " event " << i;
      EXPECT_EQ(b.to_polygon, a.to_polygon);
      EXPECT_EQ(b.to_edge, a.to_edge);
      EXPECT_NEAR(b.t, a.t, 1e-2 * scene.scale) << "ray " << k << " event " << i;
      EXPECT_NEAR(b.at.x, a.at.x, 1e-2 * scene.scale);
      EXPECT_NEAR(b.at.y, a.at.y, 1e-2 * scene.scale);
    }
    EXPECT_GT(got.steps, 0);
  }
}

std::vector<Case> cases() {
  std::vector<Case> all;
  for (const char* backend : {"opengl", "vulkan"})
    for (const std::string& name : test::gallery_names())
      for (Method m : {Method::sphere, Method::relaxed, Method::analytic})
        all.push_back({backend, name, m});
  return all;
}

INSTANTIATE_TEST_SUITE_P(Gallery, GpuConformance, testing::ValuesIn(cases()),
                         [](const testing::TestParamInfo<Case>& param) {
                           return param.param.backend + "_" + param.param.scene + "_" +
                                  to_string(param.param.method);
                         });

}  // namespace
}  // namespace flatmarch
