// The interactive viewer, `flatmarch view`, driven by scripts under a virtual display
// (xvfb-run): walking through a glued wall lands where the gluing says, the keys change the
// method, eps, offset and scene, screenshots are the view encoded as `flatmarch render` encodes
// it, and bad scripts and a missing display end with exit codes 2 and 3. Skipped, visibly, when
// xvfb-run is not installed.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <OpenImageIO/imagebuf.h>
#include <nlohmann/json.hpp>

#include "backends/backend.hpp"
#include "backends/opengl/opengl.hpp"
#include "tests/gallery.hpp"
#include "tests/process.hpp"
#include "viewer/controls.hpp"
#include "viewer/script.hpp"

namespace flatmarch {
namespace {

namespace fs = std::filesystem;

constexpr double kDeg = kPi / 180.0;
// The test window: small, since llvmpipe draws every pixel on the CPU.
constexpr int kWidth = 320, kHeight = 180;
// Walking speed in the torus and the L-shape: 0.5 scene.scale per second (viewer/controls.hpp),
// and both scenes' largest vertex coordinate is 4.
constexpr double kSpeed = 2.0;
// Walking crosses a gluing with the point placed 1e-9 scene.scale inside the edge
// (motion/walk.cpp), so positions agree to well within this.
constexpr double kPositionTolerance = 1e-6;

bool on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');)
    if (!dir.empty() && access((fs::path(dir) / program).c_str(), X_OK) == 0) return true;
  return false;
}

#define SKIP_WITHOUT_XVFB()                                                                   \
  if (!on_path("xvfb-run"))                                                                   \
  GTEST_SKIP() << "xvfb-run is not on PATH (Debian: apt-get install xvfb xauth); the viewer " \
                  "needs a display, and these tests give it a virtual one"

std::string scene_path(const std::string& name) {
  return (fs::path(FLATMARCH_SOURCE_DIR) / "scenes" / (name + ".json")).string();
}

class ViewerTest : public testing::Test {
 protected:
  void SetUp() override { dir_ = test::make_temp_dir(); }
  void TearDown() override { fs::remove_all(dir_); }

  std::string file(const std::string& name) const { return (fs::path(dir_) / name).string(); }

  // Runs `flatmarch view SCENE --script` with `script` under xvfb-run, in a small window.
  test::ProcessResult view(const std::string& scene, const std::string& script,
                           const std::vector<std::string>& extra = {}) const {
    const std::string script_file = file("script.txt");
    std::ofstream(script_file) << script;
    std::vector<std::string> argv{"xvfb-run",
                                  "-a",
                                  FLATMARCH_BINARY,
                                  "view",
                                  scene_path(scene),
                                  "--size",
                                  std::to_string(kWidth) + "x" + std::to_string(kHeight),
                                  "--scale",
                                  "0.5",
                                  "--script",
                                  script_file};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return test::run_process(argv, 120.0);
  }

  nlohmann::json state(const std::string& name) const {
    std::ifstream in(file(name));
    EXPECT_TRUE(in) << "no state file " << name;
    return in ? nlohmann::json::parse(in) : nlohmann::json();
  }

  std::string dir_;
};

void expect_position(const nlohmann::json& state, Vec3 expected) {
  ASSERT_EQ(state["position"].size(), 3u);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(state["position"][static_cast<size_t>(k)].get<double>(), expected[k],
                kPositionTolerance)
        << "coordinate " << k;
}

TEST_F(ViewerTest, TorusWalkThroughTheWallItFaces) {
  SKIP_WITHOUT_XVFB();
  const auto r = view("torus",
                      "# start, then 2.4 s forward: 72 frames of 1/30 s\n"
                      "state " +
                          file("start.json") +
                          "\n"
                          "hold W 2.4\n"
                          "state " +
                          file("end.json") + "\n");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json start = state("start.json"), end = state("end.json");
  // The scene file's camera: polygon 0 at (0.6, 0.9, 1.3), yaw 30, pitch -5.
  EXPECT_EQ(start["scene"], "torus");
  EXPECT_EQ(start["polygon"], 0);
  expect_position(start, {0.6, 0.9, 1.3});
  EXPECT_DOUBLE_EQ(start["yaw_deg"].get<double>(), 30.0);
  // 72 frames at 2 units/s: 4.8 units along (cos 30, sin 30). The path meets x = 4 (edge 1,
  // from (4,0) to (4,4)) at y = 0.9 + 3.4 tan 30 = 2.86, away from the corners; edge 1 is glued
  // to edge 3 (x = 0) by the translation (-4, 0), so the walk ends at
  // (0.6 + 4.8 cos 30 - 4, 0.9 + 4.8 sin 30) = (0.7569, 3.3) in the same polygon, same yaw.
  const double d = kSpeed * 72.0 / 30.0;
  EXPECT_DOUBLE_EQ(d, 4.8);
  EXPECT_EQ(end["polygon"], 0);
  expect_position(end,
                  {0.6 + d * std::cos(30.0 * kDeg) - 4.0, 0.9 + d * std::sin(30.0 * kDeg), 1.3});
  EXPECT_NEAR(end["yaw_deg"].get<double>(), 30.0, 1e-9);
  EXPECT_NEAR(end["pitch_deg"].get<double>(), -5.0, 1e-9);
  EXPECT_EQ(end["frames"], 72);
  EXPECT_GT(end["mean_steps"].get<double>(), 1.0);  // the frames were drawn
}

TEST_F(ViewerTest, LShapeTurnWithTheMouseAndWalkThroughAGluedWall) {
  SKIP_WITHOUT_XVFB();
  const auto r = view("l_shape",
                      "# 2300 pixels right at 0.1 degree a pixel: yaw 140 -> -90 (facing -y)\n"
                      "mouse 2300 0\n"
                      "state " +
                          file("turned.json") +
                          "\n"
                          "hold W 0.5\n"
                          "state " +
                          file("end.json") + "\n");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json turned = state("turned.json"), end = state("end.json");
  EXPECT_NEAR(turned["yaw_deg"].get<double>(), -90.0, 1e-9);
  expect_position(turned, {3.2, 0.5, 1.2});  // the scene file's camera, not moved
  // 15 frames at 2 units/s: 1 unit along -y from (3.2, 0.5). The path leaves through edge 1
  // (y = 0, from A = (2,0) to B = (4,0)), glued to edge 3 (from C = (4,2) to D = (2,2)):
  // g(A) = D, g(B) = C, the translation (0, 2). So it ends at (3.2, 0.5 - 1 + 2) = (3.2, 1.5).
  EXPECT_EQ(end["polygon"], 0);
  expect_position(end, {3.2, 1.5, 1.2});
  EXPECT_NEAR(end["yaw_deg"].get<double>(), -90.0, 1e-9);
  EXPECT_EQ(end["frames"], 15);
}

TEST_F(ViewerTest, KeysChangeMethodEpsOffsetAndScene) {
  SKIP_WITHOUT_XVFB();
  const auto r = view("l_shape",
                      "key 3\n"
                      "# eps 1e-4 -> 1.78e-4, below offset 2e-4; offset 2e-4 -> 1.12e-4 would\n"
                      "# not be above eps, so ; is refused; ' then raises it to 3.56e-4\n"
                      "key ]\n"
                      "key ;\n"
                      "key '\n"
                      "state " +
                          file("keys.json") +
                          "\n"
                          "key TAB\n"
                          "frames 1\n"
                          "state " +
                          file("tab.json") + "\n",
                      {"--method", "sphere"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json keys = state("keys.json"), tab = state("tab.json");
  const double step = std::pow(10.0, 0.25);
  EXPECT_EQ(keys["method"], "analytic");
  EXPECT_NEAR(keys["eps"].get<double>(), 1e-4 * step, 1e-15);
  EXPECT_NEAR(keys["offset"].get<double>(), 2e-4 * step, 1e-15);
  // Tab: the next scene of the folder, sorted, from its own camera.
  const std::vector<std::string> names = test::gallery_names();
  const auto at = std::find(names.begin(), names.end(), "l_shape");
  ASSERT_NE(at, names.end());
  const std::string next = at + 1 == names.end() ? names.front() : *(at + 1);
  EXPECT_EQ(fs::path(tab["scene_file"].get<std::string>()).stem(), next);
  EXPECT_EQ(tab["polygon"], test::gallery_scene(next).camera.polygon);
  EXPECT_EQ(tab["method"], "analytic");  // the settings stay
  EXPECT_EQ(tab["frames"], 1);
}

// The screenshot is the view at the window's size, so that it matches `flatmarch render
// --backend opengl` of the same camera, written by the same PNG writer: in the torus, and in the
// double pentagon, whose two rooms' tables the window's program reads from a buffer.
TEST_F(ViewerTest, ScreenshotIsTheViewAtTheWindowSize) {
  SKIP_WITHOUT_XVFB();
  for (const std::string scene : {"torus", "double_pentagon"}) {
    const std::string shot_file = file(scene + ".png");
    const auto r = view(scene, "frames 2\nscreenshot " + shot_file + "\nkey F12\n",
                        {"--screenshot-dir", dir_});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_TRUE(fs::exists(file("flatmarch-screenshot-1.png"))) << "F12 saved nothing: " << r.err;
    fs::remove(file("flatmarch-screenshot-1.png"));
    OIIO::ImageBuf shot(shot_file);
    ASSERT_TRUE(shot.read(0, 0, true, OIIO::TypeDesc::UINT8)) << shot.geterror();
    const OIIO::ImageSpec& spec = shot.spec();
    ASSERT_EQ(spec.width, kWidth);
    ASSERT_EQ(spec.height, kHeight);
    ASSERT_EQ(spec.nchannels, 3);
    std::vector<unsigned char> pixels(static_cast<size_t>(kWidth) * kHeight * 3);
    ASSERT_TRUE(shot.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::UINT8, pixels.data()));
    std::set<int> colours;
    for (size_t px = 0; px < pixels.size(); px += 3)
      colours.insert(pixels[px] << 16 | pixels[px + 1] << 8 | pixels[px + 2]);
    EXPECT_GE(colours.size(), 50u) << scene << ": the screenshot is nearly blank";

    // The backend the window draws with.
    const Backend* opengl = find_backend(OpenGlBackend::kName);
    if (!opengl || !opengl->availability().available) return;  // nothing to compare with here
    const auto rendered =
        test::run_flatmarch({"render", scene_path(scene), "-o", file("render.png"), "--backend",
                             OpenGlBackend::kName, "--method", "sphere", "--size",
                             std::to_string(kWidth) + "x" + std::to_string(kHeight), "--quiet"});
    ASSERT_EQ(rendered.exit_code, 0) << rendered.err;
    OIIO::ImageBuf render(file("render.png"));
    std::vector<unsigned char> expected(pixels.size());
    ASSERT_TRUE(render.read(0, 0, true, OIIO::TypeDesc::UINT8)) << render.geterror();
    ASSERT_TRUE(render.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::UINT8, expected.data()));
    size_t differ = 0;
    for (size_t k = 0; k < pixels.size(); ++k) differ += std::abs(pixels[k] - expected[k]) > 1;
    EXPECT_LE(static_cast<double>(differ), 1e-3 * static_cast<double>(pixels.size()))
        << scene << ": values of the screenshot differ by more than 1 from `flatmarch render "
        << "--backend opengl`";
  }
}

TEST_F(ViewerTest, FramesDrawsThatManyAndExits) {
  SKIP_WITHOUT_XVFB();
  const std::vector<std::string> argv{
      "xvfb-run", "-a",      FLATMARCH_BINARY, "view", scene_path("double_pentagon"),
      "--size",   "320x180", "--frames",       "3"};
  const auto r = test::run_process(argv, 120.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("view: 3 frames"), std::string::npos) << r.err;
}

TEST_F(ViewerTest, MalformedScriptLinesExit2WithTheLineNumber) {
  // The script is read before any window opens: no display needed.
  const struct {
    std::string script, fragment;
  } cases[] = {
      {"frames 1\n\n# fine so far\njump 3\n", ":4: unknown command \"jump\""},
      {"hold W\n", ":1: expected SECONDS"},
      {"key NOPE\n", ":1: unknown key \"NOPE\""},
      {"frames 2 3\n", ":1: unexpected \"3\""},
      {"hold W 0.001\n", ":1: SECONDS must come to 1"},
      {"mouse 1 nan\n", ":1: DY: \"nan\" is not a finite number"},
  };
  for (const auto& c : cases) {
    std::ofstream(file("bad.txt")) << c.script;
    const auto r = test::run_flatmarch(
        {"view", scene_path("torus"), "--script", file("bad.txt"), "--frames", "1"});
    EXPECT_EQ(r.exit_code, 2) << c.script << r.err;
    EXPECT_NE(r.err.find("error: " + file("bad.txt") + c.fragment), std::string::npos)
        << "script " << c.script << " gave: " << r.err;
  }
}

TEST_F(ViewerTest, NoDisplayExits3) {
  const auto r =
      test::run_process({"env", "-u", "DISPLAY", "-u", "WAYLAND_DISPLAY", FLATMARCH_BINARY, "view",
                         scene_path("torus"), "--frames", "1"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("cannot open a window"), std::string::npos) << r.err;
}

TEST(Viewer, HelpListsTheControlsAndTheScriptFormat) {
  const auto r = test::run_flatmarch({"view", "--help"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  for (const char* text : {"Usage: flatmarch view", "W/A/S/D", "hold KEY SECONDS", "--script"})
    EXPECT_NE(r.out.find(text), std::string::npos) << text;
}

TEST_F(ViewerTest, BadSceneAndArgumentsExit2) {
  std::ofstream(file("bad.json")) << "{\"polygons\": []}";
  auto r = test::run_flatmarch({"view", file("bad.json")});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err.rfind("error: " + file("bad.json"), 0), 0u) << r.err;
  r = test::run_flatmarch({"view", scene_path("torus"), "--eps", "1e-3", "--offset", "1e-3"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--offset: must lie above --eps"), std::string::npos) << r.err;
  // No SCENE: the installed gallery's L-shape, from any folder; a name found nowhere is an error.
  r = test::run_flatmarch({"view", "--frames", "1"});
  EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 3) << r.err;  // 3: no display here
  EXPECT_EQ(r.err.find("SCENE"), std::string::npos) << r.err;
  r = test::run_flatmarch({"view", "no_such_scene"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("nor a scene of that name in the gallery"), std::string::npos) << r.err;
}

// The controls and the script parser alone, in process.

TEST(ViewerControls, OffsetStaysAboveEps) {
  MarchParams start;  // eps 1e-4, offset 2e-4
  motion::MarchSettings s(start);
  EXPECT_TRUE(s.step_offset(-1));  // 1.12e-4: still above eps
  s = motion::MarchSettings(start);
  EXPECT_TRUE(s.step_eps(2));  // eps 3.16e-4 passes offset 2e-4, which follows to 3.56e-4
  EXPECT_NEAR(s.params().eps, 1e-4 * std::sqrt(10.0), 1e-18);
  EXPECT_GT(s.params().offset, s.params().eps);
  EXPECT_NEAR(s.params().offset, 2e-4 * std::pow(10.0, 0.25), 1e-18);
  EXPECT_FALSE(s.step_offset(-1));  // 2e-4 would not be above eps
  EXPECT_TRUE(s.step_eps(-2));
  EXPECT_TRUE(s.step_offset(-1));  // back to the start exactly
  EXPECT_EQ(s.params().eps, start.eps);
  EXPECT_EQ(s.params().offset, start.offset);
  for (int k = 0; k < 100; ++k) s.step_eps(1);  // stops at the bound
  EXPECT_LE(s.params().eps, motion::kMaxEps);
  EXPECT_GT(s.params().offset, s.params().eps);
}

TEST(ViewerControls, RenderScaleStepsWithinItsBounds) {
  motion::RenderScale scale(0.5);
  EXPECT_TRUE(scale.step(2));
  EXPECT_EQ(scale.value(), 1.0);
  EXPECT_FALSE(scale.step(1));
  EXPECT_TRUE(scale.step(-2));
  EXPECT_EQ(scale.value(), 0.5);
  for (int k = 0; k < 100; ++k) scale.step(-1);
  EXPECT_EQ(scale.value(), motion::kMinScale);
}

TEST(ViewerScript, ParsesEveryCommand) {
  std::istringstream in(
      "# a comment\n\nhold w 0.5\nkey TAB\nkey ]\nmouse -3.5 2\nclick\nframes 4\n"
      "screenshot out dir/shot.png\nstate s.json\n");
  const std::vector<viewer::ScriptStep> steps = viewer::parse_script(in, "test");
  ASSERT_EQ(steps.size(), 8u);
  EXPECT_EQ(steps[0].kind, viewer::ScriptStep::Kind::hold);
  EXPECT_EQ(steps[0].line, 3);
  EXPECT_EQ(steps[0].key, viewer::key_by_name("W"));
  EXPECT_EQ(steps[0].frames, 15);
  EXPECT_EQ(steps[1].key, viewer::key_by_name("tab"));
  EXPECT_EQ(steps[2].key, viewer::key_by_name("RIGHT_BRACKET"));
  EXPECT_EQ(steps[3].dx, -3.5);
  EXPECT_EQ(steps[3].dy, 2.0);
  EXPECT_EQ(steps[4].kind, viewer::ScriptStep::Kind::click);
  EXPECT_EQ(steps[5].frames, 4);
  EXPECT_EQ(steps[6].path, "out dir/shot.png");
  EXPECT_EQ(steps[7].kind, viewer::ScriptStep::Kind::state);
}

}  // namespace
}  // namespace flatmarch
