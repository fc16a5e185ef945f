#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "backends/backend.hpp"
#include "backends/simd/simd.hpp"
#include "backends/vulkan/vulkan.hpp"
#include "cli/commands.hpp"

namespace flatmarch::cli {

void add_backends(CLI::App& app) {
  auto* cmd = app.add_subcommand("backends",
                                 "List the backends, whether each is available here, and why not.");
  auto json = std::make_shared<bool>(false);
  cmd->add_flag("--json", *json, "Print JSON instead of a table");
  cmd->callback([json] {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& b : backends()) {
      const Availability a = b->availability();
      nlohmann::json methods = nlohmann::json::array();
      for (Method m : b->methods()) methods.push_back(to_string(m));
      list.push_back({{"name", b->name()},
                      {"available", a.available},
                      {"reason", a.reason},
                      {"methods", methods},
                      {"description", b->description()}});
      if (b->name() == "simd") list.back()["isas"] = simd::isa_names(true);
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
    std::string isas;
    for (const std::string& name : simd::isa_names(true)) isas += (isas.empty() ? "" : ", ") + name;
    std::printf("\nsimd instruction sets this CPU runs (--isa), best first: %s\n", isas.c_str());
    for (const auto& b : list) {
      if (!b.contains("devices")) continue;
      if (b["devices"].empty()) {
        std::printf("\nvulkan devices (--device): none\n");
        continue;
      }
      std::printf("\nvulkan devices (--device), * the default:\n");
      for (const auto& d : b["devices"])
        std::printf(
            "  %s %d  %s  (%s, Vulkan %s%s)%s\n", d["default"].get<bool>() ? "*" : " ",
            d["index"].get<int>(), d["name"].get<std::string>().c_str(),
            d["type"].get<std::string>().c_str(), d["api"].get<std::string>().c_str(),
            d["driver"].get<std::string>().empty()
                ? ""
                : (", " + d["driver"].get<std::string>()).c_str(),
            d["usable"].get<bool>() ? "" : "  not usable: no Vulkan 1.1 or no compute queue");
    }
  });
}

}  // namespace flatmarch::cli
