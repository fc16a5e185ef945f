// A command loads only the libraries it uses: the flatmarch program links no GPU, windowing or
// image library, and commands that draw or write nothing do not open one at run time either
// (bench/startup_bench times what that saves).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "backends/backend.hpp"
#include "tests/process.hpp"

namespace flatmarch {
namespace {

// Libraries only some commands need, as the dynamic loader names their files.
const std::vector<std::string> kHeavy = {"libOpenImageIO", "libOSMesa", "libEGL",
                                         "libGL.",         "libGLX",    "libvulkan",
                                         "libglfw",        "libX11",    "libLLVM"};

std::string scene(const std::string& name) {
  return std::string(FLATMARCH_SOURCE_DIR) + "/scenes/" + name + ".json";
}

// The files the dynamic loader opened while running `flatmarch ARGS` (LD_DEBUG=files); the
// command is expected to exit with `exit_code`.
std::string loaded_by(const std::vector<std::string>& args, int exit_code = 0) {
  std::vector<std::string> argv = {"env", "LD_DEBUG=files", FLATMARCH_BINARY};
  argv.insert(argv.end(), args.begin(), args.end());
  const test::ProcessResult r = test::run_process(argv);
  EXPECT_EQ(r.exit_code, exit_code) << r.err.substr(r.err.size() > 2000 ? r.err.size() - 2000 : 0);
  std::string files;
  for (size_t at = r.err.find("file="); at != std::string::npos; at = r.err.find("file=", at + 1))
    files += r.err.substr(at, r.err.find_first_of(" \n", at) - at) + "\n";
  return files;
}

// Sanitizer builds link OpenImageIO (output/CMakeLists.txt says why).
#ifdef FLATMARCH_SANITIZE_BUILD
#define SKIP_IN_SANITIZER_BUILDS() \
  GTEST_SKIP() << "sanitizer builds load OpenImageIO with the program (output/CMakeLists.txt)"
#else
#define SKIP_IN_SANITIZER_BUILDS()
#endif

TEST(Startup, TheProgramLinksNoGpuWindowOrImageLibrary) {
  SKIP_IN_SANITIZER_BUILDS();
  const test::ProcessResult r = test::run_process({"ldd", FLATMARCH_BINARY});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const std::string& name : kHeavy)
    EXPECT_EQ(r.out.find(name), std::string::npos) << name << " is linked:\n" << r.out;
}

TEST(Startup, CommandsThatDrawAndWriteNothingOpenNoneOfThem) {
  SKIP_IN_SANITIZER_BUILDS();
  const std::string dir = test::make_temp_dir();
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--help"},
        {"inspect", scene("torus")},
        {"trace", scene("torus"), "--from", "1,1,1", "--dir", "3,1,0"},
        {"plan", scene("l_shape"), "-o", dir + "/l.svg"}}) {
    const std::string files = loaded_by(args);
    ASSERT_FALSE(files.empty()) << "LD_DEBUG=files printed nothing for " << args[0];
    for (const std::string& name : kHeavy)
      EXPECT_EQ(files.find(name), std::string::npos) << args[0] << " opens " << name;
  }
}

TEST(Startup, AnImageWrittenLoadsOpenImageIoAndADrawingLoadsItsDriver) {
  const std::string dir = test::make_temp_dir();
  // render's default backend: the fastest CPU backend this build has.
  const std::string cpu =
      loaded_by({"render", scene("torus"), "--size", "16x9", "-o", dir + "/t.png"});
  EXPECT_NE(cpu.find("libOpenImageIO"), std::string::npos) << cpu;
  for (const char* name : {"libEGL", "libOSMesa", "libvulkan", "libglfw"})
    EXPECT_EQ(cpu.find(name), std::string::npos) << "a CPU render opens " << name;
  // A drawing opens the libraries of its device's API, and none of another API's. The backends
  // with a device reached here, as `flatmarch backends` lists them; an API not listed here (a
  // browser's) opens none of them in this process.
  const std::vector<std::pair<std::string, std::vector<std::string>>> kApiLibraries = {
      {"OpenGL", {"libEGL", "libOSMesa"}}, {"Vulkan", {"libvulkan"}}};
  for (const auto& b : nlohmann::json::parse(test::run_flatmarch({"backends", "--json"}).out)) {
    if (!b["available"].get<bool>() || !b.contains("device")) continue;
    const std::string name = b["name"], api = b["device"]["api"];
    const std::string files = loaded_by(
        {"render", scene("torus"), "--backend", name, "--size", "16x9", "-o", dir + "/g.png"});
    for (const auto& [prefix, libraries] : kApiLibraries) {
      const bool own = api.rfind(prefix, 0) == 0;
      bool opened = false;
      for (const std::string& library : libraries)
        opened = opened || files.find(library) != std::string::npos;
      EXPECT_EQ(opened, own) << name << " (" << api << ") " << (own ? "does not open" : "opens")
                             << " the " << prefix << " libraries";
    }
  }
}

}  // namespace
}  // namespace flatmarch
