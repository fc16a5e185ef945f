#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "backends/backend.hpp"
#include "backends/opengl/context.hpp"
#include "backends/opengl/opengl.hpp"
#include "backends/simd/simd.hpp"
#include "backends/vulkan/vulkan.hpp"
#include "cli/commands.hpp"
#include "cli/common.hpp"

namespace flatmarch::cli {

void add_backends(CLI::App& app) {
  auto* cmd = app.add_subcommand("backends",
                                 "List the backends, whether each is available here, and why not.");
  auto json = std::make_shared<bool>(false);
  cmd->add_flag("--json", *json, "Print JSON instead of a table");
  cmd->callback([json] {
    nlohmann::json list = nlohmann::json::array();
    const std::vector<BackendEntry>& registry = backend_registry();
    for (size_t k = 0; k < backends().size(); ++k) {
      const auto& b = backends()[k];
      const Availability a = b->availability();
      nlohmann::json methods = nlohmann::json::array();
      for (Method m : b->methods()) methods.push_back(to_string(m));
      list.push_back({{"name", b->name()},
                      {"available", a.available},
                      {"reason", a.reason},
                      {"methods", methods},
                      {"description", b->description()},
                      {"kernel", registry[k].kernel},
                      {"reference_for", registry[k].reference_for}});
      if (b->name() == "simd") list.back()["isas"] = simd::isa_names(true);
      if (const auto device = b->device())
        list.back()["device"] = {{"name", device->name},         {"type", device->type},
                                 {"api", device->api},           {"driver", device->driver},
                                 {"platform", device->platform}, {"software", device->software}};
      if (const auto* opengl = dynamic_cast<const OpenGlBackend*>(b.get())) {
        nlohmann::json devices = nlohmann::json::array();
        for (const gl::Device& d : gl::list_devices())
          devices.push_back({{"index", d.index},
                             {"platform", d.platform},
                             {"node", d.node},
                             {"vendor", d.vendor},
                             {"renderer", d.renderer},
                             {"version", d.version},
                             {"software", d.software},
                             {"usable", d.usable},
                             {"reason", d.reason},
                             {"default", d.index == opengl->device_index()}});
        list.back()["devices"] = devices;
      }
      if (const auto* vulkan = dynamic_cast<const VulkanBackend*>(b.get())) {
        nlohmann::json devices = nlohmann::json::array();
        for (const vulkan::Device& d : vulkan->devices())
          devices.push_back({{"index", d.index},
                             {"name", d.name},
                             {"type", d.type},
                             {"api", d.api},
                             {"driver", d.driver},
                             {"usable", d.usable},
                             {"default", d.index == vulkan->device_index()}});
        list.back()["devices"] = devices;
      }
    }
    if (*json) {
      std::cout << list.dump(2) << "\n";
      return;
    }
    std::printf("%-10s %-11s %-28s %s\n", "backend", "available", "methods", "description");
    for (const auto& b : list) {
      std::string methods;
      for (const auto& m : b["methods"])
        methods += (methods.empty() ? "" : ",") + m.get<std::string>();
      const bool ok = b["available"].get<bool>();
      std::printf("%-10s %-11s %-28s %s\n", b["name"].get<std::string>().c_str(), ok ? "yes" : "NO",
                  methods.c_str(),
                  (ok ? b["description"].get<std::string>()
                      : "unavailable: " + b["reason"].get<std::string>())
                      .c_str());
    }
    std::printf("\n");
    for (const auto& b : list)
      if (const std::string r = b["reference_for"].get<std::string>(); !r.empty())
        std::printf("%s is the reference for %s\n", b["name"].get<std::string>().c_str(),
                    r.c_str());
    std::printf("\nsimd instruction sets this CPU runs (--isa), best first: %s\n",
                joined(simd::isa_names(true)).c_str());
    for (const auto& b : list) {
      if (!b.contains("devices")) continue;
      const std::string name = b["name"].get<std::string>();
      if (b["devices"].empty()) {
        std::printf("\n%s devices (--device): none\n", name.c_str());
        continue;
      }
      std::printf("\n%s devices (--device), * the default:\n", name.c_str());
      for (const auto& d : b["devices"]) {
        const bool is_default = d["default"].get<bool>();
        const int index = d["index"].get<int>();
        if (name == "opengl") {
          const std::string node = d["node"].get<std::string>();
          const std::string where =
              d["platform"].get<std::string>() + (node.empty() ? "" : " " + node);
          if (!d["usable"].get<bool>()) {
            std::printf("  %s %d  %s  not usable: %s\n", is_default ? "*" : " ", index,
                        where.c_str(), d["reason"].get<std::string>().c_str());
            continue;
          }
          std::printf("  %s %d  %s  (%s, %s, OpenGL %s%s)\n", is_default ? "*" : " ", index,
                      d["renderer"].get<std::string>().c_str(), where.c_str(),
                      d["vendor"].get<std::string>().c_str(),
                      d["version"].get<std::string>().c_str(),
                      d["software"].get<bool>() ? ", software" : "");
          continue;
        }
        const std::string driver = d["driver"].get<std::string>();
        std::printf(
            "  %s %d  %s  (%s, Vulkan %s%s)%s\n", is_default ? "*" : " ", index,
            d["name"].get<std::string>().c_str(), d["type"].get<std::string>().c_str(),
            d["api"].get<std::string>().c_str(), driver.empty() ? "" : (", " + driver).c_str(),
            d["usable"].get<bool>() ? "" : "  not usable: no Vulkan 1.1 or no compute queue");
      }
    }
  });
}

}  // namespace flatmarch::cli
