#include <iostream>

#include "cli/commands.hpp"
#include "scene/inspect.hpp"
#include "scene/load.hpp"

namespace flatmarch::cli {

void add_inspect(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "inspect",
      "Validate a scene and print its derived structure as JSON: polygons, edges, gluings with\n"
      "their type, vertex classes with cone angles, Euler characteristic, orientability, genus.");
  auto file = std::make_shared<std::string>();
  auto compact = std::make_shared<bool>(false);
  cmd->add_option("SCENE", *file, kSceneArgumentHelp)->required();
  cmd->add_flag("--compact", *compact, "One line of JSON instead of indented");
  cmd->callback([file, compact] {
    const Scene scene = load_named_scene(*file);
    std::cout << inspect(scene).dump(*compact ? -1 : 2) << "\n";
  });
}

}  // namespace flatmarch::cli
