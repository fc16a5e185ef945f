#include <iostream>

#include "backends/oracle/oracle.hpp"
#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "output/trace_json.hpp"
#include "scene/load.hpp"

namespace flatmarch::cli {

void add_trace(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "trace",
      "Follow one ray and print its transport trace as JSON: every gluing crossed, mirror bounce\n"
      "and the final event, each with its path length t and point (DESIGN.md section 4).");
  struct Options {
    std::string scene, from, dir;
    int polygon = 0;
    int max_events = 1000;
    MarchOptions march;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("SCENE", o->scene, kSceneArgumentHelp)->required();
  cmd->add_option("--from", o->from, "Ray origin X,Y,Z in the coordinates of --polygon")
      ->required();
  cmd->add_option("--dir", o->dir, "Ray direction DX,DY,DZ (normalised)")->required();
  cmd->add_option("--polygon", o->polygon, "Polygon of the origin")->capture_default_str();
  cmd->add_option("--max-events", o->max_events, "Events to print at most")->capture_default_str();
  o->march.add_to(*cmd);
  cmd->callback([o] {
    if (o->max_events < 1 || o->max_events > 10'000'000)
      throw UsageError("--max-events: must lie in [1, 1e7]");
    const Backend& backend = o->march.resolve();
    const Scene scene = load_named_scene(o->scene);
    Ray ray{o->polygon, parse_vec3("--from", o->from), parse_vec3("--dir", o->dir)};
    if (auto problem = ray_problem(scene, ray))
      throw UsageError("--from/--dir/--polygon: " + *problem);
    ray.dir = glm::normalize(ray.dir);
    Camera from;
    from.position = ray.from;
    check_reach(scene, from, o->march.params);
    const Trace trace = backend.trace(scene, ray, o->march.params, o->max_events);
    std::cout
        << trace_to_json(scene.name, backend.name(), o->march.params.method, ray, trace).dump(2)
        << "\n";
  });
}

}  // namespace flatmarch::cli
