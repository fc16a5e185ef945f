#include "web/page.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "kernels/compile.hpp"
#include "kernels/scene_shader.hpp"
#include "motion/settings.hpp"
#include "motion/walk.hpp"
#include "scene/inspect.hpp"

namespace flatmarch::web {

// web/page.html and web/page.js (page_source.cpp, generated).
extern const char* const kPageHtml;
extern const char* const kPageScript;

namespace {

using nlohmann::json;

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
  return s;
}

json pair(Vec2 v) {
  return {v.x, v.y};
}

// What the page's walk (a port of motion/walk.cpp) needs of the scene: its band, and each
// polygon's edges with their gluings and an outline for the inside test (an unbounded room's cut
// off far beyond where a walk may go, kWalkReach).
json walk_data(const Scene& scene) {
  json polygons = json::array();
  for (const Polygon& polygon : scene.polygons) {
    double reach = motion::kWalkReach * scene.scale;
    for (int i = 0; i < polygon.size(); ++i)
      if (!polygon.is_ideal(i)) reach = std::max(reach, glm::length(polygon.vertex(i)));
    json outline = json::array();
    for (const Vec2 v :
         polygon.infinite() ? polygon.outline(8.0 * (reach + 1.0)) : polygon.vertices)
      outline.push_back(pair(v));
    json edges = json::array();
    for (const Edge& e : polygon.edges) {
      const Mat2& m = e.map.linear;
      edges.push_back(
          {{"kind", to_string(e.kind)},
           {"at_infinity", e.shape == EdgeShape::at_infinity},
           {"start", pair(e.start)},
           {"along", pair(e.along)},
           {"length", std::isfinite(e.length) ? json(e.length) : json(nullptr)},
           {"normal", pair(e.normal)},
           {"to", {e.to.polygon, e.to.edge}},
           {"linear", {m[0].x, m[0].y, m[1].x, m[1].y}},
           {"translation", pair(e.map.translation)},
           {"gluing",
            e.gluing >= 0 ? to_string(scene.gluings[static_cast<size_t>(e.gluing)].type) : ""}});
    }
    polygons.push_back({{"infinite", polygon.infinite()}, {"outline", outline}, {"edges", edges}});
  }
  return {{"margin", motion::kWalkMargin},
          {"max_segments", motion::kMaxSegments},
          {"reach", motion::kWalkReach},
          {"scale", scene.scale},
          {"height", scene.height},
          {"period", scene.period ? json(*scene.period) : json(nullptr)},
          {"floor", scene.floor},
          {"polygons", polygons}};
}

}  // namespace

std::string page(const Scene& scene, const MarchParams& params, const PageOptions& options) {
  if (std::find(options.methods.begin(), options.methods.end(), params.method) ==
      options.methods.end())
    throw std::invalid_argument(std::string("web::page: the page starts with ") +
                                to_string(params.method) + ", which it has no shader for");
  json shaders = json::object();
  for (const Method m : options.methods) {
    MarchParams p = params;
    p.method = m;
    shaders[to_string(m)] = kernel::web_fragment_shader(kernel::compile_scene<float>(scene, p));
  }
  json data = {{"name", scene.name},
               {"description", scene.description},
               {"camera", json(camera_json(scene.camera))},
               {"method", to_string(params.method)},
               {"eps", params.eps},
               {"offset", params.offset},
               {"eps_range", {motion::kMinEps, motion::kMaxEps}},
               {"max_offset", motion::kMaxOffset},
               {"degrees_per_pixel", motion::kDegreesPerPixel},
               {"walk", walk_data(scene)},
               {"vertex_shader", kernel::kWebVertexShader},
               {"shaders", shaders}};
  if (options.floor_plan) {
    const FloorPlan& f = *options.floor_plan;
    data["floor_plan"] = {{"svg", f.svg},
                          {"width", f.width},
                          {"height", f.height},
                          {"title_height", f.title_height},
                          {"origin", {f.origin_x, f.origin_y}},
                          {"scale", f.scale}};
  }
  if (options.readback) {
    const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
    data["readback"] = {
        {"render", kernel::web_fragment_shader(tables, kernel::WebShader::readback)},
        {"trace", kernel::web_fragment_shader(tables, kernel::WebShader::trace)}};
  }
  // In a script element "</" would end it early.
  const std::string text = replace_all(data.dump(), "</", "<\\/");
  return replace_all(replace_all(kPageHtml, "@SCRIPT@", kPageScript), "@DATA@", text);
}

}  // namespace flatmarch::web
