#include "interop/peer_import.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <optional>
#include <set>
#include <sstream>

#include "scene/derive.hpp"
#include "scene/json_reader.hpp"
#include "scene/load.hpp"

namespace flatmarch {

namespace {

// The files store 8 decimals: redundant values that agree to this (relative to the scene's
// scale for positions) agree.
constexpr double kPeerTolerance = 1e-6;

// The app's defaults and conventions (src/core/ShaderGenerator.js, public/shader/template.frag,
// src/core/Camera.js of RayMarchingFlatSurfaces).
constexpr double kDefaultWallHeight = 2.0;
constexpr double kDefaultWrapAmount = 4.0;
constexpr double kDefaultFogStrength = 0.01;
constexpr double kDefaultInnerRatio = 0.77;
const Vec3 kDefaultInitialPosition{0.0, 1.0, 0.0};
// The top-level fields the app reads.
constexpr std::array<std::string_view, 13> kPeerKeys{"id",
                                                     "name",
                                                     "description",
                                                     "vertices",
                                                     "gluing",
                                                     "edges",
                                                     "normals",
                                                     "wallHeight",
                                                     "vertical_component",
                                                     "vertical_wrap_amount",
                                                     "fog_effect_strength",
                                                     "initialPosition",
                                                     "decorations"};
// three.js cameras look along -z, which is -y here.
constexpr double kAppYawDeg = -90.0;

// The app spreads its 75 degree field of view over half the shorter image side
// (uv = (pixel - size / 2) / min(width, height)), so for landscape images its vertical field of
// view is 2 atan(tan(37.5 degrees) / 2).
double app_vertical_fov_deg() {
  return 2.0 * std::atan(0.5 * std::tan(0.5 * 75.0 * kPi / 180.0)) * 180.0 / kPi;
}

std::string format_number(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v + 0.0;  // no "-0"
  return s.str();
}

std::string format_vec(Vec2 v) {
  return "(" + format_number(v.x) + ", " + format_number(v.y) + ")";
}

// Rows, as the files write matrices.
std::string format_matrix(const Mat2& m) {
  return "[[" + format_number(m[0][0]) + ", " + format_number(m[1][0]) + "], [" +
         format_number(m[0][1]) + ", " + format_number(m[1][1]) + "]]";
}

// A computed value rounded to 12 significant digits, so that the scene file reads 0.1001, not
// 0.10010000000000001.
double tidy(double v) {
  std::ostringstream s;
  s.precision(12);
  s << v + 0.0;
  return std::stod(s.str());
}

double max_difference(const Mat2& m, const Mat2& n) {
  double d = 0.0;
  for (int c = 0; c < 2; ++c)
    for (int r = 0; r < 2; ++r) d = std::max(d, std::abs(m[c][r] - n[c][r]));
  return d;
}

bool is_orthogonal(const Mat2& m) {
  return max_difference(glm::transpose(m) * m, Mat2(1.0)) <= kPeerTolerance;
}

// "DoublePentagon_mirror" -> "double_pentagon_mirror", "torus3D" -> "torus3d".
std::string snake_case(const std::string& s) {
  const auto at = [&](size_t i) { return static_cast<unsigned char>(s[i]); };
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    const unsigned char c = at(i);
    if (std::isupper(c)) {
      const bool word_start =
          i > 0 && (std::islower(at(i - 1)) ||
                    (std::isupper(at(i - 1)) && i + 1 < s.size() && std::islower(at(i + 1))));
      if (word_start && !out.empty() && out.back() != '_') out += '_';
      out += static_cast<char>(std::tolower(c));
    } else if (std::isalnum(c)) {
      out += static_cast<char>(c);
    } else if (!out.empty() && out.back() != '_') {
      out += '_';
    }
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  return out.empty() ? "peer_scene" : out;
}

nlohmann::ordered_json json_vec(Vec2 v) {
  return {v.x, v.y};
}
nlohmann::ordered_json json_vec(Vec3 v) {
  return {v.x, v.y, v.z};
}

// A point clearly inside a simple polygon: the centroid or the centroid of a convex corner's
// triangle, whichever lies inside and farthest from the boundary. Some convex corner is an ear,
// whose triangle lies inside, so a point is always found.
Vec2 interior_point(const Polygon& polygon) {
  std::vector<Vec2> candidates{polygon.centroid()};
  for (int v = 0; v < polygon.size(); ++v)
    if (polygon.corner_angle(v) < kPi)
      candidates.push_back((polygon.vertex(v - 1) + polygon.vertex(v) + polygon.vertex(v + 1)) /
                           3.0);
  Vec2 best = candidates.front();
  double best_distance = -1.0;
  for (Vec2 c : candidates) {
    if (!polygon.contains(c)) continue;
    const double d = polygon.distance_to_boundary(c);
    if (d > best_distance) best = c, best_distance = d;
  }
  return best;
}

// A clockwise polygon is reversed keeping vertex 0 first: our vertex j is the file's vertex
// -j (mod n), and our edge j is the file's edge n-1-j run backwards. Both maps are involutions,
// so they also take our indices to the file's.
struct Numbering {
  int n = 0;
  bool reversed = false;
  int vertex(int k) const { return reversed ? (n - k) % n : k; }
  int edge(int k) const { return reversed ? n - 1 - k : k; }
};

struct PeerEdge {
  enum class Type { translation, mirror, affine };
  Type type = Type::mirror;
  std::string type_name;
  Vec2 vector{0.0};  // translation: the displacement of a point leaving through the edge
  Mat2 matrix{1.0};  // affine, meant as x' = matrix x + translation
  Vec2 translation{0.0};
};

// A decoration that stands at a polygon vertex ("Pillars" files): our markers draw it.
struct Pillar {
  int vertex = 0;  // the file's index
  size_t decoration = 0;
  double radius = 0.0;
  double z0 = 0.0, z1 = 0.0;
};

std::string decoration_pointer(size_t d) {
  return "/decorations/" + std::to_string(d);
}

class Importer {
 public:
  Importer(const nlohmann::json& peer, const std::string& file)
      : file_(file), root_(peer, "", file_) {}

  PeerImport run() {
    root_.object();
    read_polygon();
    read_gluing();
    read_edges();
    read_normals();
    read_names();
    convert_vertical();
    convert_gluings();
    convert_decorations();
    convert_camera();
    convert_look();
    report_unknown_keys();
    Scene scene = load();
    if (!pillars_.empty()) scene = add_markers(std::move(scene));
    check_edges(scene);
    return {document(), std::move(findings_)};
  }

 private:
  void add(std::string pointer, Severity severity, std::string message) {
    findings_.push_back({pointer.empty() ? "/" : std::move(pointer), severity, std::move(message)});
  }

  // A numeric field the app writes with toFixed(1) into its shader, so it uses the rounded value.
  void check_one_decimal(const char* key, double value) {
    const double rounded = std::round(value * 10.0) / 10.0;
    if (std::abs(rounded - value) > 1e-12)
      add(std::string("/") + key, Severity::converted,
          "the app rounds this to one decimal and uses " + format_number(rounded) +
              "; the scene keeps " + format_number(value));
  }

  void read_polygon() {
    const JsonNode list = root_["vertices"];
    const size_t count =
        list.array_size(4, static_cast<size_t>(SceneLimits::max_vertices_per_polygon) + 1);
    std::vector<Vec2> vertices;
    for (size_t k = 0; k < count; ++k) vertices.push_back(list[k].vec2());
    for (Vec2 v : vertices) scale_ = std::max({scale_, std::abs(v.x), std::abs(v.y)});
    if (glm::length(vertices.back() - vertices.front()) > kLengthTolerance * scale_)
      list[count - 1].fail(
          "the vertex list is not closed: its last vertex must repeat the first, " +
          format_vec(vertices.front()));
    vertices.pop_back();
    const int n = static_cast<int>(vertices.size());

    Polygon as_listed;
    as_listed.vertices = vertices;
    const bool clockwise = as_listed.area() < 0.0;
    // Mirroring reverses the orientation but keeps the numbering, so problems are named by the
    // file's indices.
    if (clockwise)
      for (Vec2& v : as_listed.vertices) v.x = -v.x;
    if (auto problem = check_polygon(as_listed, scale_)) {
      if (problem->vertex >= 0) list[static_cast<size_t>(problem->vertex)].fail(problem->message);
      list.fail(problem->message);
    }
    numbering_ = {n, clockwise};
    for (int j = 0; j < n; ++j)
      polygon_.vertices.push_back(vertices[static_cast<size_t>(numbering_.vertex(j))]);
    init_edges(polygon_, EdgeKind::mirror);  // for distances to its edges
    if (clockwise)
      add(list.pointer(), Severity::converted,
          "the polygon is listed clockwise; the scene lists it counterclockwise from the same "
          "vertex 0, so the file's vertex k is our vertex -k mod " +
              std::to_string(n) + " and its edge k our edge " + std::to_string(n - 1) +
              "-k run backwards (this report uses the file's indices)");
  }

  int edge_count() const { return numbering_.n; }

  // A per-edge array of the file: one entry for each edge.
  JsonNode per_edge(const char* key) const {
    const JsonNode list = root_[key];
    if (list.array_size() != static_cast<size_t>(edge_count()))
      list.fail("expected one entry per edge (" + std::to_string(edge_count()) + "), found " +
                std::to_string(list.json().size()));
    return list;
  }

  void read_gluing() {
    const JsonNode list = per_edge("gluing");
    for (int i = 0; i < edge_count(); ++i)
      partner_.push_back(list[static_cast<size_t>(i)].index(edge_count(), "edge"));
    for (int i = 0; i < edge_count(); ++i) {
      const int j = partner_[static_cast<size_t>(i)], k = partner_[static_cast<size_t>(j)];
      if (k != i)
        list[static_cast<size_t>(i)].fail(
            "edge " + std::to_string(i) + " is glued to edge " + std::to_string(j) +
            ", but /gluing/" + std::to_string(j) + " glues edge " + std::to_string(j) +
            " to edge " + std::to_string(k) + "; a gluing pairs two edges both ways");
    }
  }

  void read_edges() {
    const JsonNode list = per_edge("edges");
    for (size_t i = 0; i < list.json().size(); ++i) {
      const JsonNode node = list[i].object();
      PeerEdge e;
      e.type_name = node["type"].string();
      if (e.type_name == "translation") {
        e.type = PeerEdge::Type::translation;
        e.vector = node["vector"].vec2();
      } else if (e.type_name == "mirror") {
        e.type = PeerEdge::Type::mirror;
      } else if (e.type_name == "affine") {
        e.type = PeerEdge::Type::affine;
        const JsonNode transform = node["transform"].object();
        const JsonNode m = transform["matrix"];
        m.array_size(4, 4);
        e.matrix = Mat2(Vec2(m[0].number(), m[2].number()), Vec2(m[1].number(), m[3].number()));
        e.translation = transform["translation"].vec2();
        for (const auto& [key, value] : transform.json().items())
          if (key != "matrix" && key != "translation")
            add(transform.pointer() + "/" + key, Severity::ignored,
                "not a field of the app's affine maps");
      } else {
        node["type"].fail("unknown edge type \"" + e.type_name +
                          "\" (expected translation, mirror or affine)");
      }
      for (const auto& [key, value] : node.json().items()) {
        const std::string at = node.pointer() + "/" + key;
        if (key == "ID") {
          if (!(value.is_number() && value.get<double>() == static_cast<double>(i)))
            add(at, Severity::disagrees,
                "ID " + value.dump() + " is not this edge's index " + std::to_string(i));
        } else if (key != "type" && key != "vector" && key != "transform") {
          add(at, Severity::ignored, "not a field of the app's edges");
        }
      }
      edges_.push_back(e);
    }
  }

  void read_normals() {
    const JsonNode list = per_edge("normals");
    for (size_t i = 0; i < list.json().size(); ++i) normals_.push_back(list[i].vec2());
  }

  void read_names() {
    const std::string stem = std::filesystem::path(file_).stem().string();
    name_ = snake_case(stem);
    if (root_.has("id")) {
      const std::string id = root_["id"].string();
      if (snake_case(id) != name_)
        add("/id", Severity::disagrees,
            "id \"" + id + "\" is not the file's name; the app names geometries by file, " +
                "so the scene is named \"" + name_ + "\"");
    }
    std::string text = root_.has("name") ? root_["name"].string() : "";
    if (root_.has("description"))
      text += (text.empty() ? "" : ": ") + root_["description"].string();
    if (!text.empty() && text.back() != '.') text += '.';
    description_ = text + (text.empty() ? "" : " ") + "Imported from " +
                   std::filesystem::path(file_).filename().string() + " of the original web app.";
  }

  void convert_vertical() {
    if (root_.has("wallHeight")) {
      wall_height_ = root_["wallHeight"].positive();
      check_one_decimal("wallHeight", wall_height_);
    }
    std::string mode = "line";
    if (root_.has("vertical_component")) {
      mode = root_["vertical_component"].string();
      std::transform(mode.begin(), mode.end(), mode.begin(),
                     [](unsigned char c) { return std::tolower(c); });
      if (mode != "line" && mode != "circle")
        root_["vertical_component"].fail("unknown vertical_component \"" +
                                         root_["vertical_component"].string() +
                                         "\" (expected line or circle)");
    }
    const double wrap = root_.has("vertical_wrap_amount") ? root_["vertical_wrap_amount"].positive()
                                                          : kDefaultWrapAmount;
    if (mode == "circle") {
      period_ = wrap;
      if (root_.has("vertical_wrap_amount")) check_one_decimal("vertical_wrap_amount", wrap);
      if (wrap > 2.0 * wall_height_ + kPeerTolerance)
        add("/vertical_wrap_amount", Severity::converted,
            "the app's walls fill only z in [0, " + format_number(2.0 * wall_height_) +
                "] of each period " + format_number(wrap) +
                "; the walls of our translation prism fill the whole period");
    } else if (root_.has("vertical_wrap_amount")) {
      add("/vertical_wrap_amount", Severity::ignored,
          "the app uses it only with vertical_component \"circle\"");
    }
  }

  double band_top() const { return period_ ? *period_ : 2.0 * wall_height_; }

  // The map of gluing (i, j) as our scene writes it, from the file's map out of edge i: the
  // default orientation-preserving isometry, a reflection, or for a non-isometric affine map
  // the file's matrix (or its inverse, given the app's inverted linear parts) that carries edge
  // i onto edge j.
  nlohmann::ordered_json gluing_entry(int i, int j) const {
    const int a = numbering_.edge(i), b = numbering_.edge(j);
    nlohmann::ordered_json edges = {{0, a}, {0, b}};
    const PeerEdge& e = edges_[static_cast<size_t>(i)];
    if (e.type != PeerEdge::Type::affine ||
        (is_orthogonal(e.matrix) && glm::determinant(e.matrix) > 0.0))
      return edges;
    if (is_orthogonal(e.matrix)) return {{"edges", edges}, {"map", "reflection"}};
    const Vec2 A = polygon_.vertex(a), B = polygon_.vertex(a + 1), C = polygon_.vertex(b),
               D = polygon_.vertex(b + 1);
    for (const Mat2& m : {e.matrix, glm::inverse(e.matrix)}) {
      const Vec2 target = glm::determinant(m) > 0.0 ? C - D : D - C;
      if (glm::length(m * (B - A) - target) <= kPeerTolerance * scale_)
        return {{"edges", edges},
                {"matrix", {{tidy(m[0][0]), tidy(m[1][0])}, {tidy(m[0][1]), tidy(m[1][1])}}}};
    }
    root_["edges"][static_cast<size_t>(i)]["transform"]["matrix"].fail(
        "neither this matrix nor its inverse carries edge " + std::to_string(i) + " onto edge " +
        std::to_string(j) + ", to which /gluing/" + std::to_string(i) + " glues it");
  }

  void convert_gluings() {
    for (int i = 0; i < edge_count(); ++i) {
      const int j = partner_[static_cast<size_t>(i)];
      if (j <= i) continue;  // a mirror, or a pair already written
      gluings_.push_back(gluing_entry(i, j));
      gluing_source_.push_back(i);
    }
  }

  void convert_decorations() {
    if (!root_.has("decorations")) return;
    const JsonNode list = root_["decorations"];
    const size_t n = list.array_size(0, SceneLimits::max_objects);
    for (size_t d = 0; d < n; ++d) convert_decoration(list[d], d);
  }

  // The decoration's centre in the app's coordinates: a 2D [x, z] position with `height` y, or a
  // legacy 3D [x, y, z] one.
  Vec3 decoration_position(const JsonNode& node, const std::string& type) {
    const JsonNode position = node["position"];
    if (position.array_size(2, 3) == 2)
      return {position[0].number(), node.has("height") ? node["height"].number() : 0.0,
              position[1].number()};
    if (node.has("height") && type != "cylinder")  // a cylinder's height is also its length
      add(node.pointer() + "/height", Severity::ignored,
          "the app takes the height of a 3D position from position[1]");
    return position.vec3();
  }

  void convert_decoration(const JsonNode& node, size_t d) {
    node.object();
    const std::string type = node["type"].string();
    std::vector<std::string> known{"type", "position", "height", "radius", "color"};
    Vec3 app = decoration_position(node, type);
    Object o;
    const bool legacy_hollow =
        type == "sphere" && node.has("hollowCube") && node["hollowCube"].boolean();
    if (type == "hollow_cube" || legacy_hollow) {
      known.insert(known.end(), {"inner_ratio", "hollowCube"});
      const double r = node["radius"].positive();
      const double ratio = node.has("inner_ratio") && !legacy_hollow
                               ? node["inner_ratio"].positive()
                               : kDefaultInnerRatio;
      if (legacy_hollow)
        add(node.pointer() + "/hollowCube", Severity::converted,
            "the app's deprecated form of a hollow cube: converted as one with inner_ratio " +
                format_number(kDefaultInnerRatio));
      // The app draws a box of half-size radius * inner_ratio minus a sphere of the radius.
      o.type = ObjectType::hollow_cube;
      o.size = tidy(r * ratio);
      o.hole = r;
      if (o.hole >= std::sqrt(3.0) * o.size) {
        add(node.pointer(), Severity::dropped,
            "with inner_ratio " + format_number(ratio) +
                " the sphere removes the whole box: the app draws nothing");
        return;
      }
    } else if (type == "sphere") {
      known.insert(known.end(), {"animation", "hollowCube"});
      o.type = ObjectType::sphere;
      o.radius = node["radius"].positive();
      if (node.has("animation")) {
        const std::optional<Vec2> at = still_position(node, Vec2(app.x, app.z));
        if (!at) return;
        app.x = at->x;
        app.z = at->y;
      }
    } else if (type == "cylinder") {
      known.push_back("length");
      o.type = ObjectType::cylinder;
      o.radius = node["radius"].positive();
      // The app takes `length || height` as the full length, centred on the position.
      const double length = node.has("length") && node["length"].number() != 0.0
                                ? node["length"].positive()
                                : node["height"].positive();
      o.z0 = tidy(app.y + wall_height_ - 0.5 * length);
      o.z1 = tidy(app.y + wall_height_ + 0.5 * length);
      if (const std::optional<int> vertex = vertex_at(Vec2(app.x, app.z))) {
        pillars_.push_back({*vertex, d, o.radius, o.z0, o.z1});
        report_unknown_keys(node, known);
        return;
      }
    } else {
      add(node.pointer(), Severity::dropped,
          "unknown decoration type \"" + type + "\": the app draws nothing for it");
      return;
    }
    report_unknown_keys(node, known);
    o.center = Vec3(app.x, app.z, tidy(app.y + wall_height_));
    if (fits(o, node.pointer())) {
      objects_.push_back(object_json(o));
      object_source_.push_back(d);
    }
  }

  // Whether the object fits our rules (DESIGN.md section 1: strictly inside the polygon, within
  // the wall band or period), after moving it up or down into the band if it sticks out.
  bool fits(Object& o, const std::string& pointer) {
    const Vec2 c(o.center);
    if (!polygon_.contains(c)) {
      add(pointer, Severity::dropped, "its centre " + format_vec(c) + " is outside the polygon");
      return false;
    }
    const double room = polygon_.distance_to_boundary(c);
    if (room <= o.footprint_radius()) {
      add(pointer, Severity::dropped,
          "it touches or crosses the polygon's boundary (footprint radius " +
              format_number(o.footprint_radius()) + ", " + format_number(room) +
              " from the boundary): objects lie strictly inside");
      return false;
    }
    const double top = band_top();
    const std::string band =
        std::string(period_ ? "period" : "wall band") + " [0, " + format_number(top) + "]";
    if (o.z_max() - o.z_min() > top) {
      add(pointer, Severity::dropped,
          "it is " + format_number(o.z_max() - o.z_min()) + " tall, taller than the " + band);
      return false;
    }
    const double shift = o.z_min() < 0.0 ? -o.z_min() : std::min(0.0, top - o.z_max());
    if (shift != 0.0) {
      add(pointer, Severity::moved,
          std::string(shift > 0.0 ? "raised" : "lowered") +
              " from z = " + format_number(o.center.z) +
              " (the app's y = " + format_number(o.center.z - wall_height_) + ") to z = " +
              format_number(o.center.z + shift) + " so that it lies within the " + band);
      o.center.z = tidy(o.center.z + shift);
      o.z0 = tidy(o.z0 + shift);
      o.z1 = tidy(o.z1 + shift);
      // Rounding may leave it an ulp outside the band: step it in.
      for (int ulp = 0; ulp < 8 && (o.z_min() < 0.0 || o.z_max() > top); ++ulp) {
        const double inwards = o.z_min() < 0.0 ? top : 0.0;
        o.center.z = std::nextafter(o.center.z, inwards);
        o.z0 = std::nextafter(o.z0, inwards);
        o.z1 = std::nextafter(o.z1, inwards);
      }
    }
    return true;
  }

  static nlohmann::ordered_json object_json(const Object& o) {
    nlohmann::ordered_json j = {
        {"type", to_string(o.type)}, {"polygon", o.polygon}, {"center", json_vec(o.center)}};
    if (o.type == ObjectType::hollow_cube) {
      j["size"] = o.size;
      j["hole"] = o.hole;
    } else {
      j["radius"] = o.radius;
    }
    if (o.type == ObjectType::cylinder) j["z"] = {o.z0, o.z1};
    return j;
  }

  // Where an animated sphere stands in a still: at the start of its animation (time 0), or at
  // its position when the animation is disabled. Nothing when the app does not draw it.
  std::optional<Vec2> still_position(const JsonNode& node, Vec2 position) {
    const JsonNode animation = node["animation"].object();
    if (!(animation.has("enabled") && animation["enabled"].boolean())) {
      add(animation.pointer(), Severity::ignored, "the animation is disabled");
      return position;
    }
    for (const auto& [key, value] : animation.json().items())
      if (key != "enabled" && key != "type" && key != "speed" && key != "radius" && key != "center")
        add(animation.pointer() + "/" + key, Severity::ignored,
            "not a field of the app's animations");
    if (!animation.has("type") || animation["type"].string() != "circular") {
      add(node.pointer(), Severity::dropped,
          "the app draws animated spheres only of type \"circular\"");
      return std::nullopt;
    }
    const double radius = animation["radius"].number();
    if (animation.has("speed")) animation["speed"].number();  // checked; a still has no time
    Vec2 center(0.0);
    if (animation.has("center")) {
      const JsonNode c = animation["center"];
      center = c.array_size(2, 3) == 2 ? c.vec2() : Vec2(c[0].number(), c[2].number());
    }
    // The app's sphere is at center + radius (cos(speed t), sin(speed t)) in (x, z).
    const Vec2 start = center + Vec2(radius, 0.0);
    add(animation.pointer(), Severity::converted,
        "scenes are still: the sphere stands where its circular animation starts, " +
            format_vec(start) + " = center + (radius, 0), and does not move");
    return start;
  }

  void report_unknown_keys(const JsonNode& node, const std::vector<std::string>& known) {
    for (const auto& [key, value] : node.json().items()) {
      const std::string at = node.pointer() + "/" + key;
      if (key == "color")
        add(at, Severity::ignored,
            "the app colours every decoration by its normal, as our default colour does");
      else if (std::find(known.begin(), known.end(), key) == known.end())
        add(at, Severity::ignored, "not a field of the app's decorations");
    }
  }

  // The file's index of the polygon vertex at p, if any.
  std::optional<int> vertex_at(Vec2 p) const {
    for (int k = 0; k < edge_count(); ++k)
      if (glm::length(polygon_.vertex(numbering_.vertex(k)) - p) <= kPeerTolerance * scale_)
        return k;
    return std::nullopt;
  }

  void convert_camera() {
    const Vec3 app =
        root_.has("initialPosition") ? root_["initialPosition"].vec3() : kDefaultInitialPosition;
    Vec3 position(app.x, app.z, app.y + wall_height_);
    const bool in_band = period_ || (position.z >= 0.0 && position.z <= 2.0 * wall_height_);
    if (in_band && !polygon_.contains(Vec2(position))) {
      const Vec2 inside = interior_point(polygon_);
      add("/initialPosition", Severity::moved,
          "the app starts at " + format_vec(Vec2(position)) +
              ", which is not strictly inside the polygon (our cameras within the wall band "
              "must be); the camera starts at " +
              format_vec(inside) + " instead");
      position = Vec3(inside, position.z);
    }
    const double fov = std::round(app_vertical_fov_deg() * 1000.0) / 1000.0;
    camera_ = {{"polygon", 0},
               {"position", json_vec(Vec3(tidy(position.x), tidy(position.y), tidy(position.z)))},
               {"yaw_deg", kAppYawDeg},
               {"fov_deg", fov}};
    add("/initialPosition", Severity::converted,
        "the app's initial view looks along its -z axis with a 75 degree field of view over "
        "half the shorter image side: yaw -90 and a vertical field of view of " +
            format_number(fov) +
            " degrees here (for landscape images); the image is the mirror image of the app's");
  }

  void convert_look() {
    double strength = kDefaultFogStrength;
    if (root_.has("fog_effect_strength")) {
      const JsonNode node = root_["fog_effect_strength"];
      strength = node.number();
      if (strength < 0.0 || strength > 1.0) node.fail("fog_effect_strength lies in [0, 1]");
    }
    // The app's look: a white background, every crossing darker, no colours on walls.
    look_ = {{"wall_tint", strength},
             {"fog", {0.0, 0.0, 0.0}},
             {"sky", {1.0, 1.0, 1.0}},
             {"ground", {1.0, 1.0, 1.0}},
             {"mirror", {0.0, 0.0, 0.0}}};
    add("/fog_effect_strength", Severity::converted,
        std::string(root_.has("fog_effect_strength")
                        ? ""
                        : "absent, so the app's default " + format_number(kDefaultFogStrength) +
                              "; ") +
            "the app subtracts n * " + format_number(strength) +
            " from the colour after n wall crossings, the scene multiplies it by (1 - " +
            format_number(strength) +
            ")^n (wall_tint, with black walls and mirrors: equal to first order at normal "
            "incidence; here the walls are up to four times as dark at grazing incidence), on a "
            "white sky and ground that darken into a black fog at the horizon");
  }

  void report_unknown_keys() {
    for (const auto& [key, value] : root_.json().items())
      if (std::find(kPeerKeys.begin(), kPeerKeys.end(), key) == kPeerKeys.end())
        add("/" + key, Severity::ignored, "not used by the app's renderer, nor here");
  }

  nlohmann::ordered_json document() const {
    nlohmann::ordered_json doc;
    doc["name"] = name_;
    doc["description"] = description_;
    nlohmann::ordered_json vertices = nlohmann::ordered_json::array();
    for (Vec2 v : polygon_.vertices) vertices.push_back(json_vec(v));
    // One polygon. Spelled out: `= {vertices}` is a copy of vertices for Clang, a list for GCC.
    doc["polygons"] = nlohmann::ordered_json::array({vertices});
    doc["gluings"] = gluings_;
    doc["height"] = tidy(2.0 * wall_height_);
    if (period_) doc["period"] = *period_;
    if (!objects_.empty()) doc["objects"] = objects_;
    if (markers_) doc[markers_->first] = {{"radius", markers_->second}};
    doc["camera"] = camera_;
    doc["look"] = look_;
    // Glued walls black like the app's: each crossing only darkens.
    doc["look"]["gluings"] = nlohmann::ordered_json::array();
    for (size_t k = 0; k < gluings_.size(); ++k) doc["look"]["gluings"].push_back({0.0, 0.0, 0.0});
    return doc;
  }

  // The place in the file that a part of the converted scene comes from, for errors.
  std::string peer_pointer(const std::string& ours) const {
    std::istringstream tokens(ours);
    std::string empty, key, index;
    std::getline(tokens, empty, '/');
    std::getline(tokens, key, '/');
    std::getline(tokens, index, '/');
    const auto number = [&] {
      return index.empty() || !std::isdigit(static_cast<unsigned char>(index[0]))
                 ? -1
                 : std::stoi(index);
    };
    if (key == "gluings" && number() >= 0 && static_cast<size_t>(number()) < gluing_source_.size())
      return "/gluing/" + std::to_string(gluing_source_[static_cast<size_t>(number())]);
    if (key == "objects" && number() >= 0 && static_cast<size_t>(number()) < object_source_.size())
      return decoration_pointer(object_source_[static_cast<size_t>(number())]);
    if ((key == "singularities" || key == "vertices") && !pillars_.empty())
      return decoration_pointer(pillars_.front().decoration);
    if (key == "polygons") return "/vertices";
    if (key == "camera") return "/initialPosition";
    if (key == "height") return "/wallHeight";
    if (key == "period") return "/vertical_wrap_amount";
    if (key == "look") return "/fog_effect_strength";
    return "/";
  }

  // Loads the converted scene; everything was checked on the way, so a rejection is a problem
  // of the file that only the loader sees (glued edges of different lengths, say).
  Scene load() const {
    try {
      return scene_from_json(nlohmann::json(document()), file_);
    } catch (const SceneError& e) {
      throw SceneError(file_, peer_pointer(e.pointer()),
                       "the converted scene is invalid at " + e.pointer() + ": " + e.problem());
    }
  }

  // Cylinders at polygon vertices cannot be objects (objects lie strictly inside), but our
  // markers draw exactly such cylinders, around every corner of the vertex classes they mark.
  Scene add_markers(Scene scene) {
    std::set<int> marked, singular;
    for (const Pillar& p : pillars_)
      marked.insert(scene.corner_class[0][static_cast<size_t>(numbering_.vertex(p.vertex))]);
    for (size_t c = 0; c < scene.vertex_classes.size(); ++c)
      if (scene.vertex_classes[c].singular) singular.insert(static_cast<int>(c));
    // Our markers mark either the singular classes or all of them: the smallest that covers the
    // file's.
    const bool singularities =
        std::includes(singular.begin(), singular.end(), marked.begin(), marked.end());
    double radius = 0.0;
    std::string sources, missing, extent;
    std::set<int> pillar_vertices;
    for (const Pillar& p : pillars_) {
      radius = std::max(radius, p.radius);
      pillar_vertices.insert(p.vertex);
      sources += (sources.empty() ? "" : ", ") + decoration_pointer(p.decoration);
      if (std::abs(p.z0) > kPeerTolerance || std::abs(p.z1 - band_top()) > kPeerTolerance)
        extent = "; ours span the whole " + std::string(period_ ? "period" : "wall band") +
                 ", not only z in [" + format_number(p.z0) + ", " + format_number(p.z1) + "]";
    }
    for (int k = 0; k < edge_count(); ++k) {
      const int c = scene.corner_class[0][static_cast<size_t>(numbering_.vertex(k))];
      const bool drawn = singularities ? singular.contains(c) : true;
      if (drawn && !pillar_vertices.contains(k))
        missing += (missing.empty() ? "" : ", ") + std::to_string(k);
    }
    bool radii_differ = false;
    for (const Pillar& p : pillars_) radii_differ = radii_differ || p.radius != radius;
    const std::string key = singularities ? "singularities" : "vertices";
    add(decoration_pointer(pillars_.front().decoration), Severity::converted,
        "the cylinders " + sources +
            " stand at polygon vertices, where objects cannot (they lie strictly inside the "
            "polygon); they become \"" +
            key + "\": {\"radius\": " + format_number(radius) + "}, a cylinder around " +
            (singularities ? "every corner of each singular vertex class" : "every vertex") +
            (missing.empty() ? "" : " (the file has none at vertices " + missing + ")") +
            (radii_differ ? "; the radii differ, the largest is used" : "") + extent);
    markers_ = {key, radius};
    try {
      return scene_from_json(nlohmann::json(document()), file_);
    } catch (const SceneError& e) {
      add(decoration_pointer(pillars_.front().decoration), Severity::dropped,
          "the " + key + " markers do not fit: " + e.problem());
      markers_.reset();
      return scene;
    }
  }

  void check_edges(const Scene& scene) {
    const Polygon& ours = scene.polygons[0];
    const double position_tolerance = kPeerTolerance * scale_;
    for (int i = 0; i < edge_count(); ++i) {
      const std::string at = "/edges/" + std::to_string(i);
      const PeerEdge& e = edges_[static_cast<size_t>(i)];
      const Edge& edge = ours.edges[static_cast<size_t>(numbering_.edge(i))];
      const int j = partner_[static_cast<size_t>(i)];
      if (i > 0 && e.type_name != edges_.front().type_name)
        add(at + "/type", Severity::disagrees,
            "the app gives every edge the type of /edges/0 (" + edges_.front().type_name +
                "), not " + e.type_name);
      if (j == i && e.type != PeerEdge::Type::mirror)
        add(at + "/type", Severity::disagrees,
            "/gluing/" + std::to_string(i) + " makes edge " + std::to_string(i) +
                " a mirror, but its type is " + e.type_name);
      if (j != i && e.type == PeerEdge::Type::mirror)
        add(at + "/type", Severity::disagrees,
            "/gluing/" + std::to_string(i) + " glues edge " + std::to_string(i) + " to edge " +
                std::to_string(j) + ", but its type is mirror");
      if (j != i && e.type == PeerEdge::Type::translation)
        check_translation(at, e, edge, position_tolerance);
      if (j != i && e.type == PeerEdge::Type::affine) check_affine(at, e, edge, position_tolerance);
      check_normal(i, edge);
    }
  }

  void check_translation(const std::string& at, const PeerEdge& e, const Edge& edge,
                         double tolerance) {
    const Affine2& g = edge.map;
    if (max_difference(g.linear, Mat2(1.0)) > kPeerTolerance) {
      add(at + "/type", Severity::disagrees,
          "the derived map of this edge is a " + std::string(to_string(classify(g.linear))) +
              " (linear part " + format_matrix(g.linear) + "), not a translation");
      return;
    }
    if (glm::length(e.vector - g.translation) <= tolerance) return;
    if (glm::length(e.vector + g.translation) <= tolerance)
      add(at + "/vector", Severity::disagrees,
          "vector " + format_vec(e.vector) +
              " is the translation of the glued edge back to this one; the derived map out of "
              "this edge translates by " +
              format_vec(g.translation));
    else
      add(at + "/vector", Severity::disagrees,
          "vector " + format_vec(e.vector) +
              " disagrees with the derived map, which translates by " + format_vec(g.translation));
  }

  void check_affine(const std::string& at, const PeerEdge& e, const Edge& edge, double tolerance) {
    const Mat2& m = e.matrix;
    const Mat2& derived = edge.map.linear;
    const bool transpose_is_derived = max_difference(glm::transpose(m), derived) <= kPeerTolerance;
    // GLSL's mat2(a, b, c, d) fills columns, so the app applies [[a, c], [b, d]].
    const std::string app_applies = transpose_is_derived
                                        ? "; the app's GLSL mat2(a, b, c, d) fills columns, so "
                                          "it applies the transpose, which is the derived map"
                                        : "";
    if (max_difference(m, derived) > kPeerTolerance) {
      const char* relation = max_difference(m, glm::inverse(derived)) <= kPeerTolerance
                                 ? "is the inverse of"
                             : transpose_is_derived ? "is the transpose of"
                                                    : "disagrees with";
      add(at + "/transform/matrix", Severity::disagrees,
          std::string("linear part ") + relation + " the derived map: the file has " +
              format_matrix(m) + ", the derived map " + format_matrix(derived) + app_applies);
    }
    if (glm::length(e.translation - edge.map.translation) > tolerance)
      add(at + "/transform/translation", Severity::disagrees,
          "translation " + format_vec(e.translation) + " disagrees with the derived map's " +
              format_vec(edge.map.translation));
  }

  void check_normal(int i, const Edge& edge) {
    const Vec2 n = normals_[static_cast<size_t>(i)];
    if (glm::length(n - edge.normal) <= kPeerTolerance) return;
    const std::string at = "/normals/" + std::to_string(i);
    if (glm::length(n + edge.normal) <= kPeerTolerance) {
      add(at, Severity::disagrees,
          "normal " + format_vec(n) + " points inward instead of outward; the outward normal is " +
              format_vec(edge.normal));
      return;
    }
    const double angle =
        glm::length(n) > 0.0
            ? std::acos(std::clamp(glm::dot(glm::normalize(n), edge.normal), -1.0, 1.0)) * 180.0 /
                  kPi
            : 180.0;
    add(at, Severity::disagrees,
        "normal " + format_vec(n) + " is not the outward unit normal " + format_vec(edge.normal) +
            " (" + format_number(angle) + " degrees off, length " + format_number(glm::length(n)) +
            ")");
  }

  const std::string file_;
  const JsonNode root_;
  std::vector<PeerFinding> findings_;
  double scale_ = 1.0;
  Polygon polygon_;  // counterclockwise
  Numbering numbering_;
  std::vector<int> partner_;
  std::vector<PeerEdge> edges_;
  std::vector<Vec2> normals_;
  std::string name_, description_;
  double wall_height_ = kDefaultWallHeight;
  std::optional<double> period_;
  nlohmann::ordered_json gluings_ = nlohmann::ordered_json::array();
  std::vector<int> gluing_source_;  // the file's edge behind each of our gluings
  nlohmann::ordered_json objects_ = nlohmann::ordered_json::array();
  std::vector<size_t> object_source_;  // the decoration behind each of our objects
  std::vector<Pillar> pillars_;
  std::optional<std::pair<std::string, double>> markers_;
  nlohmann::ordered_json camera_, look_;
};

}  // namespace

const char* to_string(Severity severity) {
  switch (severity) {
    case Severity::disagrees:
      return "disagrees";
    case Severity::converted:
      return "converted";
    case Severity::moved:
      return "moved";
    case Severity::dropped:
      return "dropped";
    case Severity::ignored:
      return "ignored";
  }
  return "?";
}

PeerImport import_peer(const nlohmann::json& peer, const std::string& file) {
  return Importer(peer, file).run();
}

PeerImport import_peer_file(const std::filesystem::path& path) {
  PeerImport result = import_peer(read_json_file(path), path.string());
  result.scene["imported_from"] = std::filesystem::absolute(path).lexically_normal().string();
  return result;
}

bool is_peer_geometry(const nlohmann::json& doc) {
  return doc.is_object() && doc.contains("vertices") && doc.contains("gluing") &&
         !doc.contains("polygons");
}

Camera benchmark_view(Camera start) {
  start.position += Vec3(0.5, 0.5, 0.0);
  start.yaw_deg = std::atan2(0.3, 1.0) * 180.0 / std::acos(-1.0);
  start.pitch_deg = 0.0;
  return start;
}

void use_benchmark_view(nlohmann::ordered_json& scene) {
  nlohmann::ordered_json& json = scene["camera"];
  const auto position = json["position"].get<std::vector<double>>();
  Camera camera;
  camera.position = Vec3(position.at(0), position.at(1), position.at(2));
  camera = benchmark_view(camera);
  json["position"] = {camera.position.x, camera.position.y, camera.position.z};
  json["yaw_deg"] = camera.yaw_deg;
  json["pitch_deg"] = camera.pitch_deg;
}

nlohmann::ordered_json findings_json(const std::vector<PeerFinding>& findings) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const PeerFinding& f : findings)
    list.push_back(
        {{"pointer", f.pointer}, {"severity", to_string(f.severity)}, {"message", f.message}});
  return list;
}

}  // namespace flatmarch
