// The Vulkan backend's entry in the registry: its options, its devices as the fingerprint and
// `flatmarch backends` give them, and the compute shader `flatmarch shader` prints and compiles.
#include <glslang/build_info.h>

#include <nlohmann/json.hpp>

#include "backends/vulkan/vulkan.hpp"
#include "kernels/compile.hpp"
#include "kernels/scene_shader.hpp"

namespace flatmarch {

BackendEntry vulkan_backend_entry() {
  return {
      .name = VulkanBackend::kName,
      .make = [](const BackendOptions& o) { return std::make_unique<VulkanBackend>(o); },
      .options = {{"--device", &BackendOptions::device,
                   "likewise "
                   "(default: a discrete, integrated or virtual GPU, else lavapipe)"},
                  {"--vk-staging", &BackendOptions::vk_staging,
                   "read frames back through a staging buffer, as on a discrete GPU, even where "
                   "the device's memory is host-visible"},
                  {"--kernel-shape", &BackendOptions::kernel_shape, "likewise"}},
      .cost = {.frame_seconds = 0.02, .startup_seconds = 0.08},
      .fingerprint =
          [](nlohmann::json& fp) {
            const VulkanBackend vulkan;
            if (const std::optional<DeviceInfo> d = vulkan.device()) {
              const vulkan::Device listed =
                  vulkan.devices().at(static_cast<size_t>(vulkan.device_index()));
              fp["vulkan"] = {{"device", d->name},
                              {"type", d->type},
                              {"api", listed.api},
                              {"driver", d->driver},
                              {"software", d->software}};
            } else {
              fp["vulkan"] = {{"unavailable", vulkan.availability().reason}};
            }
            fp["libraries"]["glslang"] = std::to_string(GLSLANG_VERSION_MAJOR) + "." +
                                         std::to_string(GLSLANG_VERSION_MINOR) + "." +
                                         std::to_string(GLSLANG_VERSION_PATCH);
          },
      .fingerprint_rows =
          [](const nlohmann::json& fp) {
            const nlohmann::json vk = fp.value("vulkan", nlohmann::json::object());
            const auto field = [&](const char* key) {
              return vk.contains(key) ? vk[key].get<std::string>() : std::string("None");
            };
            const std::string text =
                vk.contains("device")
                    ? vk["device"].get<std::string>() + " (" + field("type") + ", Vulkan " +
                          field("api") + ", driver " + field("driver") +
                          (vk.value("software", false) ? ", software: a rasteriser on the CPU"
                                                       : "") +
                          ")"
                    : "unavailable: " + vk.value("unavailable", "?");
            return std::vector<std::pair<std::string, std::string>>{{"Vulkan", text}};
          },
      .describe_machine =
          [](const nlohmann::json& fp) {
            const nlohmann::json vk = fp.value("vulkan", nlohmann::json::object());
            if (!vk.contains("device")) return std::string();
            return "Vulkan: " + vk["device"].get<std::string>() +
                   (vk.value("software", false) ? " (software)" : "");
          },
      .list =
          [](const Backend& b, nlohmann::json& listing) {
            const auto& vulkan = dynamic_cast<const VulkanBackend&>(b);
            nlohmann::json devices = nlohmann::json::array();
            for (const vulkan::Device& d : vulkan.devices())
              devices.push_back({{"index", d.index},
                                 {"name", d.name},
                                 {"type", d.type},
                                 {"api", d.api},
                                 {"driver", d.driver},
                                 {"usable", d.usable},
                                 {"default", d.index == vulkan.device_index()}});
            listing["devices"] = devices;
          },
      .list_text =
          [](const nlohmann::json& listing) {
            const nlohmann::json& devices = listing.at("devices");
            if (devices.empty()) return std::string("vulkan devices (--device): none\n");
            std::string text = "vulkan devices (--device), * the default:\n";
            for (const auto& d : devices) {
              const std::string driver = d["driver"].get<std::string>();
              text +=
                  std::string("  ") + (d["default"].get<bool>() ? "*" : " ") + " " +
                  std::to_string(d["index"].get<int>()) + "  " + d["name"].get<std::string>() +
                  "  (" + d["type"].get<std::string>() + ", Vulkan " + d["api"].get<std::string>() +
                  (driver.empty() ? "" : ", " + driver) + ")" +
                  (d["usable"].get<bool>() ? ""
                                           : "  not usable: no Vulkan 1.1 or no compute queue") +
                  "\n";
            }
            return text;
          },
      .shader =
          [](const Scene& scene, const MarchParams& params, const ShaderRequest& r) {
            const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
            return kernel::scene_compute_shader(
                tables, {.trace = r.trace, .shape = r.shape, .readback = kernel::Readback::all},
                kernel::ComputeApi::vulkan);
          },
      .compile_shader =
          [](const Backend& b, const std::string& source, const ShaderRequest&) {
            const auto& vulkan = dynamic_cast<const VulkanBackend&>(b);
            vulkan.compile(source);
            return vulkan.description();
          }};
}

}  // namespace flatmarch
