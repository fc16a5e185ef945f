// The SIMD backend's entry in the registry: its options, its instruction sets as the fingerprint
// and `flatmarch backends` give them, and what its timed cases cost.
#include <hwy/highway.h>
#include <oneapi/tbb/version.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "backends/simd/simd.hpp"

namespace flatmarch {

namespace {

std::string joined(const std::vector<std::string>& names, const char* separator) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : separator) + n;
  return s;
}

std::string version(int major, int minor, int patch) {
  return std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(patch);
}

}  // namespace

BackendEntry simd_backend_entry() {
  return {.name = SimdBackend::kName,
          .make = [](const BackendOptions& o) { return std::make_unique<SimdBackend>(o); },
          .variants =
              [] {
                std::vector<std::pair<std::string, BackendOptions>> v;
                for (const std::string& isa : simd::isa_names(false))
                  v.push_back({isa, BackendOptions{.isa = isa}});
                return v;
              },
          .options = {{"--isa", &BackendOptions::isa,
                       "the instruction set, one of those `flatmarch backends` lists (default: the "
                       "best this CPU runs)"},
                      {"--threads", &BackendOptions::threads, "worker threads (0: all cores)"}},
          // A timed case also draws a counted frame, times the peak of a room's step (0.05 s, 0.1 s
          // where min_time is Google Benchmark's: register_frame_benchmark) and four frames on one
          // thread (the median of the last three), each of those on one of this 2-core machine's
          // two threads.
          .cost = {.frame_seconds = 0.01,
                   .extra_timed_seconds =
                       [](double frame_seconds, double min_time) {
                         const double peak_seconds = min_time > 0.0 ? 0.05 : 0.1;
                         return frame_seconds + peak_seconds + 4.0 * 2.0 * frame_seconds;
                       }},
          .cpu_rank = 2,
          .check_options =
              [](const BackendOptions& options) {
                const std::vector<std::string> isas = simd::isa_names(false);
                if (options.isa.empty() ||
                    std::find(isas.begin(), isas.end(), options.isa) != isas.end())
                  return std::string();
                return "--isa: unknown instruction set \"" + options.isa + "\" (" +
                       joined(isas, ", ") + ")";
              },
          .fingerprint =
              [](nlohmann::json& fp) {
                const SimdBackend simd;
                fp["cpu"]["isa"] = simd.availability().available ? simd.isa() : "none";
                fp["cpu"]["simd_lanes"] = simd.lanes();
                fp["cpu"]["isas"] = simd::isa_names(true);
                fp["libraries"]["oneTBB"] =
                    version(TBB_VERSION_MAJOR, TBB_VERSION_MINOR, TBB_VERSION_PATCH);
                fp["libraries"]["Highway"] = version(HWY_MAJOR, HWY_MINOR, HWY_PATCH);
              },
          .fingerprint_rows =
              [](const nlohmann::json& fp) {
                const nlohmann::json cpu = fp.value("cpu", nlohmann::json::object());
                const nlohmann::json lanes = cpu.value("simd_lanes", nlohmann::json("?"));
                return std::vector<std::pair<std::string, std::string>>{
                    {"SIMD", cpu.value("isa", "?") + " (" +
                                 (lanes.is_string() ? lanes.get<std::string>() : lanes.dump()) +
                                 " lanes); compiled in: " +
                                 joined(cpu.value("isas", std::vector<std::string>{}), ", ")}};
              },
          .list = [](const Backend&,
                     nlohmann::json& listing) { listing["isas"] = simd::isa_names(true); },
          .list_text =
              [](const nlohmann::json& listing) {
                return "simd instruction sets this CPU runs (--isa), best first: " +
                       joined(listing.value("isas", std::vector<std::string>{}), ", ") + "\n";
              }};
}

}  // namespace flatmarch
