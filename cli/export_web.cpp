// `flatmarch export-web`: each scene as a self-contained web page that marches it with WebGL2
// (web/page.hpp), and an index page for several.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "plan/floor_plan.hpp"
#include "scene/load.hpp"
#include "web/page.hpp"

namespace flatmarch::cli {

namespace fs = std::filesystem;

namespace {

// The page's floor-plan inset: the plan `flatmarch plan` draws, 320 pixels wide.
web::FloorPlan floor_plan(const Scene& scene) {
  PlanOptions options;
  options.width = 320.0;
  const PlanLayout layout(scene, options.width);
  const Vec2 origin = layout.to_pixels(Vec2(0.0));
  return {.svg = floor_plan_svg(scene, options),
          .width = layout.width(),
          .height = layout.height(),
          .title_height = PlanLayout::kTitleHeight,
          .origin_x = origin.x,
          .origin_y = origin.y,
          .scale = layout.to_pixels(1.0)};
}

void write_file(const fs::path& file, const std::string& text) {
  std::error_code error;
  fs::create_directories(file.parent_path(), error);
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw UsageError("-o: cannot write " + file.string());
}

std::string kilobytes(size_t bytes) {
  char s[32];
  std::snprintf(s, sizeof s, "%.0f KB", static_cast<double>(bytes) / 1024.0);
  return s;
}

}  // namespace

void add_export_web(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "export-web",
      "Write each scene as a self-contained web page that marches it in the browser with WebGL2:\n"
      "the kernel's shader (kernels/march.glsl) in GLSL ES 3.00, specialised on the scene with "
      "its\n"
      "tables baked in, one per method, the scene's camera and its floor plan. Nothing is fetched\n"
      "when the page opens: it works from a file, offline. Controls, as the viewer's: W/A/S/D\n"
      "walk and E/Q rise and sink (Shift: faster), carried through gluings as in the viewer; a\n"
      "click locks the mouse to look (Esc frees it), or drag, or arrow keys; on a touch screen "
      "one\n"
      "finger drags to look and two drag to move; 1/2/3 sphere/relaxed/analytic; [ ] eps and ; '\n"
      "offset by quarter decades (the shader recompiled); the wheel the field of view; - + the\n"
      "resolution; M the floor-plan inset; P a screenshot; H the help line. The page takes\n"
      "?frame=WxH to draw one frame of that size from the scene's camera (for comparisons with\n"
      "`flatmarch render`; &bench=N times N more and puts the median in the title),\n"
      "?method=NAME, ?keys=K,K,... (key presses first) and ?walk=F,R,U;... (walks, whose end the\n"
      "title then gives). One scene: OUT/index.html; several: OUT/NAME/index.html each and\n"
      "OUT/index.html linking them. The webgl backend runs these pages in headless Chromium.");
  struct Options {
    std::vector<std::string> scenes;
    std::string out, method = "analytic";
    MarchParams params;
    bool quiet = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("SCENE", o->scenes, "Scene files (JSON), or gallery scenes' names")->required();
  cmd->add_option("-o,--output", o->out, "Output folder")->required();
  cmd->add_option("--method", o->method, "The method the page starts with")->capture_default_str();
  add_march_param_options(*cmd, o->params);
  cmd->add_flag("-q,--quiet", o->quiet, "No summary on stderr");
  cmd->callback([o] {
    check_march_params(o->params);
    const std::vector<Method> methods = parse_methods({o->method});
    if (methods.size() != 1 || methods[0] == Method::oracle)
      throw UsageError("--method: one of sphere, relaxed, analytic");
    o->params.method = methods[0];
    std::vector<Scene> scenes;
    for (const std::string& file : o->scenes) {
      scenes.push_back(load_named_scene(file));
      check_reach(scenes.back(), scenes.back().camera, o->params);
    }
    const fs::path out(o->out);
    std::string links;
    for (const Scene& scene : scenes) {
      const fs::path file =
          scenes.size() == 1 ? out / "index.html" : out / scene.name / "index.html";
      const std::string text = web::page(scene, o->params, {.floor_plan = floor_plan(scene)});
      write_file(file, text);
      links += "<li><a href=\"" + xml_escape(scene.name) + "/index.html\">" +
               xml_escape(scene.name) + "</a> " + xml_escape(scene.description) + "</li>\n";
      if (!o->quiet)
        std::fprintf(stderr, "export-web: wrote %s (%s)\n", file.string().c_str(),
                     kilobytes(text.size()).c_str());
    }
    if (scenes.size() > 1) {
      write_file(
          out / "index.html",
          "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>flatmarch "
          "scenes</title></head>\n<body style=\"font-family: sans-serif\"><h1>flatmarch "
          "scenes</h1><p>Each page marches its surface in the browser (WebGL2).</p><ul>\n" +
              links + "</ul></body></html>\n");
      if (!o->quiet)
        std::fprintf(stderr, "export-web: wrote %s\n", (out / "index.html").string().c_str());
    }
  });
}

}  // namespace flatmarch::cli
