// What every kernel backend promises, tested once over the registry (backend_registry()) and the
// variants it lists (simd: every instruction set): a backend registered there, a test's own
// included, is held to all of it with no other edit. Each backend's own test file keeps only
// what is specific to it (devices, shaders, lane counts). A backend unavailable here is skipped,
// visibly, with its reason.
#include <gtest/gtest.h>

#include <optional>

#include <algorithm>
#include <memory>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "backends/backend.hpp"
#include "backends/scalar/scalar.hpp"
#include "tests/gallery.hpp"
#include "tests/oracle_compare.hpp"

namespace flatmarch {
namespace {

// A registered kernel backend with its default options, or one of its variants (simd: each
// instruction set).
struct Variant {
  std::string backend, label;  // label: "" for the default
  BackendOptions options;
};

void PrintTo(const Variant& v, std::ostream* os) {
  *os << v.backend << (v.label.empty() ? "" : " " + v.label);
}

std::vector<Variant> variants() {
  std::vector<Variant> all;
  for (const BackendEntry& e : backend_registry()) {
    if (!e.kernel) continue;
    all.push_back({e.name, "", {}});
    if (e.variants)
      for (const auto& [label, options] : e.variants()) all.push_back({e.name, label, options});
  }
  return all;
}

class BackendContract : public testing::TestWithParam<Variant> {
 protected:
  void SetUp() override {
    if (const BackendEntry* e = find_backend_entry(GetParam().backend);
        e && !e->wrong_on_purpose.empty())
      GTEST_SKIP() << "the " << GetParam().backend
                   << " backend breaks the contract on purpose: " << e->wrong_on_purpose;
    backend_ = make_backend(GetParam().backend, GetParam().options);
    ASSERT_NE(backend_, nullptr) << GetParam().backend << " is registered but makes no backend";
    if (const Availability a = backend_->availability(); !a.available)
      GTEST_SKIP() << "the " << testing::PrintToString(GetParam())
                   << " backend is unavailable here: " << a.reason;
  }

  // How far a backend may stray from the scalar kernel, and why.
  // CPU backends compile the kernel with the scalar backend's float operations in the same order
  // (no fused multiply-add): they agree exactly. A device compiles the shader with its own
  // compiler, which may fuse, reorder or round square roots differently: a ray grazing an edge
  // or a vertex may then take a step more or less, or go the other way.
  int step_tolerance() const { return backend_->device() ? 2 : 0; }
  size_t pixel_tolerance() const { return backend_->device() ? 6 : 0; }

  std::unique_ptr<Backend> backend_;
};

// On scenes of one room and of several, with mirrors, a period and solids, scene after scene
// and method after method (the GPU backends trace with one program that every scene shares,
// kernel::shared_trace, given each one's tables).
TEST_P(BackendContract, TraceMatchesTheScalarKernelsSteps) {
  for (const char* name : {"l_shape", "cube", "mirror_double_pentagon", "double_pentagon_prism"}) {
    const Scene& scene = test::gallery_scene(name);
    for (const Method m : backend_->methods()) {
      MarchParams params;
      params.method = m;
      for (const Ray& ray : test::generic_rays(scene)) {
        const Trace want = ScalarBackend().trace(scene, ray, params, 50);
        const Trace got = backend_->trace(scene, ray, params, 50);
        EXPECT_NEAR(got.steps, want.steps, step_tolerance()) << name << " " << to_string(m);
        ASSERT_EQ(got.events.size(), want.events.size()) << name << " " << to_string(m);
        for (size_t k = 0; k < want.events.size(); ++k)
          EXPECT_EQ(got.events[k].kind, want.events[k].kind)
              << name << " " << to_string(m) << ", event " << k << ": "
              << test::describe(got.events[k]) << " where the scalar kernel has "
              << test::describe(want.events[k]);
      }
    }
  }
}

TEST_P(BackendContract, RefusesWhatItCannotMarchAndSaysWhy) {
  const Scene& scene = test::gallery_scene("torus");
  const std::vector<Precision> precisions = backend_->precisions();
  for (const Precision p : {Precision::f32, Precision::f64}) {
    if (std::find(precisions.begin(), precisions.end(), p) != precisions.end()) continue;
    MarchParams params;
    params.precision = p;
    try {
      backend_->render(scene, scene.camera, 8, 8, params, {});
      ADD_FAILURE() << "rendered in a precision it does not list";
    } catch (const std::invalid_argument& e) {
      // It names itself and what it does march in.
      const std::string why = e.what();
      EXPECT_NE(why.find(GetParam().backend), std::string::npos) << why;
      EXPECT_NE(why.find(p == Precision::f64 ? "f32" : "f64"), std::string::npos) << why;
    }
  }
}

TEST_P(BackendContract, ReportsProgressRisingToTheEnd) {
  const Scene& scene = test::gallery_scene("torus");
  std::vector<double> seen;
  backend_->render(scene, scene.camera, 32, 200, {}, [&](double f) { seen.push_back(f); });
  ASSERT_FALSE(seen.empty());
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_GE(seen.front(), 0.0);
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);
}

TEST_P(BackendContract, ImageRowsAreTopDownAsDesignSays) {
  // In the cube the bottom rows see the floor and the top rows the open sky over the walls: an
  // image far from symmetric top to bottom, so rows stored bottom-up would not agree with the
  // scalar backend's.
  const Scene& scene = test::gallery_scene("cube");
  Camera camera = scene.camera;
  camera.pitch_deg = 0.0;
  constexpr int kWidth = 40, kHeight = 30;
  const Frame want = ScalarBackend().render(scene, camera, kWidth, kHeight, {}, {});
  const Frame got = backend_->render(scene, camera, kWidth, kHeight, {}, {});
  ASSERT_EQ(got.width, kWidth);
  ASSERT_EQ(got.height, kHeight);
  size_t differ = 0, mirrored = 0;
  for (int j = 0; j < kHeight; ++j)
    for (int i = 0; i < kWidth; ++i) {
      differ += got.hit[got.pixel(i, j)] != want.hit[want.pixel(i, j)];
      mirrored += got.hit[got.pixel(i, j)] == want.hit[want.pixel(i, kHeight - 1 - j)];
    }
  EXPECT_LE(differ, pixel_tolerance());
  EXPECT_LT(mirrored, got.hit.size() / 2);  // the test would not see a flip otherwise
}

TEST_P(BackendContract, ARepeatedFrameIsTheSame) {
  const Scene& scene = test::gallery_scene("l_shape");
  const Frame a = backend_->render(scene, scene.camera, 48, 27, {}, {});
  const Frame b = backend_->render(scene, scene.camera, 48, 27, {}, {});
  EXPECT_TRUE(a.hit == b.hit && a.steps == b.steps && a.t == b.t && a.rgb == b.rgb);
}

// A frame for the eye or the clock has at least the colour: 8-bit sRGB (a GPU backend's, read
// back alone) or the whole frame; and a backend that runs on a device says how its clock timed
// the frame, where one that runs on none says nothing.
TEST_P(BackendContract, AFrameOfTheColourHasEveryPixelsColour) {
  const Scene& scene = test::gallery_scene("l_shape");
  const Frame f = backend_->render_colour(scene, scene.camera, 48, 27, {}, {});
  EXPECT_EQ(f.width, 48);
  EXPECT_EQ(f.height, 27);
  EXPECT_TRUE(f.srgb.size() == 4u * 48 * 27 || f.rgb.size() == 3u * 48 * 27);
  const std::optional<DeviceTiming> t = backend_->last_device_timing();
  // A GPU backend that does not time its frames itself (webgl's page does: last_frame_seconds)
  // says how its device timed them.
  if (backend_->device() && !backend_->last_frame_seconds()) {
    EXPECT_TRUE(t.has_value()) << "a GPU backend says how its device timed the frame";
  }
  if (!backend_->device()) {
    EXPECT_FALSE(t.has_value());
  }
  if (t && !t->measured) {
    EXPECT_FALSE(t->why.empty()) << "an unmeasured frame says why";
  }
}

TEST_P(BackendContract, ThreadsDoNotChangeTheFrame) {
  // However a backend spreads a frame over threads (--threads; ignored where it has none), each
  // pixel's ray is marched alone: one thread and three give the same frame, at a size no tile
  // divides.
  const Scene& scene = test::gallery_scene("double_pentagon");
  MarchParams params;
  params.method = Method::relaxed;
  std::vector<Frame> frames;
  for (const int threads : {1, 3}) {
    BackendOptions options = GetParam().options;
    options.threads = threads;
    frames.push_back(make_backend(GetParam().backend, options)
                         ->render(scene, scene.camera, 101, 57, params, {}));
  }
  EXPECT_EQ(frames[0].rgb, frames[1].rgb);
  EXPECT_EQ(frames[0].steps, frames[1].steps);
  EXPECT_EQ(frames[0].hit, frames[1].hit);
  EXPECT_EQ(frames[0].t, frames[1].t);
}

// The registry itself: what backends() and the name lists hold, and what it refuses.
TEST(Registry, ListsEveryBackendOnceInItsOrder) {
  std::vector<std::string> made;
  for (const auto& b : backends()) made.push_back(b->name());
  EXPECT_EQ(made, backend_names());
  const std::vector<std::string> kernel = kernel_backend_names();
  EXPECT_EQ(std::count(kernel.begin(), kernel.end(), "oracle"), 0);  // the truth, not a kernel
  EXPECT_EQ(std::count(kernel.begin(), kernel.end(), "faulty"), 1);  // tests/backends/faulty.cpp
  EXPECT_EQ(kernel.size() + 1, made.size());
  // One registered late (an external renderer, from the command line) joins backends() on its
  // next call; never two of one name.
  const auto make = [](const BackendOptions&) { return make_backend("scalar", {}); };
  ASSERT_TRUE(register_backend({.name = "late", .kernel = false, .make = make}));
  EXPECT_EQ(backends().size(), made.size() + 1);
  EXPECT_EQ(backend_names().back(), "late");
  EXPECT_EQ(backends().back()->name(), "scalar");  // what its `make` made
  EXPECT_EQ(kernel_backend_names(), kernel);
  EXPECT_THROW(register_backend({.name = "scalar", .make = make}), std::logic_error);
}

INSTANTIATE_TEST_SUITE_P(Registered, BackendContract, testing::ValuesIn(variants()),
                         [](const testing::TestParamInfo<Variant>& p) {
                           return p.param.backend +
                                  (p.param.label.empty() ? "" : "_" + p.param.label);
                         });

}  // namespace
}  // namespace flatmarch
