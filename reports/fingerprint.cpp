#include "reports/fingerprint.hpp"

#include <sys/utsname.h>

#include <benchmark/benchmark.h>
#include <glslang/build_info.h>
#include <hwy/highway.h>
#include <oneapi/tbb/version.h>

#include <fstream>
#include <glm/detail/setup.hpp>
#include <string>
#include <thread>

#include "backends/opengl/opengl.hpp"
#include "backends/simd/simd.hpp"
#include "backends/vulkan/vulkan.hpp"
#include "output/image_library.hpp"

namespace flatmarch::reports {

namespace {

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0)
      if (const size_t colon = line.find(':'); colon != std::string::npos)
        return line.substr(line.find_first_not_of(" \t", colon + 1));
  return "unknown";
}

// The OpenImageIO the image module loads, or why it cannot.
std::string image_library_version() {
  try {
    return image_library().version();
  } catch (const std::exception& e) {
    return std::string("unavailable: ") + e.what();
  }
}

std::string version(int major, int minor, int patch) {
  return std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(patch);
}

}  // namespace

nlohmann::json hardware_fingerprint() {
  nlohmann::json fp;
  const SimdBackend simd;
  fp["cpu"] = {{"model", cpu_model()},
               {"logical_cores", std::thread::hardware_concurrency()},
               {"isa", simd.availability().available ? simd.isa() : "none"},
               {"simd_lanes", simd.lanes()},
               {"isas", simd::isa_names(true)}};
  // The devices the GPU backends choose by default (a report run with --device says its own in
  // each case).
  const OpenGlBackend opengl;
  if (const std::optional<DeviceInfo> d = opengl.device())
    fp["opengl"] = {
        {"renderer", opengl.renderer()}, {"device", d->name},       {"api", d->api},
        {"driver", d->driver},           {"platform", d->platform}, {"software", d->software}};
  else
    fp["opengl"] = {{"unavailable", opengl.availability().reason}};
  const VulkanBackend vulkan;
  if (const std::optional<DeviceInfo> d = vulkan.device()) {
    const vulkan::Device listed = vulkan.devices().at(static_cast<size_t>(vulkan.device_index()));
    fp["vulkan"] = {{"device", d->name},
                    {"type", d->type},
                    {"api", listed.api},
                    {"driver", d->driver},
                    {"software", d->software}};
  } else {
    fp["vulkan"] = {{"unavailable", vulkan.availability().reason}};
  }
  utsname os{};
  if (uname(&os) == 0) {
    fp["os"] = std::string(os.sysname) + " " + os.release + " " + os.machine;
    fp["host"] = os.nodename;
  }
  fp["libraries"] = {
      {"OpenImageIO", image_library_version()},
      {"oneTBB", version(TBB_VERSION_MAJOR, TBB_VERSION_MINOR, TBB_VERSION_PATCH)},
      {"Highway", version(HWY_MAJOR, HWY_MINOR, HWY_PATCH)},
      {"glslang", version(GLSLANG_VERSION_MAJOR, GLSLANG_VERSION_MINOR, GLSLANG_VERSION_PATCH)},
      {"GLM", version(GLM_VERSION_MAJOR, GLM_VERSION_MINOR, GLM_VERSION_PATCH)},
      {"nlohmann_json", version(NLOHMANN_JSON_VERSION_MAJOR, NLOHMANN_JSON_VERSION_MINOR,
                                NLOHMANN_JSON_VERSION_PATCH)}};
  fp["build"] = {{"flatmarch", FLATMARCH_VERSION},
                 {"compiler", std::string("g++ ") + __VERSION__},
                 {"type", FLATMARCH_BUILD_TYPE}};
  return fp;
}

std::string describe_machine(const nlohmann::json& fp) {
  std::string s = fp["cpu"]["model"].get<std::string>() + ", " +
                  std::to_string(fp["cpu"]["logical_cores"].get<int>()) + " threads, " +
                  fp["cpu"]["isa"].get<std::string>();
  // Results written before devices carried the software flag have none.
  const auto software = [](const nlohmann::json& d) {
    return d.value("software", false) ? " (software)" : "";
  };
  if (fp["vulkan"].contains("device"))
    s += "; Vulkan: " + fp["vulkan"]["device"].get<std::string>() + software(fp["vulkan"]);
  if (fp["opengl"].contains("renderer"))
    s += "; OpenGL: " + fp["opengl"]["renderer"].get<std::string>() + software(fp["opengl"]);
  return s;
}

void add_to_benchmark_context(const nlohmann::json& fingerprint) {
  // Google Benchmark keeps its context for the life of the process and refuses a key twice; a
  // process that runs several reports (a test, shards in turn) adds the machine once.
  static bool added = false;
  if (added) return;
  added = true;
  const nlohmann::json flat = fingerprint.flatten();  // items() refers to it, not a copy
  for (const auto& item : flat.items())
    benchmark::AddCustomContext("fingerprint" + item.key(), item.value().is_string()
                                                                ? item.value().get<std::string>()
                                                                : item.value().dump());
}

}  // namespace flatmarch::reports
