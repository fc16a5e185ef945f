// The Vulkan backend (lavapipe here, under the validation layer): the generated compute shader
// and glslang's errors, traces cut at max_events, buffers across frame sizes, progress in bands,
// the validation layer's messages, a machine without a Vulkan driver, and the command line
// (backend_contract_test holds it to what every backend promises, gallery_conformance_test
// against the oracle on the gallery). Tests that need a device
// skip, visibly, where there is none.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "backends/scalar/scalar.hpp"
#include "backends/vulkan/spirv.hpp"
#include "backends/vulkan/tests/vulkan_backend.hpp"
#include "kernels/scene_shader.hpp"
#include "kernels/shader_log.hpp"
#include "scene/surfaces.hpp"
#include "tests/gallery.hpp"
#include "tests/gpu_backend_checks.hpp"
#include "tests/oracle_compare.hpp"
#include "tests/process.hpp"

namespace flatmarch {
namespace {

using test::vulkan;

std::string scene_path(const std::string& name) {
  return std::string(FLATMARCH_SOURCE_DIR) + "/scenes/" + name + ".json";
}

TEST(VulkanShader, EveryGallerySceneCompilesToSpirvWithGlslang) {
  for (const std::string& name : test::gallery_names()) {
    const kernel::SceneTables<float> tables =
        kernel::compile_scene<float>(test::gallery_scene(name), {});
    for (bool trace : {false, true}) {
      const std::vector<uint32_t> spirv =
          vulkan::compile_compute(kernel::scene_compute_shader(tables, {.trace = trace}));
      ASSERT_GT(spirv.size(), 5u) << name;
      EXPECT_EQ(spirv[0], 0x07230203u) << name << ": not a SPIR-V module";  // its magic number
    }
  }
}

TEST(VulkanShader, BakesTheTablesOfOneRoomAsPlainArraysAndSpecialises) {
  const Scene& scene = test::gallery_scene("l_shape");
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, {});
  const std::string source = kernel::scene_compute_shader(tables);
  const std::string edges = "EdgeRecord edges[" + std::to_string(tables.edges.size()) + "]";
  ASSERT_NE(source.find("\n" + edges), std::string::npos);
  EXPECT_EQ(source.find("const " + edges), std::string::npos) << "see scene_compute_shader";
  EXPECT_NE(source.find("const KernelParams params"), std::string::npos);
  EXPECT_NE(source.find("const uint FEATURES = " + std::to_string(tables.features) + "u;"),
            std::string::npos);
  EXPECT_NE(source.find("layout(local_size_x = TILE, local_size_y = TILE) in;"), std::string::npos);
  EXPECT_EQ(source.find("#define FLATMARCH_TRACE"), std::string::npos);
  EXPECT_NE(kernel::scene_compute_shader(tables, {.trace = true}).find("#define FLATMARCH_TRACE"),
            std::string::npos);
}

TEST(VulkanShader, AFrameOfTheColourAndAWholeFrameShareOneProgram) {
  // One program a scene for both read-backs (the push constants' order.y picks the outputs), so
  // that the matrix compiles a frame program and a trace program a case, not three programs.
  for (const char* name : {"l_shape", "cube"}) {
    const kernel::SceneTables<float> tables =
        kernel::compile_scene<float>(test::gallery_scene(name), {});
    for (const kernel::ComputeApi api : {kernel::ComputeApi::vulkan, kernel::ComputeApi::opengl}) {
      const std::string colour =
          kernel::scene_compute_shader(tables, {.readback = kernel::Readback::colour}, api);
      EXPECT_EQ(colour,
                kernel::scene_compute_shader(tables, {.readback = kernel::Readback::all}, api))
          << name;
      EXPECT_NE(colour.find("colours[px] = packUnorm4x8"), std::string::npos) << name;
      EXPECT_NE(colour.find("pixels[n + px] = uvec4("), std::string::npos) << name;
    }
  }
}

std::vector<std::filesystem::path> modules_in(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(folder))
    if (e.path().extension() == ".spv") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(VulkanSpirvCache, AModuleIsKeptForTheNextProcessAndABrokenOneCompiledAgain) {
  const std::string home = test::make_temp_dir();
  ASSERT_EQ(setenv("XDG_CACHE_HOME", home.c_str(), 1), 0);
  ASSERT_EQ(unsetenv("FLATMARCH_SPIRV_CACHE"), 0);
  const std::filesystem::path folder = vulkan::spirv_cache_folder();
  EXPECT_EQ(folder, std::filesystem::path(home) / "flatmarch" / "spirv");
  const std::string source = kernel::scene_compute_shader(
      kernel::compile_scene<float>(test::gallery_scene("l_shape"), {}));
  const std::vector<uint32_t> compiled = vulkan::compile_compute(source);
  EXPECT_EQ(vulkan::compile_compute_cached(source), compiled);
  const std::vector<std::filesystem::path> files = modules_in(folder);
  ASSERT_EQ(files.size(), 1u);

  // Read back, not compiled again: a word changed in the file comes back changed.
  const auto size = std::filesystem::file_size(files[0]);
  {
    std::fstream f(files[0], std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(size - 4));
    const uint32_t marked = compiled.back() ^ 0x5a5a5a5au;
    f.write(reinterpret_cast<const char*>(&marked), 4);
  }
  const std::vector<uint32_t> read = vulkan::compile_compute_cached(source);
  ASSERT_EQ(read.size(), compiled.size());
  EXPECT_EQ(read.back(), compiled.back() ^ 0x5a5a5a5au);

  // Cut short: compiled again and written whole.
  std::filesystem::resize_file(files[0], 10);
  EXPECT_EQ(vulkan::compile_compute_cached(source), compiled);
  EXPECT_EQ(std::filesystem::file_size(files[0]), size);
  EXPECT_EQ(vulkan::compile_compute_cached(source), compiled);

  // Another source, another module; and none with the cache turned off.
  const std::string other =
      kernel::scene_compute_shader(kernel::compile_scene<float>(test::gallery_scene("torus"), {}));
  EXPECT_EQ(vulkan::compile_compute_cached(other), vulkan::compile_compute(other));
  EXPECT_EQ(modules_in(folder).size(), 2u);
  ASSERT_EQ(setenv("FLATMARCH_SPIRV_CACHE", "0", 1), 0);
  EXPECT_TRUE(vulkan::spirv_cache_folder().empty());
  ASSERT_EQ(unsetenv("FLATMARCH_SPIRV_CACHE"), 0);
}

TEST(VulkanSpirvCache, KeepsTheNewestModulesPastItsBound) {
  const std::filesystem::path folder = test::make_temp_dir();
  const auto now = std::filesystem::file_time_type::clock::now();
  for (int k = 0; k < 5; ++k) {
    const std::filesystem::path f = folder / ("m" + std::to_string(k) + ".spv");
    std::ofstream(f) << k;
    std::filesystem::last_write_time(f, now - std::chrono::hours(10 - k));  // m4 the newest
  }
  std::ofstream(folder / "notes.txt") << "not a module";
  vulkan::keep_newest_modules(folder, 5, 2);  // not past its bound: all stay
  EXPECT_EQ(modules_in(folder).size(), 5u);
  vulkan::keep_newest_modules(folder, 4, 2);
  EXPECT_EQ(modules_in(folder),
            (std::vector<std::filesystem::path>{folder / "m3.spv", folder / "m4.spv"}));
  EXPECT_TRUE(std::filesystem::exists(folder / "notes.txt"));
}

// The number of type T at `offset` in a table buffer's bytes.
template <typename T>
T number_at(const std::string& bytes, size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof v);
  return v;
}

TEST(VulkanShader, ReadsTheTablesOfSeveralRoomsFromTheTableBuffer) {
  const Scene& scene = test::gallery_scene("cube");
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, {});
  ASSERT_TRUE(kernel::tables_in_buffer(tables));
  const std::string source = kernel::scene_compute_shader(tables);
  EXPECT_NE(source.find("layout(std430, binding = 6) readonly buffer SceneTableBuffer {\n"
                        "  ivec4 polygons[6];\n  EdgeRecord edges[24];\n"
                        "  ObjectRecord objects[1];\n};"),
            std::string::npos);
  EXPECT_EQ(source.find("EdgeRecord edges[24] ="), std::string::npos) << "not baked in too";
  EXPECT_NE(source.find("const KernelParams params"), std::string::npos) << "still baked in";
  // The buffer as std430 lays it out: six squares of four edges each, then their 24 edges
  // (112 bytes each), then the one solid (64 bytes).
  const std::string bytes = kernel::table_buffer(tables);
  ASSERT_EQ(bytes.size(), 6u * 16 + 24u * 112 + 64);
  const auto int_at = [&](size_t offset) { return number_at<int32_t>(bytes, offset); };
  const auto float_at = [&](size_t offset) { return number_at<float>(bytes, offset); };
  for (int p = 0; p < 6; ++p) {
    EXPECT_EQ(int_at(16 * static_cast<size_t>(p)), 4 * p) << "first edge of polygon " << p;
    EXPECT_EQ(int_at(16 * static_cast<size_t>(p) + 4), 4) << "edges of polygon " << p;
  }
  // The first face is the square [0, 2]^2: its first edge from (0, 0) to (2, 0).
  EXPECT_EQ(float_at(96 + 0), 0.0f);
  EXPECT_EQ(float_at(96 + 4), 0.0f);
  EXPECT_EQ(float_at(96 + 8), 2.0f);
  EXPECT_EQ(float_at(96 + 12), 0.0f);
  // The solid's centre (1, 1, 1).
  EXPECT_EQ(float_at(96 + 24 * 112 + 0), 1.0f);
  EXPECT_EQ(float_at(96 + 24 * 112 + 8), 1.0f);
  // A scene of one room bakes them in and has no buffer.
  EXPECT_TRUE(
      kernel::table_buffer(kernel::compile_scene<float>(test::gallery_scene("torus"), {})).empty());
}

// A trace is one program for every scene and method (kernel::shared_trace): its tables,
// parameters and features come in the table buffer, laid out as the shader declares them.
TEST(VulkanShader, ATraceIsOneProgramForEveryScene) {
  const Scene& cube = test::gallery_scene("cube");
  MarchParams analytic;
  analytic.method = Method::analytic;
  analytic.eps = 1e-3;
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(cube, analytic);
  const std::string source = kernel::scene_compute_shader(tables, {.trace = true});
  for (const char* name : {"torus", "l_shape", "mirror_double_pentagon", "double_pentagon_prism"})
    for (const Method m : kKernelMethods) {
      MarchParams params;
      params.method = m;
      const kernel::SceneTables<float> other =
          kernel::compile_scene<float>(test::gallery_scene(name), params);
      ASSERT_TRUE(kernel::shared_trace(other)) << name;
      EXPECT_EQ(kernel::scene_compute_shader(other, {.trace = true}), source)
          << name << " " << to_string(m);
      EXPECT_EQ(kernel::scene_fragment_shader(other, {.trace = true}),
                kernel::scene_fragment_shader(tables, {.trace = true}))
          << name << " " << to_string(m);
    }
  EXPECT_EQ(source.find("const KernelParams params"), std::string::npos) << "nothing baked in";
  EXPECT_EQ(source.find("const uint FEATURES"), std::string::npos);
  EXPECT_NE(source.find("#define FEATURES (trace_scene.x)"), std::string::npos);
  // In the gpu shape whatever the backend's, which compiles a quarter as long on lavapipe.
  EXPECT_NE(source.find("#define FLATMARCH_GPU_SHAPE"), std::string::npos);
  EXPECT_EQ(kernel::scene_compute_shader(tables, {.trace = true, .shape = KernelShape::gpu}),
            source);
  EXPECT_FALSE(vulkan::compile_compute(source).empty());

  // The buffer: the parameters (192 bytes), the features, 256 polygons, 64 objects, the edges.
  const std::string bytes = kernel::table_buffer(tables, true);
  const size_t objects = 192 + 16 + kernel::kTracePolygons * 16,
               edges = objects + kernel::kTraceObjects * 64;
  ASSERT_EQ(bytes.size(), edges + 24u * 112);
  const auto int_at = [&](size_t offset) { return number_at<int32_t>(bytes, offset); };
  const auto float_at = [&](size_t offset) { return number_at<float>(bytes, offset); };
  EXPECT_EQ(int_at(0), kMethodAnalytic);
  EXPECT_EQ(int_at(8), 6) << "polygon_count";
  EXPECT_EQ(float_at(16), 1e-3f) << "eps";
  EXPECT_EQ(static_cast<uint>(int_at(192)), tables.features);
  EXPECT_EQ(int_at(208 + 5 * 16), 20) << "the sixth face's first edge";
  EXPECT_EQ(int_at(208 + 6 * 16 + 4), 0) << "past the faces: zeros";
  EXPECT_EQ(float_at(objects + 0), 1.0f) << "the solid's centre (1, 1, 1)";
  EXPECT_EQ(float_at(edges + 8), 2.0f) << "the first edge from (0, 0) to (2, 0)";

  // A scene of more rooms than the shared trace holds traces with a program of its own.
  const kernel::SceneTables<float> stairs =
      kernel::compile_scene<float>(staircase_surface(2 * kernel::kTracePolygons), {});
  EXPECT_FALSE(kernel::shared_trace(stairs));
  EXPECT_NE(kernel::scene_compute_shader(stairs, {.trace = true}).find("SceneTableBuffer"),
            std::string::npos);
  EXPECT_EQ(kernel::table_buffer(stairs, true), kernel::table_buffer(stairs));
}

TEST(VulkanShader, RowsOfWorkgroupsDrawEveryRowOnceInASpreadOrder) {
  for (int rows = 1; rows <= 300; ++rows) {
    const int stride = kernel::row_stride(rows);
    std::vector<int> drawn(static_cast<size_t>(rows), 0);
    for (int k = 0; k < rows; ++k) ++drawn[static_cast<size_t>(k * stride % rows)];
    EXPECT_EQ(std::count(drawn.begin(), drawn.end(), 1), rows)
        << rows << " rows, stride " << stride;
    if (rows < 8) continue;
    // The first half of the workgroups (one of two threads' runs) draws rows from both halves
    // of the band, about as many from each.
    int top = 0;
    for (int k = 0; k < rows / 2; ++k) top += k * stride % rows < rows / 2;
    EXPECT_NEAR(top, rows / 4, rows / 8 + 1) << rows << " rows, stride " << stride;
  }
}

TEST(VulkanShader, GlslangErrorsNameTheBrokenLine) {
  const Scene& scene = test::gallery_scene("torus");
  std::string source = kernel::scene_compute_shader(kernel::compile_scene<float>(scene, {}));
  const std::string call = "vec3 color = shade(r);";  // in the frame variant's main()
  const size_t at = source.find(call);
  ASSERT_NE(at, std::string::npos);
  source.replace(at, call.size(), "vec3 color = shade(no_such_name);");
  try {
    vulkan::compile_compute(source);
    FAIL() << "a broken shader compiled";
  } catch (const kernel::ShaderError& e) {
    const std::string text = e.what();
    EXPECT_NE(text.find("'no_such_name' : undeclared identifier"), std::string::npos) << text;
    EXPECT_NE(text.find("vec3 color = shade(no_such_name);"), std::string::npos) << text;
    // The line glslang names is marked.
    const size_t marked = text.find("\n>");
    ASSERT_NE(marked, std::string::npos) << text;
    EXPECT_NE(text.substr(marked, text.find('\n', marked + 1) - marked).find("no_such_name"),
              std::string::npos)
        << text;
  }
}

TEST(Vulkan, AFrameOfTheColourAloneIsTheWholeFramesColourInEitherShapeAndReadBack) {
  SKIP_WITHOUT_VULKAN();
  test::expect_colour_frames_as_whole_frames(vulkan());
  const VulkanBackend other(
      BackendOptions{.kernel_shape = vulkan().device()->kernel_shape == "gpu" ? "software" : "gpu",
                     .vk_staging = true,
                     .validation = true});
  test::expect_colour_frames_as_whole_frames(other);
}

TEST(Vulkan, CamerasWithinAndOutsideTheBandSeeAsTheScalarKernel) {
  SKIP_WITHOUT_VULKAN();
  test::expect_band_views_as_scalar(vulkan());
}

TEST(Vulkan, ScenesOfOneShaderDrawTheirOwnTables) {
  SKIP_WITHOUT_VULKAN();
  test::expect_each_scene_its_own_tables(vulkan());
}

TEST(Vulkan, TraceKeepsAtMostMaxEventsAndCountsTheRest) {
  SKIP_WITHOUT_VULKAN();
  const Scene& scene = test::gallery_scene("torus");
  const Ray ray = test::generic_rays(scene).front();
  const Trace all = vulkan().trace(scene, ray, {}, 1000);
  ASSERT_GT(all.events.size(), 3u);
  const Trace cut = vulkan().trace(scene, ray, {}, 2);
  ASSERT_EQ(cut.events.size(), 2u);
  EXPECT_EQ(test::describe(cut.events[1]), test::describe(all.events[1]));
  EXPECT_EQ(vulkan().trace(scene, ray, {}, 0).events.size(), 0u);
}

TEST(Vulkan, ReportsProgressInBandsToTheEnd) {
  SKIP_WITHOUT_VULKAN();
  test::expect_progress_in_bands(vulkan());
}

// The hit AOV's pixels that differ from the scalar backend's.
size_t differences(const Frame& a, const Frame& b) {
  size_t n = 0;
  for (size_t px = 0; px < a.hit.size(); ++px) n += a.hit[px] != b.hit[px];
  return n;
}

TEST(Vulkan, FramesOfEverySizeAgreeWithScalarAsBuffersGrow) {
  SKIP_WITHOUT_VULKAN();
  // Sizes that are not multiples of the 8x8 workgroups or of the 64-row bands, small after large
  // (the pixel buffer is kept and grown): every pixel written, in its place, with every channel.
  const Scene& scene = test::gallery_scene("mirror_square");
  for (const auto& [w, h] : {std::pair{13, 7}, {97, 131}, {5, 3}, {64, 64}}) {
    const Frame scalar = ScalarBackend().render(scene, scene.camera, w, h, {}, {});
    const Frame got = vulkan().render(scene, scene.camera, w, h, {}, {});
    ASSERT_EQ(got.hit.size(), static_cast<size_t>(w * h));
    EXPECT_LE(differences(got, scalar), static_cast<size_t>(w * h) / 200 + 1) << w << "x" << h;
    size_t steps = 0, colours = 0;
    for (size_t px = 0; px < got.hit.size(); ++px) {
      steps += got.steps[px] == scalar.steps[px] && got.crossings[px] == scalar.crossings[px];
      colours += std::abs(got.rgb[3 * px + 1] - scalar.rgb[3 * px + 1]) < 1e-3f;
    }
    EXPECT_GE(steps, got.hit.size() * 99 / 100) << w << "x" << h;
    EXPECT_GE(colours, got.hit.size() * 99 / 100) << w << "x" << h;
  }
}

TEST(Vulkan, AValidationMessageFailsTheCallThatCausedIt) {
  SKIP_WITHOUT_VULKAN();
  ASSERT_TRUE(vulkan().validation());
  // A shader that reads binding 7, which the backend's pipeline layout does not have: the
  // validation layer says so when the pipeline is made.
  const std::string source = R"glsl(#version 450
layout(local_size_x = 1) in;
layout(std430, binding = 7) buffer Missing { float values[]; };
void main() { values[0] = 1.0; }
)glsl";
  const size_t before = vulkan::validation_messages().size();
  try {
    vulkan().compile(source);
    FAIL() << "the validation layer's message was not reported";
  } catch (const kernel::ShaderError& e) {
    FAIL() << "glslang rejected the shader: " << e.what();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("validation layer"), std::string::npos) << e.what();
  }
  EXPECT_GT(vulkan::validation_messages().size(), before);
}

TEST(Vulkan, AWholeLifeUnderValidationIsSilent) {
  const size_t before = vulkan::validation_messages().size();
  {
    BackendOptions options;
    options.validation = true;
    const VulkanBackend backend(options);
    if (const Availability a = backend.availability(); !a.available)
      GTEST_SKIP() << "the vulkan backend is unavailable here: " << a.reason;
    const Scene& scene = test::gallery_scene("l_shape");
    backend.render(scene, scene.camera, 40, 90, {}, {});
    backend.trace(scene, test::generic_rays(scene).front(), {}, 10);
  }  // the device and instance are destroyed here: leaks would be reported now
  const std::vector<std::string> messages = vulkan::validation_messages();
  for (size_t k = before; k < messages.size(); ++k) ADD_FAILURE() << messages[k];
}

TEST(VulkanCli, WithoutADriverTheBackendIsUnavailableAndSaysWhy) {
  // The loader reads its drivers from VK_ICD_FILENAMES when set: here, none.
  const std::vector<std::string> no_driver = {"env", "VK_ICD_FILENAMES=/nonexistent/icd.json",
                                              "VK_DRIVER_FILES=/nonexistent/icd.json",
                                              FLATMARCH_BINARY};
  const auto with = [&](std::vector<std::string> args) {
    std::vector<std::string> argv = no_driver;
    argv.insert(argv.end(), args.begin(), args.end());
    return test::run_process(argv);
  };
  const auto listed = with({"backends", "--json"});
  ASSERT_EQ(listed.exit_code, 0) << listed.err;
  bool found = false;
  for (const auto& b : nlohmann::json::parse(listed.out))
    if (b["name"] == "vulkan") {
      found = true;
      EXPECT_FALSE(b["available"].get<bool>());
      EXPECT_NE(b["reason"].get<std::string>().find("no driver"), std::string::npos) << b;
      EXPECT_TRUE(b["devices"].empty());
    }
  EXPECT_TRUE(found);
  const auto rendered = with({"render", scene_path("torus"), "--backend", "vulkan", "--size", "8x8",
                              "-o", test::make_temp_dir() + "/t.png"});
  EXPECT_EQ(rendered.exit_code, 3) << rendered.err;
  EXPECT_NE(rendered.err.find("backend vulkan is unavailable here"), std::string::npos)
      << rendered.err;
  const auto scalar = with({"render", scene_path("torus"), "--backend", "scalar", "--size", "8x8",
                            "-o", test::make_temp_dir() + "/t.png"});
  EXPECT_EQ(scalar.exit_code, 0) << scalar.err;
}

TEST(VulkanCli, DevicePicksByIndexOrNameAndAnUnknownOneExits3) {
  SKIP_WITHOUT_VULKAN();
  const auto listed = test::run_flatmarch({"backends", "--json"});
  ASSERT_EQ(listed.exit_code, 0) << listed.err;
  std::string name;
  for (const auto& b : nlohmann::json::parse(listed.out))
    if (b["name"] == "vulkan") {
      ASSERT_FALSE(b["devices"].empty());
      name = b["devices"][0]["name"].get<std::string>();
    }
  ASSERT_FALSE(name.empty());
  const std::string dir = test::make_temp_dir();
  for (const std::string& device : {std::string("0"), name.substr(0, 4)}) {
    const auto r = test::run_flatmarch({"render", scene_path("l_shape"), "--backend", "vulkan",
                                        "--device", device, "--method", "analytic", "--size",
                                        "64x36", "-o", dir + "/l.png"});
    EXPECT_EQ(r.exit_code, 0) << device << ": " << r.err;
  }
  EXPECT_TRUE(std::filesystem::exists(dir + "/l.exr"));
  const auto r = test::run_flatmarch({"render", scene_path("l_shape"), "--backend", "vulkan",
                                      "--device", "no such device", "-o", dir + "/x.png"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("no Vulkan device matches --device \"no such device\""), std::string::npos)
      << r.err;
}

TEST(VulkanCli, ShaderPrintsTheComputeShaderAndCompileReportsErrorsWithExit2) {
  SKIP_WITHOUT_VULKAN();
  const std::string scene = scene_path("torus");
  const auto printed = test::run_flatmarch({"shader", scene, "--backend", "vulkan"});
  ASSERT_EQ(printed.exit_code, 0) << printed.err;
  EXPECT_EQ(printed.out.rfind("#version 450", 0), 0u);
  EXPECT_NE(printed.out.find("layout(push_constant) uniform Constants"), std::string::npos);
  const auto compiled = test::run_flatmarch({"shader", scene, "--backend", "vulkan", "--compile"});
  EXPECT_EQ(compiled.exit_code, 0) << compiled.err;
  EXPECT_NE(compiled.err.find("compiles"), std::string::npos);

  const std::string file = test::make_temp_dir() + "/broken.comp";
  std::string broken = printed.out;
  broken.replace(broken.find("vec3 color = shade(r);"), 22, "vec3 color = shade(r, r);");
  std::ofstream(file) << broken;
  const auto failed =
      test::run_flatmarch({"shader", scene, "--backend", "vulkan", "--compile", "--file", file});
  EXPECT_EQ(failed.exit_code, 2);
  EXPECT_NE(failed.err.find("error: " + file), std::string::npos) << failed.err;
  EXPECT_NE(failed.err.find("vec3 color = shade(r, r);"), std::string::npos) << failed.err;
}

}  // namespace
}  // namespace flatmarch
