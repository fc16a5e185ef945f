// `flatmarch render` and `flatmarch trace` with the scalar backend work for every gallery scene
// and method, and say so when the parameters guarantee a failure.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "backends/backend.hpp"
#include "output/image_io.hpp"
#include "scene/load.hpp"
#include "tests/gallery.hpp"
#include "tests/process.hpp"

namespace flatmarch {
namespace {

namespace fs = std::filesystem;

TEST(CliScalar, RendersAndTracesEveryGalleryScene) {
  // Each method on a third of the scenes keeps the run short; the conformance tests render
  // every scene with every method through the same backend.
  const fs::path dir = test::make_temp_dir();
  std::vector<std::string> methods;
  for (Method m : kKernelMethods) methods.push_back(to_string(m));
  std::vector<std::string> scenes;
  for (const auto& file : test::gallery_files()) scenes.push_back(file.string());
  // Under the sanitizers every fourth scene (tests/gallery.hpp): k = 0, 4, 8, ... still takes
  // each method in turn.
  for (size_t k = 0; k < scenes.size(); k += test::kSanitizedStride) {
    const std::string& scene = scenes[k];
    const std::string& method = methods[k % methods.size()];
    const fs::path out = dir / (fs::path(scene).stem().string() + ".png");
    const auto r = test::run_flatmarch({"render", scene, "-o", out.string(), "--size", "32x18",
                                        "--backend", "scalar", "--method", method});
    ASSERT_EQ(r.exit_code, 0) << scene << " " << method << ": " << r.err;
    EXPECT_TRUE(fs::exists(out));
    EXPECT_TRUE(fs::exists(fs::path(out).replace_extension(".exr")));
    // A ray from the scene's camera.
    const Camera camera = load_scene(scene).camera;
    const auto t = test::run_flatmarch({"trace", scene, "--polygon", std::to_string(camera.polygon),
                                        "--from", test::vec3_arg(camera.position), "--dir",
                                        "1,0.3,-0.2", "--backend", "scalar", "--method",
                                        methods[(k + 1) % methods.size()], "--precision", "f64"});
    ASSERT_EQ(t.exit_code, 0) << scene << ": " << t.err;
    const nlohmann::json trace = nlohmann::json::parse(t.out);
    EXPECT_EQ(trace["backend"], "scalar");
    EXPECT_EQ(trace["method"], methods[(k + 1) % 3]);
    EXPECT_FALSE(trace["events"].empty());
  }
  fs::remove_all(dir);
}

TEST(CliScalar, WarnsOfAnEpsBelowFloat32sResolutionAtAnInfiniteScenesReach) {
  // eps 1e-6 is above 2^-23 x the torus's scale (4), below 2^-23 x (3 + max_distance 100), how
  // far out a ray along the cylinder meets its walls.
  const auto run = [](const std::string& scene) {
    return test::run_flatmarch({"render", FLATMARCH_SOURCE_DIR "/scenes/" + scene + ".json", "-o",
                                test::make_temp_dir() + "/resolution_" + scene + ".png", "--size",
                                "16x9", "--backend", "scalar", "--method", "sphere", "--eps",
                                "1e-6", "--offset", "1e-4"});
  };
  const auto torus = run("torus"), cylinder = run("cylinder");
  ASSERT_EQ(torus.exit_code, 0) << torus.err;
  ASSERT_EQ(cylinder.exit_code, 0) << cylinder.err;
  EXPECT_EQ(torus.err.find("float32's resolution"), std::string::npos) << torus.err;
  EXPECT_NE(cylinder.err.find("below float32's resolution at this scene's reach"),
            std::string::npos)
      << cylinder.err;
}

TEST(CliScalar, AnInfiniteSceneKeepsRaysWithinItsModelledReach) {
  // Rays in an unbounded room must stay within 2^30 of the origin (kernel::kReach): from the
  // cone's camera a max_distance of 2e9 would take them beyond, exit 2; on the torus it is fine.
  const std::string png = test::make_temp_dir() + "/reach.png";
  const auto cone = test::run_flatmarch({"render", FLATMARCH_SOURCE_DIR "/scenes/cone_pi.json",
                                         "-o", png, "--size", "8x4", "--max-distance", "2e9"});
  EXPECT_EQ(cone.exit_code, 2) << cone.err;
  EXPECT_NE(cone.err.find("--max-distance: an unbounded scene is modelled out to 2^30"),
            std::string::npos)
      << cone.err;
  const auto torus = test::run_flatmarch({"render", FLATMARCH_SOURCE_DIR "/scenes/torus.json", "-o",
                                          png, "--size", "8x4", "--max-distance", "2e9"});
  EXPECT_EQ(torus.exit_code, 0) << torus.err;
  const auto trace = test::run_flatmarch({"trace", FLATMARCH_SOURCE_DIR "/scenes/cylinder.json",
                                          "--from", "1,1.1e9,1", "--dir", "0,1,0"});
  EXPECT_EQ(trace.exit_code, 2) << trace.err;
}

TEST(CliScalar, WarnsThatOffsetNotAboveEpsPingPongs) {
  const std::string torus = FLATMARCH_SOURCE_DIR "/scenes/torus.json";
  const auto r =
      test::run_flatmarch({"trace", torus, "--from", "2,2,1", "--dir", "1,0,0", "--backend",
                           "scalar", "--eps", "1e-3", "--offset", "1e-3", "--max-steps", "50"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: --offset"), std::string::npos) << r.err;
  const nlohmann::json trace = nlohmann::json::parse(r.out);
  EXPECT_EQ(trace["events"].back()["kind"], "max_steps");
  EXPECT_EQ(trace["steps"], 50);
}

// Sphere tracing with 3 steps leaves most rays of the torus undecided (max_steps): by default
// they are shaded as fog (no black), with --show-failures magenta; the hit AOV says max_steps
// either way.
TEST(CliScalar, ShowFailuresPaintsTheFailedRaysMagenta) {
  const std::string torus = FLATMARCH_SOURCE_DIR "/scenes/torus.json";
  const fs::path dir = test::make_temp_dir();
  const std::vector<std::string> args{"render", torus,      "--size", "8x6",         "--backend",
                                      "scalar", "--method", "sphere", "--max-steps", "3"};
  for (const bool show : {false, true}) {
    const std::string png = (dir / (show ? "shown.png" : "fog.png")).string();
    std::vector<std::string> a = args;
    a.insert(a.end(), {"-o", png});
    if (show) a.push_back("--show-failures");
    const auto r = test::run_flatmarch(a);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("pixels failed") != std::string::npos, show) << r.err;
    const Png image = read_png(png);
    const Frame aovs = read_aov_exr(aov_path(png));
    int failed = 0;
    for (size_t px = 0; px < aovs.hit.size(); ++px) {
      const uint8_t* p = &image.rgb[3 * px];
      const bool magenta = p[0] == 255 && p[1] == 0 && p[2] == 255;
      EXPECT_GT(std::max({p[0], p[1], p[2]}), 8) << "a black pixel";
      if (aovs.hit[px] != kHitMaxSteps) {
        EXPECT_FALSE(magenta);
        continue;
      }
      ++failed;
      EXPECT_EQ(magenta, show);
    }
    EXPECT_GE(failed, 24);  // most of the 48
  }
}

}  // namespace
}  // namespace flatmarch
