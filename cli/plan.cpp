#include <cstdio>
#include <fstream>

#include "backends/oracle/oracle.hpp"
#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "plan/floor_plan.hpp"
#include "scene/load.hpp"

namespace flatmarch::cli {

void add_plan(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "plan",
      "Draw the floor plan as SVG: the polygons as the scene lays them out, glued edges in "
      "matching\n"
      "colours with arrows showing how they match, mirrors and walls, cone points with their "
      "angles,\n"
      "objects, the camera, and with --from/--dir the path of a light ray traced by the oracle.");
  struct Options {
    std::string scene, out, from, dir;
    int polygon = 0;
    int max_events = 200;
    double width = 800.0;
    bool quiet = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("SCENE", o->scene, kSceneArgumentHelp)->required();
  cmd->add_option("-o,--output", o->out, "Output SVG")->required();
  auto* from = cmd->add_option("--from", o->from,
                               "Start of a light ray X,Y,Z in the coordinates of --polygon");
  auto* dir = cmd->add_option("--dir", o->dir, "Direction of the light ray DX,DY,DZ");
  from->needs(dir);
  dir->needs(from);
  cmd->add_option("--polygon", o->polygon, "Polygon of --from")->capture_default_str();
  cmd->add_option("--max-events", o->max_events, "Pieces of the ray's path to draw at most")
      ->capture_default_str();
  cmd->add_option("--width", o->width, "Width of the picture in pixels")->capture_default_str();
  cmd->add_flag("-q,--quiet", o->quiet, "No summary on stderr");
  cmd->callback([o] {
    if (o->max_events < 1 || o->max_events > 100000)
      throw UsageError("--max-events: must lie in [1, 100000]");
    if (!(o->width >= 100.0 && o->width <= 20000.0))
      throw UsageError("--width: must lie in [100, 20000]");
    const Scene scene = load_named_scene(o->scene);
    PlanOptions options;
    options.width = o->width;
    options.max_events = o->max_events;
    if (!o->from.empty()) {
      const Ray ray{o->polygon, parse_vec3("--from", o->from), parse_vec3("--dir", o->dir)};
      if (auto problem = ray_problem(scene, ray))
        throw UsageError("--from/--dir/--polygon: " + *problem);
      options.ray = ray;
    }
    const std::string svg = floor_plan_svg(scene, options);
    std::ofstream out(o->out, std::ios::binary);
    out << svg;
    if (!out.flush()) throw UsageError("--output: cannot write " + o->out);
    if (!o->quiet)
      std::fprintf(stderr, "wrote %s (floor plan of %s%s)\n", o->out.c_str(), scene.name.c_str(),
                   options.ray ? ", with a ray" : "");
  });
}

}  // namespace flatmarch::cli
