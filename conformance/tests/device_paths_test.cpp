// Every way a GPU backend reaches the same device gives the same frame, to the bit: the OpenGL
// backend's context made through EGL and through OSMesa on Mesa's llvmpipe, and the Vulkan
// backend's frames read back directly and through a staging copy (the path a discrete GPU takes,
// forced with --vk-staging); and both kernel shapes (--kernel-shape software and gpu: on OpenGL a
// fragment and a compute shader) give the same steps, crossings and hits. Every gallery scene (and
// conformance/scenes) and method (the staging copy: one method a scene), at the conformance
// suite's size. Labelled `conformance`; a path this machine lacks is skipped, with the reason.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <map>
#include <optional>

#include "backends/opengl/context.hpp"
#include "backends/opengl/opengl.hpp"
#include "backends/vulkan/vulkan.hpp"
#include "scene/load.hpp"
#include "tests/gallery.hpp"

namespace flatmarch {
namespace {

constexpr int kWidth = 160, kHeight = 90;

struct Case {
  std::string scene;
  Method method;
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.scene << " " << to_string(c.method);
}

std::vector<std::filesystem::path> scene_files() {
  std::vector<std::filesystem::path> files = test::gallery_files();
  for (const auto& entry : std::filesystem::directory_iterator(
           std::filesystem::path(FLATMARCH_SOURCE_DIR) / "conformance" / "scenes"))
    if (entry.path().extension() == ".json") files.push_back(entry.path());
  return files;
}

const Scene& scene_named(const std::string& name) {
  static std::map<std::string, Scene> loaded;
  if (auto it = loaded.find(name); it != loaded.end()) return it->second;
  for (const auto& file : scene_files())
    if (file.stem() == name) return loaded.emplace(name, load_scene(file)).first->second;
  throw std::runtime_error("no scene " + name);
}

// The first usable OpenGL device of a platform ("EGL", "OSMesa") on Mesa's llvmpipe.
std::optional<gl::Device> llvmpipe_device(const std::string& platform) {
  static const std::vector<gl::Device> devices = gl::list_devices();
  for (const gl::Device& d : devices)
    if (d.usable && d.platform.rfind(platform, 0) == 0 &&
        d.renderer.find("llvmpipe") != std::string::npos)
      return d;
  return std::nullopt;
}

struct OpenGlPaths {
  std::optional<gl::Device> egl = llvmpipe_device("EGL"), osmesa = llvmpipe_device("OSMesa");
  std::unique_ptr<OpenGlBackend> through_egl, through_osmesa;
  OpenGlPaths() {
    if (!egl || !osmesa) return;
    through_egl = std::make_unique<OpenGlBackend>(
        BackendOptions{.device = std::to_string(egl->index), .kernel_shape = "software"});
    through_osmesa = std::make_unique<OpenGlBackend>(
        BackendOptions{.device = std::to_string(osmesa->index), .kernel_shape = "software"});
  }
};

// The kernel's two shapes on the default device (llvmpipe here; a GPU where there is one).
struct OpenGlShapes {
  OpenGlBackend software{BackendOptions{.kernel_shape = "software"}};
  OpenGlBackend gpu{BackendOptions{.kernel_shape = "gpu"}};
};

const OpenGlShapes& opengl_shapes() {
  static const OpenGlShapes shapes;
  return shapes;
}

const OpenGlPaths& opengl_paths() {
  static const OpenGlPaths paths;
  return paths;
}

struct VulkanPaths {
  VulkanBackend direct{BackendOptions{.kernel_shape = "software", .validation = true}};
  VulkanBackend staging{
      BackendOptions{.kernel_shape = "software", .vk_staging = true, .validation = true}};
  VulkanBackend gpu_shape{BackendOptions{.kernel_shape = "gpu", .validation = true}};
};

const VulkanPaths& vulkan_paths() {
  static const VulkanPaths paths;
  return paths;
}

// Bit for bit: equal floats, and NaN where the other has the same NaN.
void expect_identical(const Channel& a, const Channel& b, const char* channel) {
  ASSERT_EQ(a.size(), b.size()) << channel;
  size_t differ = 0, first = 0;
  for (size_t k = 0; k < a.size(); ++k)
    if (std::memcmp(&a[k], &b[k], sizeof(float)) != 0 && differ++ == 0) first = k;
  EXPECT_EQ(differ, 0u) << channel << ": " << differ << " values differ, the first at " << first
                        << " (" << a[first] << " against " << b[first] << ")";
}

void expect_identical(const Frame& a, const Frame& b) {
  expect_identical(a.hit, b.hit, "hit");
  expect_identical(a.steps, b.steps, "steps");
  expect_identical(a.crossings, b.crossings, "crossings");
  expect_identical(a.t, b.t, "t");
  expect_identical(a.rgb, b.rgb, "colour");
}

// The kernel's two shapes: the same rays, each taking the same steps to the same end.
void expect_same_rays(const Frame& software, const Frame& gpu) {
  expect_identical(software.hit, gpu.hit, "hit");
  expect_identical(software.steps, gpu.steps, "steps");
  expect_identical(software.crossings, gpu.crossings, "crossings");
}

class DevicePaths : public testing::TestWithParam<Case> {
 protected:
  const Scene& scene() const { return scene_named(GetParam().scene); }
  MarchParams params() const {
    MarchParams p;
    p.method = GetParam().method;
    return p;
  }
};

TEST_P(DevicePaths, OpenGlThroughEglAndOsMesaAgreeOnLlvmpipe) {
  const OpenGlPaths& gl = opengl_paths();
  if (!gl.egl) GTEST_SKIP() << "EGL makes no context on llvmpipe here (see `flatmarch backends`)";
  if (!gl.osmesa) GTEST_SKIP() << "OSMesa makes no context on llvmpipe here";
  const Scene& s = scene();
  const Frame a = gl.through_egl->render(s, s.camera, kWidth, kHeight, params(), {});
  const Frame b = gl.through_osmesa->render(s, s.camera, kWidth, kHeight, params(), {});
  expect_identical(a, b);
}

TEST_P(DevicePaths, OpenGlKernelShapesMarchAlike) {
  const OpenGlShapes& gl = opengl_shapes();
  if (const Availability a = gl.software.availability(); !a.available)
    GTEST_SKIP() << "the opengl backend is unavailable here: " << a.reason;
  const Scene& s = scene();
  const Frame a = gl.software.render(s, s.camera, kWidth, kHeight, params(), {});
  const Frame b = gl.gpu.render(s, s.camera, kWidth, kHeight, params(), {});
  expect_same_rays(a, b);
}

// The frame read back directly is made once for both checks, and the staging copy, which moves
// bytes whichever rays they hold, reads back one method a scene: each frame is a pipeline built
// under the validation layer, and four a case took 47 s on an idle 2-core Zen 5, these 34 s.
TEST_P(DevicePaths, VulkanReadBacksAndKernelShapesAgree) {
  const VulkanPaths& vk = vulkan_paths();
  if (const Availability a = vk.direct.availability(); !a.available)
    GTEST_SKIP() << "the vulkan backend is unavailable here: " << a.reason;
  const Scene& s = scene();
  const Frame direct = vk.direct.render(s, s.camera, kWidth, kHeight, params(), {});
  {
    SCOPED_TRACE("the gpu kernel shape against the software one");
    expect_same_rays(direct, vk.gpu_shape.render(s, s.camera, kWidth, kHeight, params(), {}));
  }
  if (GetParam().method != Method::sphere) return;
  ASSERT_TRUE(vk.staging.reads_through_staging());
  if (vk.direct.reads_through_staging())
    GTEST_SKIP() << "this device's memory is not host-visible: every frame takes the staging path";
  SCOPED_TRACE("read back through a staging copy against directly");
  expect_identical(direct, vk.staging.render(s, s.camera, kWidth, kHeight, params(), {}));
}

std::vector<Case> cases() {
  std::vector<Case> all;
  for (const auto& file : scene_files())
    for (Method m : kKernelMethods) all.push_back({file.stem().string(), m});
  return all;
}

INSTANTIATE_TEST_SUITE_P(Gallery, DevicePaths, testing::ValuesIn(cases()),
                         [](const testing::TestParamInfo<Case>& p) {
                           return p.param.scene + "_" + to_string(p.param.method);
                         });

}  // namespace
}  // namespace flatmarch
