// The main job where OpenImageIO is missing (a GPU machine lent for minutes has none): with the
// image module made unloadable (FLATMARCH_MODULE_DIR naming a folder without it), `flatmarch
// report`, `conform` and `sweep` measure every figure a normal run measures but Yee's perceptual
// check, write their JSON, leave the images out and say so once, with how to draw them; `flatmarch
// merge` of the report's results where the module loads draws the recommended gallery and the page.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <nlohmann/json.hpp>

#include "backends/backend.hpp"
#include "backends/oracle/oracle.hpp"
#include "backends/scalar/scalar.hpp"
#include "conformance/compare.hpp"
#include "tests/gallery.hpp"
#include "tests/process.hpp"
#include "tests/report_figures.hpp"

namespace flatmarch {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json read(const fs::path& file) {
  std::ifstream in(file);
  return json::parse(in);
}

// A process of the program under test with the image module unloadable, or not.
test::ProcessResult flatmarch(const std::vector<std::string>& args, const std::string& no_module) {
  std::vector<std::string> argv;
  if (!no_module.empty()) argv = {"env", "FLATMARCH_MODULE_DIR=" + no_module};
  argv.push_back(FLATMARCH_BINARY);
  argv.insert(argv.end(), args.begin(), args.end());
  return test::run_process(argv, 600.0);
}

// A small report: two backends, two methods, scenes of three surface types, the sweep.
// A small report on every CPU backend of the kernel this build has.
std::vector<std::string> small_report(const fs::path& out) {
  std::vector<std::string> args = {"report", "-o", out.string()};
  for (const std::string& b : cpu_backend_names()) args.insert(args.end(), {"--backend", b});
  args.insert(args.end(), {"--method", "analytic", "--method", "sphere", "--size", "32x18",
                           "--conform-size", "32x18", "--repetitions", "2", "--min-time", "0.001",
                           "--sweep-size", "16x9", "--no-scaling", "-q"});
  for (const char* s : {"torus", "l_shape", "mirror_pentagon"})
    args.insert(args.end(),
                {"--scene", std::string(FLATMARCH_SOURCE_DIR) + "/scenes/" + s + ".json"});
  return args;
}

// The figures less what only the module measures: Yee's check wherever it is named (a failed
// check's name or line, a count by check), and the note that names it left out.
void strip_perceptual(json& j) {
  const std::string check = "image.perceptual_failpercent";
  if (j.is_object()) {
    j.erase(check);
    j.erase("unmeasured");
    for (auto& [key, value] : j.items()) strip_perceptual(value);
  } else if (j.is_array()) {
    json kept = json::array();
    for (json& v : j) {
      if (v.is_string() && v.get<std::string>().rfind(check, 0) == 0) continue;
      strip_perceptual(v);
      kept.push_back(v);
    }
    j = kept;
  }
}
json without_perceptual(json figures) {
  strip_perceptual(figures);
  return figures;
}

OIIO::ImageBuf colour(const Frame& f) {
  OIIO::ImageBuf image(OIIO::ImageSpec(f.width, f.height, 3, OIIO::TypeDesc::FLOAT));
  image.set_pixels(OIIO::ROI(0, f.width, 0, f.height, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT,
                   f.rgb.data());
  return image;
}

// The conformance suite's idiff figures are its own (they need no module): OpenImageIO's compare
// and Yee's metric give the same on a sphere-traced frame against the oracle's.
TEST(WithoutTheImageModule, TheIdiffFiguresAreOpenImageIosCompare) {
  for (const char* name : {"cube", "l_shape_singularities"}) {
    const Scene& scene = test::gallery_scene(name);
    MarchParams params;
    params.eps = 1e-2;  // coarse: pixels off by more than the thresholds
    params.offset = 2e-2;
    const Frame got = ScalarBackend().render(scene, scene.camera, 96, 54, params, {});
    params.method = Method::oracle;
    const Frame truth = OracleBackend().render(scene, scene.camera, 96, 54, params, {});
    const conformance::ImageThresholds t{.fail = 0.05, .warn = 0.01};
    const conformance::ImageComparison c =
        conformance::compare_images(got, truth, std::vector<uint8_t>(truth.hit.size(), 0), t);
    const OIIO::ImageBuf a = colour(got), b = colour(truth);
    const OIIO::ImageBufAlgo::CompareResults r = OIIO::ImageBufAlgo::compare(a, b, 0.05f, 0.01f);
    ASSERT_GT(r.nwarn, 0u) << name << ": the frames must differ for the test to tell anything";
    EXPECT_EQ(c.fail, r.nfail) << name;
    EXPECT_EQ(c.warn, r.nwarn) << name;
    EXPECT_EQ(c.max_error, r.maxerror) << name;
    EXPECT_EQ(c.max_x, r.maxx) << name;
    EXPECT_EQ(c.max_y, r.maxy) << name;
    EXPECT_NEAR(c.mean_error, r.meanerror, 1e-12 * r.meanerror) << name;
    EXPECT_NEAR(c.rms_error, r.rms_error, 1e-12 * r.rms_error) << name;
    EXPECT_NEAR(c.psnr, r.PSNR, 1e-9) << name;
    OIIO::ImageBufAlgo::CompareResults yee;
    ASSERT_TRUE(c.perceptual_measured);
    EXPECT_EQ(c.perceptual, static_cast<size_t>(OIIO::ImageBufAlgo::compare_Yee(a, b, yee)));
  }
}

TEST(WithoutTheImageModule, TheReportMeasuresTheFiguresOfANormalRunAndLeavesTheImagesOut) {
  const fs::path dir = test::make_temp_dir(), empty = dir / "no_module";
  fs::create_directories(empty);
  const test::ProcessResult normal = flatmarch(small_report(dir / "normal"), "");
  ASSERT_EQ(normal.exit_code, 0) << normal.err;
  const test::ProcessResult bare = flatmarch(small_report(dir / "bare"), empty.string());
  ASSERT_EQ(bare.exit_code, 0) << bare.err;

  const json a = read(dir / "normal" / "results.json"), b = read(dir / "bare" / "results.json");
  // Every figure alike, verdicts and recommendations too: the gallery's sweep points that fail
  // Yee's check fail others as well.
  const json differ = json::diff(without_perceptual(test::deterministic_report(a)),
                                 without_perceptual(test::deterministic_report(b)));
  EXPECT_TRUE(differ.empty()) << differ.dump().substr(0, 4000);
  EXPECT_EQ(a["ranking"].size(), b["ranking"].size());
  // Every case says which check it left out and why; the normal run's leave none out.
  for (const json& c : b["matrix"]["cases"]) {
    ASSERT_TRUE(c["accuracy"].contains("unmeasured")) << c["name"];
    EXPECT_EQ(c["accuracy"]["unmeasured"][0]["check"], "image.perceptual_failpercent");
    EXPECT_NE(c["accuracy"]["unmeasured"][0]["why"].get<std::string>().find("flatmarch_image.so"),
              std::string::npos);
  }
  for (const json& c : a["matrix"]["cases"]) EXPECT_FALSE(c["accuracy"].contains("unmeasured"));
  // The images: in the normal run's folder, none in the other's, which says so once, and how.
  EXPECT_TRUE(fs::exists(dir / "normal" / "images"));
  EXPECT_TRUE(a.contains("gallery"));
  EXPECT_FALSE(fs::exists(dir / "bare" / "images"));
  EXPECT_FALSE(b.contains("gallery"));
  ASSERT_TRUE(b.contains("left_out"));
  EXPECT_EQ(b["left_out"]["what"], json::array({"image.perceptual_failpercent", "images"}));
  const std::string said = "report: left out, ";
  ASSERT_NE(bare.err.find(said), std::string::npos) << bare.err;
  EXPECT_EQ(bare.err.find(said), bare.err.rfind(said)) << "said once: " << bare.err;
  EXPECT_NE(bare.err.find("flatmarch merge"), std::string::npos) << bare.err;
  EXPECT_EQ(normal.err.find(said), std::string::npos) << normal.err;

  // Finished where the module loads: the recommended gallery and the page drawn.
  const test::ProcessResult merged = flatmarch({"merge", (dir / "bare" / "results.json").string(),
                                                "-o", (dir / "finished" / "results.json").string()},
                                               "");
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  const json c = read(dir / "finished" / "results.json");
  EXPECT_TRUE(c.contains("gallery"));
  EXPECT_EQ(c["recommendation"], b["recommendation"]);
  EXPECT_TRUE(fs::exists(dir / "finished" / "index.html"));
  EXPECT_FALSE(fs::is_empty(dir / "finished" / "images"));
}

TEST(WithoutTheImageModule, ConformMeasuresAndSaysWhatItLeftOut) {
  const fs::path dir = test::make_temp_dir(), empty = dir / "no_module";
  fs::create_directories(empty);
  const std::vector<std::string> args = {"conform",
                                         "--backend",
                                         "scalar",
                                         "--scene",
                                         std::string(FLATMARCH_SOURCE_DIR) + "/scenes/torus.json",
                                         "--size",
                                         "32x18",
                                         "--error-images",
                                         (dir / "errors").string(),
                                         "--json"};
  const test::ProcessResult normal = flatmarch(
      [&] {
        auto a = args;
        a.push_back((dir / "normal.json").string());
        return a;
      }(),
      "");
  ASSERT_EQ(normal.exit_code, 0) << normal.err;
  const test::ProcessResult bare = flatmarch(
      [&] {
        auto a = args;
        a.push_back((dir / "bare.json").string());
        return a;
      }(),
      empty.string());
  ASSERT_EQ(bare.exit_code, 0) << bare.err;
  const json a = read(dir / "normal.json"), b = read(dir / "bare.json");
  ASSERT_EQ(a["cases"].size(), b["cases"].size());
  for (size_t k = 0; k < a["cases"].size(); ++k) {
    json x = a["cases"][k], y = b["cases"][k];
    EXPECT_TRUE(y["image"]["perceptual"].is_null());
    EXPECT_FALSE(x["image"]["perceptual"].is_null());
    for (json* c : {&x, &y})
      for (const char* key : {"seconds", "unmeasured", "error_image"}) c->erase(key);
    x["image"].erase("perceptual");
    y["image"].erase("perceptual");
    json checks = json::array();
    for (const json& check : x["checks"])
      if (check["name"] != "image.perceptual_failpercent") checks.push_back(check);
    x["checks"] = checks;
    EXPECT_EQ(x, y) << a["cases"][k]["scene"] << " " << a["cases"][k]["method"];
  }
  ASSERT_EQ(b["unmeasured"].size(), 1u);
  EXPECT_EQ(b["unmeasured"][0]["check"], "image.perceptual_failpercent");
  EXPECT_FALSE(a.contains("unmeasured"));
  EXPECT_FALSE(std::filesystem::is_empty(dir / "errors")) << "the normal run draws them";
  EXPECT_NE(bare.err.find("conform: left out, Yee's perceptual check and the error images"),
            std::string::npos)
      << bare.err;
}

}  // namespace
}  // namespace flatmarch
