#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "backends/backend.hpp"
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
                      {"cpu", registry[k].cpu_rank > 0},
                      {"reference_for", registry[k].reference_for}});
      if (const auto device = b->device())
        list.back()["device"] = {{"name", device->name},         {"type", device->type},
                                 {"api", device->api},           {"driver", device->driver},
                                 {"platform", device->platform}, {"software", device->software}};
      // What the backend itself lists: its devices, its instruction sets.
      if (registry[k].list) registry[k].list(*b, list.back());
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
    for (size_t k = 0; k < list.size(); ++k)
      if (registry[k].list_text) std::printf("\n%s", registry[k].list_text(list[k]).c_str());
  });
}

}  // namespace flatmarch::cli
