// The exported web page walks as walk() does (motion/walk.hpp), in headless Chromium. Skipped,
// with the reason, where there is no Chromium.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "backends/webgl/chromium.hpp"
#include "motion/walk.hpp"
#include "scene/load.hpp"
#include "tests/process.hpp"

namespace flatmarch::motion {
namespace {

// Issue 23: the same walks from each scene's camera in headless Chromium (the page's ?walk= hook)
// end in the same room, at the same point and yaw to 1e-5, after as many crossings. Scenes of every kind of gluing: translations, mirrors,
// reflections, rotations (a cone), an affine map, a prism's period, an unbounded room.
TEST(WebWalk, ThePageWalksAsTheViewerDoes) {
  const std::optional<std::string> chromium = webgl::find_chromium();
  if (!chromium) GTEST_SKIP() << "no Chromium (Debian's chromium package)";
  // One browser for the eight pages (a browser's start is most of a page's time here); the walk
  // needs no WebGL.
  webgl::Chromium browser(*chromium, {"--disable-gpu"});
  const std::vector<std::array<double, 3>> walks = {
      {1.5, 0.0, 0.0}, {0.0, 2.5, 0.2}, {4.0, 0.0, 0.3}, {-3.0, 1.0, 0.0}, {0.7, -5.0, 0.0}};
  std::string arg;
  for (const auto& w : walks) arg += test::vec3_arg(Vec3(w[0], w[1], w[2])) + ";";
  const std::string dir = test::make_temp_dir();
  int total = 0;
  for (const std::string name : {"l_shape", "double_pentagon", "mirror_square", "klein_bottle",
                                 "cone_pi", "affine_two_rooms", "l_shape_prism", "cylinder"}) {
    SCOPED_TRACE(name);
    const std::string file = std::string(FLATMARCH_SOURCE_DIR) + "/scenes/" + name + ".json";
    const Scene scene = load_scene(file);
    Camera c = scene.camera;
    int crossings = 0;
    for (const auto& w : walks) {
      const WalkResult r = walk(scene, c, w[0], w[1], w[2]);
      c = r.camera;
      crossings += r.crossings;
    }
    const auto exported = test::run_flatmarch({"export-web", file, "-o", dir + "/" + name, "-q"});
    ASSERT_EQ(exported.exit_code, 0) << exported.err;
    browser.navigate("file://" + dir + "/" + name + "/index.html?walk=" + arg, 120.0);
    const std::string title = browser.evaluate("document.title").get<std::string>();
    const std::string walked = "flatmarch: walked ";
    ASSERT_EQ(title.rfind(walked, 0), 0u) << title;
    const auto got = nlohmann::json::parse(title.substr(walked.size()));
    EXPECT_EQ(got["polygon"].get<int>(), c.polygon);
    EXPECT_EQ(got["crossings"].get<int>(), crossings);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(got["position"][k].get<double>(), c.position[k], 1e-5) << k;
    EXPECT_NEAR(std::remainder(got["yaw_deg"].get<double>() - c.yaw_deg, 360.0), 0.0, 1e-5);
    total += crossings;
  }
  EXPECT_GT(total, 10);  // the walks crossed gluings (mirror_square has none: it slides)
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace flatmarch::motion
