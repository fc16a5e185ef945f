#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "kernels/camera.hpp"
#include "output/image_io.hpp"
#include "plan/floor_plan.hpp"
#include "scene/describe.hpp"
#include "scene/load.hpp"

namespace flatmarch::cli {

namespace fs = std::filesystem;

void add_gallery(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "gallery",
      "Render every scene of a folder with the oracle into OUT: for each scene NAME.png (colour),\n"
      "NAME.exr (AOVs) and NAME.svg (its floor plan with the ray through the middle of the "
      "picture),\n"
      "and an index.html that shows them all with their derived structure.");
  struct Options {
    std::string scenes = data_folder("scenes"), out = "out/gallery", size = "960x540";
    bool quiet = false;
    MarchOptions march;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("SCENES", o->scenes, "Folder of scene files (*.json)")->capture_default_str();
  cmd->add_option("-o,--output", o->out, "Output folder (created)")->capture_default_str();
  cmd->add_option("--size", o->size, "Image size WxH")->capture_default_str();
  cmd->add_flag("-q,--quiet", o->quiet, "Only errors on stderr");
  o->march.add_to(*cmd);
  cmd->callback([o] {
    const auto [w, h] = parse_size("--size", o->size);
    check_frame_memory("--size", w, h, kRenderFrames, "a rendered image");
    const Backend& backend = o->march.resolve();
    std::error_code ec;
    if (!fs::is_directory(o->scenes, ec))
      throw UsageError("SCENES: " + o->scenes + " is not a folder");
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(o->scenes))
      if (entry.path().extension() == ".json") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    if (files.empty()) throw UsageError("SCENES: no *.json scene files in " + o->scenes);
    fs::create_directories(o->out, ec);
    if (ec) throw UsageError("--output: cannot create " + o->out + ": " + ec.message());

    std::string cards;
    int failures = 0;
    for (size_t k = 0; k < files.size(); ++k) {
      const std::string stem = files[k].stem().string();
      const std::string label =
          "[" + std::to_string(k + 1) + "/" + std::to_string(files.size()) + "] " + stem;
      try {
        const Scene scene = load_scene(files[k]);
        const auto start = std::chrono::steady_clock::now();
        ProgressReporter progress(label, o->quiet);
        const Frame frame = backend.render(scene, scene.camera, w, h, o->march.params,
                                           [&](double f) { progress(f); });
        progress.done();
        const fs::path png = fs::path(o->out) / (stem + ".png");
        write_png(frame, png);
        write_aov_exr(frame, aov_path(png));
        // The floor plan, with the ray through the middle of the picture.
        PlanOptions plan;
        const Camera& cam = scene.camera;
        plan.ray = Ray{cam.polygon, cam.position,
                       camera_basis(cam.yaw_deg, cam.pitch_deg, cam.fov_deg, w, h).forward};
        std::ofstream(fs::path(o->out) / (stem + ".svg"), std::ios::binary)
            << floor_plan_svg(scene, plan);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (!o->quiet) std::fprintf(stderr, "%s: %.2f s\n", label.c_str(), seconds);
        cards += "<section><h2>" + xml_escape(scene.name) + "</h2><p>" +
                 xml_escape(scene.description) + "</p><p class=\"derived\">" +
                 xml_escape(surface_summary(scene)) + "</p><img src=\"" + stem + ".png\" alt=\"" +
                 xml_escape(scene.name) + "\"><img class=\"plan\" src=\"" + stem +
                 ".svg\" alt=\"floor plan of " + xml_escape(scene.name) + "\"></section>\n";
      } catch (const SceneError& e) {
        ++failures;
        std::fprintf(stderr, "%s\n", e.what());
      }
    }
    std::ofstream index(fs::path(o->out) / "index.html");
    index << "<!doctype html><html><head><meta charset=\"utf-8\"><title>flatmarch "
             "gallery</title><style>"
             "body{font-family:sans-serif;max-width:1000px;margin:2em auto;color:#222}"
             "img{max-width:100%}.plan{max-width:60%;display:block;margin-top:.5em}.derived{color:#"
             "555;font-size:90%}</style></head><body>"
             "<h1>flatmarch gallery</h1><p>Rendered with the "
          << xml_escape(backend.name()) << " backend at " << w << "x" << h << ".</p>\n"
          << cards << "</body></html>\n";
    if (!index)
      throw std::runtime_error("cannot write " + (fs::path(o->out) / "index.html").string());
    std::fprintf(stderr, "gallery: %zu scenes rendered into %s (open %s/index.html)\n",
                 files.size() - static_cast<size_t>(failures), o->out.c_str(), o->out.c_str());
    if (failures)
      throw UsageError(std::to_string(failures) + " scene(s) failed to load (see above)");
  });
}

}  // namespace flatmarch::cli
