#include "scene/surfaces.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "scene/load.hpp"

namespace flatmarch {

const std::vector<std::string>& surface_types() {
  static const std::vector<std::string> types = {
      "prism", "cone", "cylinder", "mirror", "dilation", "reflection", "rotation", "translation"};
  return types;
}

std::string surface_type(const Scene& scene) {
  if (scene.period) return "prism";
  const auto any_gluing = [&](std::initializer_list<GluingType> types) {
    return std::any_of(scene.gluings.begin(), scene.gluings.end(), [&](const Gluing& g) {
      return std::find(types.begin(), types.end(), g.type) != types.end();
    });
  };
  if (scene.topology.infinite)
    return any_gluing({GluingType::rotation, GluingType::half_translation}) ? "cone" : "cylinder";
  const auto any_edge = [&](EdgeKind kind) {
    return std::any_of(scene.polygons.begin(), scene.polygons.end(), [&](const Polygon& p) {
      return std::any_of(p.edges.begin(), p.edges.end(),
                         [&](const Edge& e) { return e.kind == kind; });
    });
  };
  if (any_edge(EdgeKind::mirror)) return "mirror";
  if (any_gluing({GluingType::similarity, GluingType::affine})) return "dilation";
  if (any_gluing({GluingType::reflection})) return "reflection";
  if (any_gluing({GluingType::rotation, GluingType::half_translation})) return "rotation";
  return "translation";
}

namespace {

// Nothing escapes a prism of period 2, and with no objects every ray runs to max_distance (or a
// cone point): the work per ray is the path's.
nlohmann::json empty_prism(nlohmann::json polygons, nlohmann::json gluings, Vec2 camera_xy,
                           const std::string& name) {
  return {{"name", name},
          {"polygons", std::move(polygons)},
          {"gluings", std::move(gluings)},
          {"period", 2.0},
          {"camera",
           {{"position", {camera_xy.x, camera_xy.y, 1.0}}, {"yaw_deg", 17.0}, {"pitch_deg", 3.0}}}};
}

}  // namespace

Scene regular_polygon_surface(int n) {
  if (n < 2 || n > 256) throw std::invalid_argument("regular_polygon_surface: n out of [2, 256]");
  const double pi = std::acos(-1.0);
  const double circumradius = 2.0 / std::cos(pi / (2.0 * n));
  nlohmann::json polygon = nlohmann::json::array();
  for (int k = 0; k < 2 * n; ++k) {
    // Edge 0 at the bottom, horizontal.
    const double angle = -pi / 2.0 - pi / (2.0 * n) + k * pi / n;
    polygon.push_back({circumradius * std::cos(angle), circumradius * std::sin(angle)});
  }
  nlohmann::json gluings = nlohmann::json::array();
  for (int k = 0; k < n; ++k) gluings.push_back({{0, k}, {0, k + n}});
  // Off the centre, so that no ray of the middle row runs through a cone point.
  return scene_from_json(empty_prism(nlohmann::json::array({polygon}), gluings, Vec2(0.31, 0.17),
                                     "regular_" + std::to_string(2 * n) + "_gon"),
                         "regular_polygon_surface");
}

Scene staircase_surface(int squares, bool apart) {
  if (squares < 2 || squares > 512 || squares % 2)
    throw std::invalid_argument("staircase_surface: squares must be even, in [2, 512]");
  nlohmann::json polygons = nlohmann::json::array();
  for (int k = 0; k < squares; ++k) {
    const int x = apart ? 2 * k : 0;
    polygons.push_back({{x, 0}, {x + 2, 0}, {x + 2, 2}, {x, 2}});
  }
  nlohmann::json gluings = nlohmann::json::array();
  for (int k = 0; k < squares; ++k) {
    const int right = k % 2 == 0 ? k + 1 : k - 1;  // horizontal pairs
    const int up = k % 2 == 1 ? (k + 1) % squares : (k + squares - 1) % squares;  // vertical
    gluings.push_back({{k, 1}, {right, 3}});  // right edge to the left edge of its neighbour
    gluings.push_back({{k, 2}, {up, 0}});     // top edge to the bottom edge of the one above
  }
  return scene_from_json(
      empty_prism(polygons, gluings, Vec2(0.7, 0.9),
                  (apart ? "staircase_apart_" : "staircase_") + std::to_string(squares)),
      "staircase_surface");
}

Scene empty_torus_prism() {
  return scene_from_json(
      empty_prism({{{0, 0}, {4, 0}, {4, 4}, {0, 4}}}, {{{0, 0}, {0, 2}}, {{0, 1}, {0, 3}}},
                  Vec2(0.6, 0.9), "empty_torus_prism"),
      "empty_torus_prism");
}

}  // namespace flatmarch
