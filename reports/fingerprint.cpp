#include "reports/fingerprint.hpp"

#include <sys/utsname.h>

#include <benchmark/benchmark.h>

#include <fstream>
#include <glm/detail/setup.hpp>
#include <string>
#include <thread>

#include "backends/backend.hpp"
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
  // The CPU's instruction set as the SIMD backend runs it, where the build has one (its entry's
  // fingerprint says).
  fp["cpu"] = {{"model", cpu_model()},
               {"logical_cores", std::thread::hardware_concurrency()},
               {"isa", "none"},
               {"simd_lanes", 0},
               {"isas", nlohmann::json::array()}};
  utsname os{};
  if (uname(&os) == 0) {
    fp["os"] = std::string(os.sysname) + " " + os.release + " " + os.machine;
    fp["host"] = os.nodename;
  }
  fp["libraries"] = {
      {"OpenImageIO", image_library_version()},
      {"GLM", version(GLM_VERSION_MAJOR, GLM_VERSION_MINOR, GLM_VERSION_PATCH)},
      {"nlohmann_json", version(NLOHMANN_JSON_VERSION_MAJOR, NLOHMANN_JSON_VERSION_MINOR,
                                NLOHMANN_JSON_VERSION_PATCH)}};
  fp["build"] = {{"flatmarch", FLATMARCH_VERSION},
                 {"compiler", std::string("g++ ") + __VERSION__},
                 {"type", FLATMARCH_BUILD_TYPE}};
  // What each backend says of the machine: its devices (the GPU backends' default ones; a report
  // run with --device says its own in each case), instruction sets, libraries.
  for (const BackendEntry& e : backend_registry())
    if (e.fingerprint) e.fingerprint(fp);
  return fp;
}

std::vector<std::pair<std::string, std::string>> fingerprint_rows(const nlohmann::json& fp) {
  const nlohmann::json cpu = fp.value("cpu", nlohmann::json::object());
  const auto text = [](const nlohmann::json& v) {
    return v.is_string() ? v.get<std::string>() : v.dump();
  };
  std::vector<std::pair<std::string, std::string>> rows{
      {"CPU", text(cpu.value("model", nlohmann::json("?"))) + ", " +
                  text(cpu.value("logical_cores", nlohmann::json("?"))) + " threads"}};
  for (const BackendEntry& e : backend_registry())
    if (e.fingerprint_rows)
      for (auto& row : e.fingerprint_rows(fp)) rows.push_back(std::move(row));
  rows.emplace_back("OS", fp.value("os", "?") + " on " + fp.value("host", "?"));
  std::string libraries;
  const nlohmann::json listed = fp.value("libraries", nlohmann::json::object());
  for (const auto& [name, v] : listed.items())  // items() refers to it, not a copy
    libraries += (libraries.empty() ? "" : ", ") + name + " " + text(v);
  rows.emplace_back("Libraries", libraries);
  const nlohmann::json b = fp.value("build", nlohmann::json::object());
  rows.emplace_back("Build", "flatmarch " + text(b.value("flatmarch", nlohmann::json("None"))) +
                                 ", " + text(b.value("compiler", nlohmann::json("None"))) + ", " +
                                 text(b.value("type", nlohmann::json("None"))));
  return rows;
}

std::string describe_machine(const nlohmann::json& fp) {
  std::string s = fp["cpu"]["model"].get<std::string>() + ", " +
                  std::to_string(fp["cpu"]["logical_cores"].get<int>()) + " threads, " +
                  fp["cpu"].value("isa", "none");
  for (const BackendEntry& e : backend_registry())
    if (e.describe_machine)
      if (const std::string part = e.describe_machine(fp); !part.empty()) s += "; " + part;
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
