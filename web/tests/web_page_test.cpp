// The exported page's controls as a visitor uses them (issue 23), driven through the DevTools
// protocol in headless Chromium: touch (one finger drags to look, two drag to move), the mouse,
// the wheel, the eps and offset keys (stepped as the viewer steps them, motion/settings.hpp) and
// the floor-plan inset. Skipped, with the reason, where there is no Chromium.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "backends/webgl/chromium.hpp"
#include "backends/webgl/webgl.hpp"
#include "cli/common.hpp"
#include "motion/settings.hpp"
#include "motion/walk.hpp"
#include "scene/load.hpp"
#include "tests/gallery.hpp"
#include "tests/process.hpp"
#include "web/page.hpp"

namespace flatmarch {
namespace {

using nlohmann::json;
constexpr int kWidth = 320, kHeight = 180;

// x as JavaScript's x.toExponential(8) writes it: "1.77827941e-3".
std::string js_exponential(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.8e", x);
  std::string s = text;
  const size_t e = s.find('e');
  std::string exponent = s.substr(e + 1);
  const char sign = exponent[0];
  exponent = exponent.substr(1);
  while (exponent.size() > 1 && exponent[0] == '0') exponent.erase(0, 1);
  return s.substr(0, e + 1) + (sign == '-' ? "-" : "+") + exponent;
}

class WebPage : public testing::Test {
 protected:
  void SetUp() override {
    const std::optional<std::string> chromium = webgl::find_chromium();
    if (!chromium) GTEST_SKIP() << "no Chromium here (Debian's chromium package)";
    browser_ = std::make_unique<webgl::Chromium>(
        *chromium, std::vector<std::string>{"--enable-unsafe-swiftshader"});
    browser_->call(
        "Emulation.setDeviceMetricsOverride",
        {{"width", kWidth}, {"height", kHeight}, {"deviceScaleFactor", 1}, {"mobile", false}});
  }

  // Opens the page of a gallery scene (with its floor plan, as export-web makes it).
  void open(const std::string& name) {
    scene_ = test::gallery_scene(name);
    web::FloorPlan plan{.svg =
                            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10\" "
                            "height=\"20\"><rect width=\"10\" height=\"20\" fill=\"#fff\"/></svg>",
                        .width = 10,
                        .height = 20,
                        .title_height = 5};
    const std::string folder = test::make_temp_dir();
    const std::string file = folder + "/index.html";
    std::ofstream(file) << web::page(scene_, {}, {.floor_plan = plan});
    browser_->navigate("file://" + file);
  }

  json state() { return browser_->evaluate("flatmarchState()"); }

  void touch(const std::string& type, const json& points) {
    browser_->call("Input.dispatchTouchEvent", {{"type", type}, {"touchPoints", points}});
  }
  static json point(double x, double y, int id) { return {{"x", x}, {"y", y}, {"id", id}}; }

  void key(const std::string& k) {
    for (const char* type : {"keyDown", "keyUp"})
      browser_->call("Input.dispatchKeyEvent", {{"type", type}, {"key", k}, {"text", k}});
  }

  std::unique_ptr<webgl::Chromium> browser_;
  Scene scene_;
};

TEST_F(WebPage, OneFingerDragsToLookAndTwoDragToMove) {
  open("torus");
  const json before = state();
  // One finger 50 pixels to the left: the view turns left (yaw up) by 2 * 0.1 degrees a pixel.
  touch("touchStart", json::array({point(200, 90, 1)}));
  touch("touchMove", json::array({point(150, 90, 1)}));
  touch("touchEnd", json::array());
  const json turned = state();
  EXPECT_NEAR(turned["camera"]["yaw_deg"].get<double>(),
              before["camera"]["yaw_deg"].get<double>() + 2 * motion::kDegreesPerPixel * 50, 1e-9);
  EXPECT_EQ(turned["camera"]["position"], before["camera"]["position"]);

  // Two fingers 40 pixels up the screen: forward by 40 / 200 of the scene's scale, as walk()
  // takes it.
  touch("touchStart", json::array({point(100, 120, 1), point(200, 120, 2)}));
  touch("touchMove", json::array({point(100, 80, 1), point(200, 80, 2)}));
  touch("touchEnd", json::array());
  const json moved = state();
  Camera want = scene_.camera;
  want.yaw_deg = turned["camera"]["yaw_deg"].get<double>();
  // The page moves once for each finger's move, half the centroid's motion each.
  want = motion::walk(scene_, want, 20.0 * scene_.scale / 200, 0.0, 0.0).camera;
  want = motion::walk(scene_, want, 20.0 * scene_.scale / 200, 0.0, 0.0).camera;
  EXPECT_EQ(moved["camera"]["polygon"].get<int>(), want.polygon);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(moved["camera"]["position"][k].get<double>(), want.position[k], 1e-9) << k;
  EXPECT_GT(std::hypot(moved["camera"]["position"][0].get<double>() -
                           turned["camera"]["position"][0].get<double>(),
                       moved["camera"]["position"][1].get<double>() -
                           turned["camera"]["position"][1].get<double>()),
            0.0);
}

TEST_F(WebPage, TheMouseLooksAndTheWheelWidensTheView) {
  open("l_shape");
  const json before = state();
  browser_->call(
      "Input.dispatchMouseEvent",
      {{"type", "mousePressed"}, {"x", 100}, {"y", 90}, {"button", "left"}, {"clickCount", 1}});
  browser_->call("Input.dispatchMouseEvent",
                 {{"type", "mouseMoved"}, {"x", 150}, {"y", 90}, {"button", "left"}});
  browser_->call(
      "Input.dispatchMouseEvent",
      {{"type", "mouseReleased"}, {"x", 150}, {"y", 90}, {"button", "left"}, {"clickCount", 1}});
  // 50 pixels right turns right: by 0.1 degrees a pixel with the pointer locked, as the viewer,
  // or by twice that dragging where the browser refuses the lock.
  const double turn =
      before["camera"]["yaw_deg"].get<double>() - state()["camera"]["yaw_deg"].get<double>();
  EXPECT_TRUE(std::abs(turn - 5.0) < 1e-9 || std::abs(turn - 10.0) < 1e-9) << turn;
  browser_->call("Input.dispatchMouseEvent",
                 {{"type", "mouseWheel"}, {"x", 100}, {"y", 90}, {"deltaX", 0}, {"deltaY", 100}});
  EXPECT_DOUBLE_EQ(state()["camera"]["fov_deg"].get<double>(), scene_.camera.fov_deg + 5);
}

TEST_F(WebPage, EpsAndOffsetKeysStepAsTheViewersAndRecompile) {
  open("l_shape");
  motion::MarchSettings viewer_settings{MarchParams{}};
  // Up past the top of eps (offset carried up with it), then offset down until refused.
  for (int k = 0; k < 10; ++k) {
    key("]");
    viewer_settings.step_eps(1);
  }
  for (int k = 0; k < 12; ++k) {
    key(";");
    viewer_settings.step_offset(-1);
  }
  key("[");
  viewer_settings.step_eps(-1);
  const json s = state();
  EXPECT_NEAR(s["eps"].get<double>(), viewer_settings.params().eps, 1e-15);
  EXPECT_NEAR(s["offset"].get<double>(), viewer_settings.params().offset, 1e-15);
  EXPECT_GT(s["offset"].get<double>(), s["eps"].get<double>());
  // The page drew with them (a program compiled with them baked in), with no error.
  browser_->evaluate("new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))");
  EXPECT_EQ(browser_->evaluate("document.title").get<std::string>(), scene_.name + " - flatmarch");
  EXPECT_TRUE(browser_->evaluate("Object.keys(programs).some((k) => k.includes('@'))").get<bool>());
  const std::string source = browser_->evaluate(
      "withParams(scene.shaders[method], flatmarchState().eps, flatmarchState().offset)");
  EXPECT_NE(source.find(js_exponential(viewer_settings.params().eps) + ", " +
                        js_exponential(viewer_settings.params().offset) + ","),
            std::string::npos);
}

TEST_F(WebPage, MShowsAndHidesTheFloorPlan) {
  open("torus");
  EXPECT_TRUE(state()["inset"].get<bool>());
  key("m");
  EXPECT_FALSE(state()["inset"].get<bool>());
  key("m");
  EXPECT_TRUE(state()["inset"].get<bool>());
}

// No Chromium: the webgl backend is unavailable, and a command that needs it exits 3 saying why.
// The page's two kernel shapes (?shape=, --kernel-shape of the webgl backend) march the same rays
// to the same ends in the same steps; unforced, a page on SwiftShader picks the software shape.
TEST(WebGlShapes, TheGpuShapeMarchesAsTheSoftwareShape) {
  const WebGlBackend picked, software(BackendOptions{.kernel_shape = "software"}),
      gpu(BackendOptions{.kernel_shape = "gpu"});
  if (const Availability a = software.availability(); !a.available)
    GTEST_SKIP() << "the webgl backend is unavailable here: " << a.reason;
  EXPECT_EQ(software.device()->kernel_shape, "software");
  EXPECT_EQ(gpu.device()->kernel_shape, "gpu");
  EXPECT_EQ(picked.device()->kernel_shape, picked.device()->software ? "software" : "gpu");
  const Scene& scene = test::gallery_scene("cube");
  for (Method m : {Method::sphere, Method::analytic}) {
    MarchParams params;
    params.method = m;
    const Frame a = software.render(scene, scene.camera, 48, 27, params, {});
    const Frame b = gpu.render(scene, scene.camera, 48, 27, params, {});
    for (size_t px = 0; px < a.hit.size(); ++px) {
      ASSERT_EQ(a.hit[px], b.hit[px]) << to_string(m) << " pixel " << px;
      ASSERT_EQ(a.steps[px], b.steps[px]) << to_string(m) << " pixel " << px;
      ASSERT_EQ(a.crossings[px], b.crossings[px]) << to_string(m) << " pixel " << px;
    }
  }
}

TEST(WebGlCli, WithoutChromiumExits3AndSaysWhy) {
  const std::string out = test::make_temp_dir() + "/x.png";
  const std::string scene = std::string(FLATMARCH_SOURCE_DIR) + "/scenes/torus.json";
  auto r = test::run_process({"env", "FLATMARCH_CHROMIUM=/no/such/chromium", FLATMARCH_BINARY,
                              "render", scene, "--backend", WebGlBackend::kName, "-o", out});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("webgl is unavailable here: cannot run /no/such/chromium"),
            std::string::npos)
      << r.err;
  r = test::run_process({"env", "PATH=/nowhere", FLATMARCH_BINARY, "render", scene, "--backend",
                         WebGlBackend::kName, "-o", out});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("no Chromium found"), std::string::npos) << r.err;
  r = test::run_process({FLATMARCH_BINARY, "render", scene, "--backend", WebGlBackend::kName,
                         "--device", "no such device", "-o", out});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("--device is one of gpu, swiftshader"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace flatmarch
