// The conformance suite on the gallery: every kernel backend (scalar, simd, opengl and vulkan
// on their default devices, here llvmpipe through EGL and lavapipe, vulkan under the validation
// layer) x every scene of the gallery and of conformance/scenes x every method, at default
// parameters (float32, and float64 on the scalar backend), measured against the oracle and
// judged by conformance/thresholds.json. Labelled `conformance`. A backend that is unavailable
// here is skipped, with the reason.
#include <gtest/gtest.h>
#include <algorithm>

#include <filesystem>
#include <iostream>
#include <map>
#include <memory>

#include "conformance/suite.hpp"
#include "conformance/tests/test_backends.hpp"
#include "scene/load.hpp"
#include "tests/gallery.hpp"

namespace flatmarch::conformance {
namespace {

struct Case {
  std::string backend, scene;
  Method method;
  Precision precision = Precision::f32;
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.backend << " " << c.scene << " " << to_string(c.method)
      << (c.precision == Precision::f64 ? " f64" : "");
}

// The gallery's scenes, then the suite's own (conformance/scenes: what the gallery lacks).
std::vector<std::string> scene_names() {
  std::vector<std::string> names = test::gallery_names();
  for (const auto& entry : std::filesystem::directory_iterator(
           std::filesystem::path(FLATMARCH_SOURCE_DIR) / "conformance" / "scenes"))
    if (entry.path().extension() == ".json") names.push_back(entry.path().stem().string());
  return names;
}

const Scene& scene_named(const std::string& name) {
  static std::map<std::string, Scene> own;
  const auto file =
      std::filesystem::path(FLATMARCH_SOURCE_DIR) / "conformance" / "scenes" / (name + ".json");
  if (!std::filesystem::exists(file)) return test::gallery_scene(name);
  auto it = own.find(name);
  if (it == own.end()) it = own.emplace(name, load_scene(file)).first;
  return it->second;
}

class GalleryConformance : public testing::TestWithParam<Case> {};

// One suite for the cases of a scene, in turn (cases() lists them scene by scene): the oracle's
// truth, the float64 reference frame and the probe rays' traces are then made once for all the
// backends a process runs, not once a case (a batch a backend: 114 s in all; the kernel
// backends' one batch: 65 s, the same figures; 2-core Zen 5, idle).
Suite& suite_for(const std::string& scene) {
  static std::string current;
  static std::unique_ptr<Suite> suite;
  if (!suite || scene != current) {
    suite = std::make_unique<Suite>();
    current = scene;
  }
  return *suite;
}

TEST_P(GalleryConformance, MeetsItsThresholds) {
  const Backend& backend = test::backend_named(GetParam().backend);
  if (const Availability a = backend.availability(); !a.available)
    GTEST_SKIP() << "the " << GetParam().backend << " backend is unavailable here: " << a.reason;
  const Scene& scene = scene_named(GetParam().scene);
  MarchParams params;
  params.method = GetParam().method;
  params.precision = GetParam().precision;
  const CaseResult r = suite_for(GetParam().scene).run(backend, scene, params, 160, 90);
  std::cout << "[ figures  ] " << to_json(r).dump() << "\n";
  // A backend wrong on purpose (the test programs' faulty one) must fail every case: the suite
  // catches a renderer that runs and is wrong.
  if (const BackendEntry* e = find_backend_entry(GetParam().backend);
      e && !e->wrong_on_purpose.empty()) {
    EXPECT_EQ(r.verdict, Verdict::fail)
        << "the suite passed the " << GetParam().backend << " backend (" << e->wrong_on_purpose
        << "): " << to_string(r.verdict);
    EXPECT_FALSE(r.failed_checks().empty());
    return;
  }
  // A case at its method's limit is expected (issue 22): it is reported, not counted as a pass,
  // and the regression gate catches it getting worse.
  if (r.verdict == Verdict::limit) std::cout << "[ limit    ] " << r.limit << "\n";
  if (r.verdict == Verdict::fail)
    for (const std::string& line : r.failed_checks()) ADD_FAILURE() << line;
  for (const TraceComparison& t : r.traces) {
    if (!t.divergence.empty()) std::cout << "  trace: " << t.divergence << "\n";
    if (t.leak) std::cout << "  trace: leak: " << t.leak_at << "\n";
  }
  if (!r.thresholds.why.empty()) std::cout << "  exceptions: " << r.thresholds.why << "\n";
}

// Scene by scene (suite_for), and in each every backend and method.
std::vector<Case> cases() {
  std::vector<Case> all;
  for (const std::string& name : scene_names()) {
    for (const std::string& backend : kernel_backend_names()) {
      // A backend whose every case costs much (webgl's starts a browser, 3 s where opengl takes
      // 0.5) is run here on the methods its entry names; `flatmarch conform` measures the others.
      const std::vector<Method>& only = find_backend_entry(backend)->gallery_test_methods;
      for (Method m : kKernelMethods)
        if (only.empty() || std::find(only.begin(), only.end(), m) != only.end())
          all.push_back({backend, name, m});
    }
    for (Method m : kKernelMethods)  // float64, on the reference CPU backend
      all.push_back({"scalar", name, m, Precision::f64});
  }
  return all;
}

INSTANTIATE_TEST_SUITE_P(Gallery, GalleryConformance, testing::ValuesIn(cases()),
                         [](const testing::TestParamInfo<Case>& param) {
                           return param.param.backend +
                                  (param.param.precision == Precision::f64 ? "_f64_" : "_") +
                                  param.param.scene + "_" + to_string(param.param.method);
                         });

}  // namespace
}  // namespace flatmarch::conformance
