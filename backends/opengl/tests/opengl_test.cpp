// The OpenGL backend (headless, through EGL or OSMesa): progress in bands, the generated shader
// and its compile errors, its devices, and the command line (backend_contract_test holds it to
// what every backend promises, gallery_conformance_test against the oracle on the gallery,
// device_paths_test holds EGL and OSMesa to the same frames). Skipped, visibly, when no OpenGL 4.5
// context can be made here.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <regex>

#include <nlohmann/json.hpp>

#include "backends/opengl/gl_kernel.hpp"
#include "backends/opengl/opengl.hpp"
#include "backends/opengl/tests/opengl_backend.hpp"
#include "backends/scalar/scalar.hpp"
#include "kernels/scene_shader.hpp"
#include "tests/gallery.hpp"
#include "tests/gpu_backend_checks.hpp"
#include "tests/oracle_compare.hpp"
#include "tests/process.hpp"

namespace flatmarch {
namespace {

using test::opengl;

TEST(OpenGl, ReportsProgressInBandsToTheEnd) {
  SKIP_WITHOUT_OPENGL();
  test::expect_progress_in_bands(opengl());
}

TEST(OpenGl, AFrameOfTheColourAloneIsTheWholeFramesColourInEitherShape) {
  SKIP_WITHOUT_OPENGL();
  test::expect_colour_frames_as_whole_frames(opengl());
  const OpenGlBackend other(BackendOptions{
      .kernel_shape = opengl().device()->kernel_shape == "gpu" ? "software" : "gpu"});
  test::expect_colour_frames_as_whole_frames(other);
}

TEST(OpenGl, CamerasWithinAndOutsideTheBandSeeAsTheScalarKernel) {
  SKIP_WITHOUT_OPENGL();
  test::expect_band_views_as_scalar(opengl());
}

TEST(OpenGl, ScenesOfOneShaderDrawTheirOwnTablesInEitherShape) {
  SKIP_WITHOUT_OPENGL();
  test::expect_each_scene_its_own_tables(opengl());
  const OpenGlBackend other(BackendOptions{
      .kernel_shape = opengl().device()->kernel_shape == "gpu" ? "software" : "gpu"});
  test::expect_each_scene_its_own_tables(other);
}

TEST(OpenGlShader, ACameraWithinTheBandGetsAShaderWithoutTheEntryIntoIt) {
  const Scene& scene = test::gallery_scene("l_shape");
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, {});
  const float height = tables.params.height;
  EXPECT_TRUE(kernel::within_band(tables, Vec3(0.0, 0.0, 0.0)));
  EXPECT_TRUE(kernel::within_band(tables, Vec3(0.0, 0.0, height)));
  EXPECT_FALSE(kernel::within_band(tables, Vec3(0.0, 0.0, std::nextafter(height, 1e9f))));
  EXPECT_FALSE(kernel::within_band(tables, Vec3(0.0, 0.0, -1e-6)));
  const std::string from_band = "#define FLATMARCH_FROM_BAND";
  EXPECT_NE(kernel::scene_fragment_shader(tables, {.from_band = true}).find(from_band),
            std::string::npos);
  EXPECT_NE(kernel::scene_compute_shader(tables, {.from_band = true}).find(from_band),
            std::string::npos);
  EXPECT_EQ(kernel::scene_fragment_shader(tables).find(from_band), std::string::npos);
  EXPECT_EQ(
      kernel::scene_fragment_shader(tables, {.trace = true, .from_band = true}).find(from_band),
      std::string::npos)
      << "a probe ray may start anywhere";
}

TEST(OpenGlShader, BakesTheTablesAndSpecialisesOnTheFeatures) {
  const Scene& scene = test::gallery_scene("mirror_square");
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, {});
  const std::string source = kernel::scene_fragment_shader(tables);
  EXPECT_NE(source.find("const EdgeRecord edges[" + std::to_string(tables.edges.size()) + "]"),
            std::string::npos);
  EXPECT_NE(source.find("const uint FEATURES = " + std::to_string(tables.features) + "u;"),
            std::string::npos);
  EXPECT_EQ(source.find("readonly buffer EdgeTable"), std::string::npos);  // no table buffers
  EXPECT_EQ(source.find("#define FLATMARCH_TRACE"), std::string::npos)
      << "a frame shader records no events";
  // The first edge's first coordinate, printed to read back as the same float.
  char first[32];
  std::snprintf(first, sizeof first, "%.9g", static_cast<double>(tables.edges[0].segment.x));
  EXPECT_NE(source.find(std::string("EdgeRecord(vec4(") + first), std::string::npos);
}

TEST(OpenGlShader, CompileErrorsShowTheGeneratedLinesAround) {
  const std::string source = "line one\nline two\nline three\nline four\nline five\n";
  const std::string log = "0:3(5): error: `three' undeclared\n0:1(1): warning: unused\n";
  const std::string text = kernel::annotate_log(source, log, 1);
  EXPECT_NE(text.find(">    3  line three"), std::string::npos) << text;
  EXPECT_NE(text.find("     2  line two"), std::string::npos) << text;
  EXPECT_NE(text.find("     4  line four"), std::string::npos) << text;
  EXPECT_EQ(text.find("line five"), std::string::npos) << text;  // outside the context
  EXPECT_EQ(text.find(">    1"), std::string::npos) << "warnings are not shown with errors";
}

TEST(OpenGlShader, NvidiasCompileErrorsShowTheGeneratedLinesAround) {
  // NVIDIA's format, with the two errors' texts as its driver (580.159.04, an H200) wrote them
  // for a broken call and a wrong type; the line numbers and the warning are made up.
  const std::string source = "line one\nline two\nline three\nline four\nline five\n";
  const std::string log =
      "0(2) : error C1503: undefined variable \"no_such_name\"\n"
      "0(4) : error C1035: assignment of incompatible types\n"
      "0(1) : warning C7050: \"x\" might be used before being initialized\n";
  const std::string text = kernel::annotate_log(source, log, 0);
  EXPECT_NE(text.find(">    2  line two"), std::string::npos) << text;
  EXPECT_NE(text.find(">    4  line four"), std::string::npos) << text;
  EXPECT_EQ(text.find("line three"), std::string::npos) << text;  // no context asked for
  EXPECT_EQ(text.find(">    1"), std::string::npos) << "warnings are not shown with errors";
  // With no error, the warnings' lines are shown.
  EXPECT_NE(
      kernel::annotate_log(source, "0(5) : warning C7050: unused\n", 0).find(">    5  line five"),
      std::string::npos);
}

TEST(OpenGlShader, DriverErrorsNameTheBrokenLine) {
  SKIP_WITHOUT_OPENGL();
  const Scene& scene = test::gallery_scene("torus");
  std::string source = kernel::scene_fragment_shader(kernel::compile_scene<float>(scene, {}));
  const std::string call = "Ray r = march(u_polygon, u_from, normalize(";
  const size_t at = source.find(call);
  ASSERT_NE(at, std::string::npos);
  source.replace(at, call.size(), "Ray r = march(no_such_name, u_from, normalize(");
  try {
    opengl().compile(source);
    FAIL() << "a broken shader compiled";
  } catch (const kernel::ShaderError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_name"), std::string::npos);
    // The broken line is shown, marked.
    EXPECT_TRUE(std::regex_search(std::string(e.what()),
                                  std::regex(R"(\n> *[0-9]+ +Ray r = march\(no_such_name)")))
        << e.what();
  }
}

TEST(OpenGlCli, RendersWithTheOpenGlBackendAndWritesTheAovs) {
  SKIP_WITHOUT_OPENGL();
  const std::string dir = test::make_temp_dir();
  const auto r = test::run_flatmarch(
      {"render", std::string(FLATMARCH_SOURCE_DIR) + "/scenes/l_shape.json", "--backend", "opengl",
       "--method", "analytic", "--size", "64x36", "-o", dir + "/l.png"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir + "/l.png"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/l.exr"));
}

TEST(OpenGlCli, ShaderPrintsTheSourceAndCompileReportsErrorsWithExit2) {
  SKIP_WITHOUT_OPENGL();
  const std::string scene = std::string(FLATMARCH_SOURCE_DIR) + "/scenes/torus.json";
  const auto printed = test::run_flatmarch({"shader", scene});
  ASSERT_EQ(printed.exit_code, 0) << printed.err;
  EXPECT_EQ(printed.out.rfind("#version 450", 0), 0u);
  EXPECT_NE(printed.out.find("Ray march(int polygon, vec3 from, vec3 dir)"), std::string::npos);
  const auto compiled = test::run_flatmarch({"shader", scene, "--compile"});
  EXPECT_EQ(compiled.exit_code, 0) << compiled.err;
  EXPECT_NE(compiled.err.find("compiles"), std::string::npos);

  const std::string file = test::make_temp_dir() + "/broken.glsl";
  std::string broken = printed.out;
  broken.replace(broken.find("out_color = vec4(shade(r), 1.0);"), 32, "out_color = shade(r);");
  std::ofstream(file) << broken;
  const auto failed = test::run_flatmarch({"shader", scene, "--compile", "--file", file});
  EXPECT_EQ(failed.exit_code, 2);
  EXPECT_NE(failed.err.find("error: " + file), std::string::npos) << failed.err;
  EXPECT_NE(failed.err.find("out_color = shade(r);"), std::string::npos) << failed.err;
}

std::string scene_path(const std::string& name) {
  return std::string(FLATMARCH_SOURCE_DIR) + "/scenes/" + name + ".json";
}

// `flatmarch backends --json`'s opengl entry, run with `environment` (VAR=VALUE) set.
nlohmann::json opengl_entry(const std::vector<std::string>& environment = {}) {
  std::vector<std::string> argv = {"env"};
  argv.insert(argv.end(), environment.begin(), environment.end());
  argv.insert(argv.end(), {FLATMARCH_BINARY, "backends", "--json"});
  const auto listed = test::run_process(argv);
  EXPECT_EQ(listed.exit_code, 0) << listed.err;
  for (const auto& b : nlohmann::json::parse(listed.out))
    if (b["name"] == "opengl") return b;
  ADD_FAILURE() << "no opengl backend listed";
  return {};
}

TEST(OpenGlCli, BackendsListsTheDevicesOfEglAndOsMesaAndRenderRunsOnEach) {
  SKIP_WITHOUT_OPENGL();
  const nlohmann::json gl = opengl_entry();
  ASSERT_TRUE(gl.contains("devices")) << gl;
  bool egl = false, osmesa = false;
  int defaults = 0;
  const std::string dir = test::make_temp_dir();
  for (const auto& d : gl["devices"]) {
    const std::string platform = d["platform"].get<std::string>();
    defaults += d["default"].get<bool>() ? 1 : 0;
    if (!d["usable"].get<bool>()) {
      EXPECT_FALSE(d["reason"].get<std::string>().empty()) << d;
      continue;
    }
    egl = egl || platform.rfind("EGL", 0) == 0;
    osmesa = osmesa || platform == "OSMesa";
    EXPECT_FALSE(d["renderer"].get<std::string>().empty()) << d;
    EXPECT_EQ(d["version"].get<std::string>().rfind("4.", 0), 0u) << d;
    if (d["renderer"].get<std::string>().find("llvmpipe") != std::string::npos) {
      EXPECT_TRUE(d["software"].get<bool>()) << d;
    }
    const std::string index = std::to_string(d["index"].get<int>());
    const auto r = test::run_flatmarch({"render", scene_path("l_shape"), "--backend", "opengl",
                                        "--device", index, "--method", "analytic", "--size",
                                        "32x18", "-o", dir + "/" + index + ".png"});
    EXPECT_EQ(r.exit_code, 0) << platform << ": " << r.err;
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + index + ".exr"));
  }
  EXPECT_EQ(defaults, 1) << gl;
  EXPECT_TRUE(osmesa) << "OSMesa makes no context here: " << gl;
  if (!egl) std::cout << "[ note     ] EGL makes no context here: " << gl["devices"] << "\n";
  // The device that draws names itself beside the figures.
  ASSERT_TRUE(gl.contains("device")) << gl;
  EXPECT_FALSE(gl["device"]["driver"].get<std::string>().empty()) << gl;
}

TEST(OpenGlCli, AnUnknownDeviceExits3AndListsTheDevices) {
  SKIP_WITHOUT_OPENGL();
  const auto r =
      test::run_flatmarch({"render", scene_path("torus"), "--backend", "opengl", "--device",
                           "no such device", "-o", test::make_temp_dir() + "/x.png"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("no OpenGL device matches --device \"no such device\" (devices: 0 "),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("(OSMesa)"), std::string::npos) << r.err;
}

TEST(OpenGlCli, WithoutAnEglDriverOsMesaDrawsAndEglSaysWhy) {
  SKIP_WITHOUT_OPENGL();
  // libglvnd's EGL reads its vendors from this variable when set: here, none.
  const std::string no_vendor = "__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/egl_vendor.json";
  const nlohmann::json gl = opengl_entry({no_vendor});
  ASSERT_TRUE(gl["available"].get<bool>()) << gl;
  EXPECT_EQ(gl["device"]["platform"], "OSMesa") << gl;
  ASSERT_FALSE(gl["devices"].empty());
  EXPECT_FALSE(gl["devices"][0]["usable"].get<bool>());
  EXPECT_NE(gl["devices"][0]["reason"].get<std::string>().find("EGL finds no driver"),
            std::string::npos)
      << gl;
  const std::string dir = test::make_temp_dir();
  const auto r =
      test::run_process({"env", no_vendor, FLATMARCH_BINARY, "render", scene_path("torus"),
                         "--backend", "opengl", "--size", "16x9", "-o", dir + "/t.png"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST(OpenGlCli, WhereNoDeviceGivesOpenGl45TheBackendIsUnavailableExit3AndSaysWhy) {
  SKIP_WITHOUT_OPENGL();
  // Mesa's softpipe rasteriser has no OpenGL 4.5: neither EGL nor OSMesa can make the context.
  const std::vector<std::string> softpipe = {"GALLIUM_DRIVER=softpipe"};
  const nlohmann::json gl = opengl_entry(softpipe);
  EXPECT_FALSE(gl["available"].get<bool>()) << gl;
  EXPECT_NE(gl["reason"].get<std::string>().find("no OpenGL 4.5 core context can be made"),
            std::string::npos)
      << gl;
  const auto r = test::run_process({"env", softpipe[0], FLATMARCH_BINARY, "render",
                                    scene_path("torus"), "--backend", "opengl", "--size", "16x9",
                                    "-o", test::make_temp_dir() + "/t.png"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("backend opengl is unavailable here"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace flatmarch
