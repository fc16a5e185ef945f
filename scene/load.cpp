#include "scene/load.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "scene/derive.hpp"
#include "scene/json_reader.hpp"

namespace flatmarch {

SceneError::SceneError(std::string file, std::string pointer, std::string what_is_wrong)
    : std::runtime_error("error: " + file + ": " + pointer + ": " + what_is_wrong),
      file_(std::move(file)),
      pointer_(std::move(pointer)),
      problem_(std::move(what_is_wrong)) {}

namespace {

std::string format_number(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

std::string format_edge(EdgeRef e) {
  return "[" + std::to_string(e.polygon) + ", " + std::to_string(e.edge) + "]";
}

// Nesting depth is checked before parsing so that no input can exhaust the stack.
void check_depth(std::string_view text, const std::string& file) {
  int depth = 0, line = 1, column = 0;
  bool in_string = false, escaped = false;
  for (char c : text) {
    ++column;
    if (c == '\n') ++line, column = 0;
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > SceneLimits::max_depth)
        throw SceneError(file, "/",
                         "JSON nested deeper than " + std::to_string(SceneLimits::max_depth) +
                             " levels at line " + std::to_string(line) + ", column " +
                             std::to_string(column));
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

EdgeRef read_edge_ref(const JsonNode& node, const Scene& scene) {
  node.array_size(2, 2);
  const int p = node[0].index(static_cast<int>(scene.polygons.size()), "polygon");
  const int e = node[1].index(scene.polygons[static_cast<size_t>(p)].size(), "edge");
  return {p, e};
}

EdgeKind read_boundary(const JsonNode& node) {
  const std::string b = node.string();
  if (b == "mirror") return EdgeKind::mirror;
  if (b == "wall") return EdgeKind::wall;
  node.fail("unknown boundary \"" + b + "\" (expected \"mirror\" or \"wall\")");
}

void read_polygons(const JsonNode& root, Scene& scene, EdgeKind boundary) {
  const JsonNode list = root["polygons"];
  const size_t n = list.array_size(1, SceneLimits::max_polygons);
  std::vector<JsonNode> vertex_lists;
  for (size_t p = 0; p < n; ++p) {
    JsonNode poly = list[p];
    if (poly.json().is_object()) {
      poly.allow_keys({"vertices"});
      poly = poly["vertices"];
    }
    const size_t nv = poly.array_size(3, SceneLimits::max_vertices_per_polygon);
    Polygon polygon;
    for (size_t v = 0; v < nv; ++v) {
      const JsonNode vertex = poly[v];
      if (vertex.json().is_object()) {  // an ideal vertex, {"to": [dx, dy]}
        vertex.allow_keys({"to"});
        Vec2 d = vertex["to"].vec2();
        const double largest = std::max(std::abs(d.x), std::abs(d.y));
        if (!(largest > 0.0))
          vertex["to"].fail("the direction of an ideal vertex must not be zero");
        d /= largest;  // no overflow or underflow in its length
        polygon.vertices.push_back(d / glm::length(d));
        polygon.ideal.push_back(true);
      } else {
        const Vec2 at = vertex.vec2();
        polygon.vertices.push_back(at);
        polygon.ideal.push_back(false);
        scene.scale = std::max({scene.scale, std::abs(at.x), std::abs(at.y)});
      }
    }
    scene.polygons.push_back(std::move(polygon));
    vertex_lists.push_back(poly);
  }
  for (size_t p = 0; p < n; ++p) {
    Polygon& polygon = scene.polygons[p];
    if (auto problem = check_polygon(polygon, scene.scale)) {
      if (problem->vertex >= 0)
        vertex_lists[p][static_cast<size_t>(problem->vertex)].fail(problem->message);
      list[p].fail(problem->message);
    }
    init_edges(polygon, boundary);
  }
}

void read_gluings(const JsonNode& root, Scene& scene) {
  if (!root.has("gluings")) return;
  const JsonNode list = root["gluings"];
  size_t total_edges = 0;
  for (const Polygon& p : scene.polygons) total_edges += p.vertices.size();
  const size_t n = list.array_size(0, total_edges / 2);
  std::vector<std::vector<int>> glued_by(scene.polygons.size());
  for (size_t p = 0; p < scene.polygons.size(); ++p)
    glued_by[p].assign(scene.polygons[p].vertices.size(), -1);

  for (size_t k = 0; k < n; ++k) {
    const JsonNode node = list[k];
    JsonNode edges = node;
    Gluing gl;
    Mat2 matrix(1.0);
    if (node.json().is_object()) {
      node.allow_keys({"edges", "map", "matrix"});
      edges = node["edges"];
      if (node.has("map") && node.has("matrix"))
        node.fail("give either \"map\" or \"matrix\", not both");
      if (node.has("map")) {
        const std::string m = node["map"].string();
        if (m == "isometry")
          gl.map = GluingMap::isometry;
        else if (m == "reflection")
          gl.map = GluingMap::reflection;
        else if (m == "similarity")
          gl.map = GluingMap::similarity;
        else
          node["map"].fail("unknown map \"" + m +
                           "\" (expected \"isometry\", \"reflection\" or \"similarity\")");
      }
      if (node.has("matrix")) {
        const JsonNode rows = node["matrix"];
        rows.array_size(2, 2);
        const Vec2 r0 = rows[0].vec2(), r1 = rows[1].vec2();
        matrix = Mat2(Vec2(r0.x, r1.x), Vec2(r0.y, r1.y));  // rows in the file, columns in glm
        gl.map = GluingMap::matrix;
      }
    }
    edges.array_size(2, 2);
    gl.a = read_edge_ref(edges[0], scene);
    gl.b = read_edge_ref(edges[1], scene);
    if (gl.a == gl.b) edges.fail("edge " + format_edge(gl.a) + " is glued to itself");
    for (size_t side = 0; side < 2; ++side) {
      const EdgeRef e = side == 0 ? gl.a : gl.b;
      const int earlier = glued_by[static_cast<size_t>(e.polygon)][static_cast<size_t>(e.edge)];
      if (earlier >= 0)
        edges[side].fail("edge " + format_edge(e) + " is already glued by /gluings/" +
                         std::to_string(earlier));
      glued_by[static_cast<size_t>(e.polygon)][static_cast<size_t>(e.edge)] = static_cast<int>(k);
    }
    GluingMapResult derived = derive_gluing_map(scene, gl.a, gl.b, gl.map, matrix);
    if (!derived.error.empty()) node.fail(derived.error);
    gl.g = derived.g;
    gl.type = classify(gl.g.linear);
    scene.gluings.push_back(gl);
    attach_gluing(scene, static_cast<int>(k));
  }
}

void read_boundaries(const JsonNode& root, Scene& scene) {
  if (!root.has("boundaries")) return;
  const JsonNode list = root["boundaries"];
  const size_t n = list.array_size();
  std::vector<std::pair<EdgeRef, size_t>> seen;
  for (size_t k = 0; k < n; ++k) {
    const JsonNode node = list[k].object();
    node.allow_keys({"edge", "boundary"});
    const EdgeRef e = read_edge_ref(node["edge"], scene);
    Edge& edge = scene.polygons[static_cast<size_t>(e.polygon)].edges[static_cast<size_t>(e.edge)];
    if (edge.kind == EdgeKind::infinity)
      node["edge"].fail("edge " + format_edge(e) +
                        " lies at infinity (between two ideal vertices): nothing reaches it, so "
                        "it takes no boundary");
    if (edge.kind == EdgeKind::glued)
      node["edge"].fail("edge " + format_edge(e) + " is glued by /gluings/" +
                        std::to_string(edge.gluing) + "; only unglued edges take a boundary");
    for (auto [other, at] : seen)
      if (other == e)
        node["edge"].fail("edge " + format_edge(e) + " already has a boundary at /boundaries/" +
                          std::to_string(at));
    seen.push_back({e, k});
    edge.kind = read_boundary(node["boundary"]);
  }
}

void read_objects(const JsonNode& root, Scene& scene) {
  if (!root.has("objects")) return;
  const JsonNode list = root["objects"];
  const size_t n = list.array_size(0, SceneLimits::max_objects);
  const double top = scene.period ? *scene.period : scene.height;
  for (size_t k = 0; k < n; ++k) {
    const JsonNode node = list[k].object();
    Object o;
    const std::string type = node["type"].string();
    if (type == "hollow_cube") {
      node.allow_keys({"type", "polygon", "center", "color", "size", "hole"});
      o.type = ObjectType::hollow_cube;
      o.size = node["size"].positive();
      o.hole = node.has("hole") ? node["hole"].positive() : 1.3 * o.size;
      if (o.hole >= std::sqrt(3.0) * o.size)
        node["hole"].fail("the hole (radius " + format_number(o.hole) +
                          ") removes the whole cube (half-size " + format_number(o.size) +
                          "); it needs hole < size * sqrt(3)");
    } else if (type == "sphere") {
      node.allow_keys({"type", "polygon", "center", "color", "radius"});
      o.type = ObjectType::sphere;
      o.radius = node["radius"].positive();
    } else if (type == "box") {
      node.allow_keys({"type", "polygon", "center", "color", "half"});
      o.type = ObjectType::box;
      o.half = node["half"].vec3();
      for (int i = 0; i < 3; ++i)
        if (!(o.half[i] > 0.0))
          node["half"][static_cast<size_t>(i)].fail("box half-extents must be positive");
    } else if (type == "cylinder") {
      node.allow_keys({"type", "polygon", "center", "color", "radius", "z"});
      o.type = ObjectType::cylinder;
      o.radius = node["radius"].positive();
      o.z0 = 0.0;
      o.z1 = top;
      if (node.has("z")) {
        const Vec2 z = node["z"].vec2();
        if (!(z.x < z.y)) node["z"].fail("expected [z0, z1] with z0 < z1");
        o.z0 = z.x;
        o.z1 = z.y;
      }
    } else {
      node["type"].fail("unknown object type \"" + type +
                        "\" (expected hollow_cube, sphere, box or cylinder)");
    }
    o.polygon = node.has("polygon")
                    ? node["polygon"].index(static_cast<int>(scene.polygons.size()), "polygon")
                    : 0;
    o.center = node["center"].vec3();
    if (node.has("color")) o.color = node["color"].color();
    if (type == "cylinder") o.center.z = 0.5 * (o.z0 + o.z1);

    const Polygon& polygon = scene.polygons[static_cast<size_t>(o.polygon)];
    const Vec2 c(o.center.x, o.center.y);
    const std::string where = type + " in polygon " + std::to_string(o.polygon);
    if (!polygon.contains(c))
      node["center"].fail("the " + where + " has its center outside that polygon");
    for (int i = 0; i < polygon.size(); ++i) {
      const double d = polygon.edges[static_cast<size_t>(i)].distance(c);
      if (d <= o.footprint_radius())
        node.fail("the " + where + " reaches edge " + std::to_string(i) +
                  ": its footprint radius " + format_number(o.footprint_radius()) +
                  " is not less than its distance " + format_number(d) +
                  " from that edge; objects lie strictly inside their polygon");
    }
    if (o.z_min() < 0.0 || o.z_max() > top)
      node.fail("the " + where + " spans z from " + format_number(o.z_min()) + " to " +
                format_number(o.z_max()) + ", outside the " +
                (scene.period ? "period" : "wall band") + " [0, " + format_number(top) + "]");
    scene.objects.push_back(o);
  }
}

void read_markers(const JsonNode& root, Scene& scene) {
  std::optional<double> singular_radius, vertex_radius;
  std::optional<JsonNode> singular_node, vertex_node;
  if (root.has("singularities")) {
    const JsonNode node = root["singularities"];
    node.allow_keys({"radius"});
    singular_radius = node["radius"].positive();
    singular_node = node["radius"];
  }
  if (root.has("vertices")) {
    const JsonNode node = root["vertices"];
    node.allow_keys({"radius"});
    vertex_radius = node["radius"].positive();
    vertex_node = node["radius"];
  }
  for (size_t c = 0; c < scene.vertex_classes.size(); ++c) {
    const VertexClass& vc = scene.vertex_classes[c];
    const bool by_singularity = vc.singular && singular_radius;
    if (!by_singularity && !vertex_radius) continue;
    const double r = by_singularity ? *singular_radius : *vertex_radius;
    const JsonNode& node = by_singularity ? *singular_node : *vertex_node;
    // The cylinder must stay a sector of the corner's disk: clear of every edge not at the corner.
    for (const Corner& k : vc.corners) {
      const Polygon& polygon = scene.polygons[static_cast<size_t>(k.polygon)];
      const Vec2 at = polygon.vertex(k.vertex);
      const int n = polygon.size();
      for (int i = 0; i < n; ++i) {
        const bool incident = i == k.vertex || (i + 1) % n == k.vertex;
        const Edge& edge = polygon.edges[static_cast<size_t>(i)];
        const double room = incident ? 0.5 * edge.length : edge.distance(at);
        if (r >= room)
          node.fail("radius " + format_number(r) + " is too large: around vertex " +
                    std::to_string(k.vertex) + " of polygon " + std::to_string(k.polygon) +
                    " the cylinder would reach " + (incident ? "the middle of edge " : "edge ") +
                    std::to_string(i) + " (room " + format_number(room) + ")");
      }
    }
    scene.markers.push_back({static_cast<int>(c), r});
  }
}

void read_camera(const JsonNode& root, Scene& scene) {
  Camera& cam = scene.camera;
  const JsonNode node = root.has("camera") ? root["camera"] : root;
  if (root.has("camera")) {
    node.allow_keys({"polygon", "position", "yaw_deg", "pitch_deg", "fov_deg"});
    if (node.has("polygon"))
      cam.polygon = node["polygon"].index(static_cast<int>(scene.polygons.size()), "polygon");
    if (node.has("yaw_deg")) cam.yaw_deg = node["yaw_deg"].number();
    if (node.has("pitch_deg")) {
      cam.pitch_deg = node["pitch_deg"].number();
      if (std::abs(cam.pitch_deg) > 90.0) node["pitch_deg"].fail("pitch lies in [-90, 90] degrees");
    }
    if (node.has("fov_deg")) {
      cam.fov_deg = node["fov_deg"].number();
      if (!(cam.fov_deg > 0.0 && cam.fov_deg < 180.0))
        node["fov_deg"].fail("the field of view lies in (0, 180) degrees");
    }
  }
  const Polygon& polygon = scene.polygons[static_cast<size_t>(cam.polygon)];
  const bool given = root.has("camera") && node.has("position");
  cam.position = given ? node["position"].vec3() : Vec3(polygon.centroid(), 0.5 * scene.height);
  const Vec2 xy(cam.position.x, cam.position.y);
  if (scene.in_band(cam.position.z) && !polygon.contains(xy)) {
    const std::string msg = "the camera at (" + format_number(cam.position.x) + ", " +
                            format_number(cam.position.y) + ", " + format_number(cam.position.z) +
                            ") is within the wall band but not strictly inside polygon " +
                            std::to_string(cam.polygon);
    if (given) node["position"].fail(msg);
    node.fail(msg + " (the default position is the polygon's centroid; give camera.position)");
  }
}

// "seams": false, or {"width", "opacity", "colour", "cones"}: "cones" a colour, or false to
// draw cone points as the other corners.
void read_seams(const JsonNode& node, Look::Seams& seams) {
  if (node.json().is_boolean()) {
    if (!node.boolean()) seams.opacity = seams.cone_opacity = 0.0;
    return;
  }
  node.object();
  node.allow_keys({"width", "opacity", "colour", "cones"});
  if (node.has("width")) {
    seams.width = node["width"].positive();
    if (seams.width > 0.5)
      node["width"].fail("the seams' width is an angle in radians, at most 0.5");
  }
  if (node.has("opacity")) {
    seams.opacity = seams.cone_opacity = node["opacity"].number();
    if (seams.opacity < 0.0 || seams.opacity > 1.0) node["opacity"].fail("opacity lies in [0, 1]");
  }
  if (node.has("colour")) seams.colour = node["colour"].color();
  if (node.has("cones")) {
    const JsonNode cones = node["cones"];
    if (cones.json().is_boolean()) {
      if (cones.boolean())
        cones.fail("\"cones\" is a colour, or false to draw cone points as the other corners");
      seams.cone = seams.colour;
      seams.cone_opacity = seams.opacity;
    } else {
      seams.cone = cones.color();
    }
  }
}

void read_look(const JsonNode& root, Scene& scene) {
  if (!root.has("look")) return;
  const JsonNode node = root["look"];
  if (node.has("background"))
    node["background"].fail(
        "the background is now a gradient: give \"sky\" (straight up) and "
        "\"ground\" (straight down); the horizon takes \"fog\"");
  node.allow_keys({"wall_tint", "fog", "fog_distance", "sky", "ground", "wall", "floor", "mirror",
                   "gluings", "seams"});
  Look& look = scene.look;
  if (node.has("wall_tint")) {
    look.wall_tint = node["wall_tint"].number();
    if (look.wall_tint < 0.0 || look.wall_tint > 1.0)
      node["wall_tint"].fail("wall_tint lies in [0, 1]");
  }
  if (node.has("fog_distance")) look.fog_distance = node["fog_distance"].positive();
  const std::pair<const char*, Vec3*> colours[] = {
      {"fog", &look.fog},   {"sky", &look.sky},     {"ground", &look.ground},
      {"wall", &look.wall}, {"floor", &look.floor}, {"mirror", &look.mirror}};
  for (const auto& [key, colour] : colours)
    if (node.has(key)) *colour = node[key].color();
  if (node.has("gluings")) {
    const JsonNode list = node["gluings"];
    // A translation prism's glued floor and ceiling take the colour after the gluings'.
    const size_t n = list.array_size(0, scene.gluings.size() + (scene.period ? 1 : 0));
    for (size_t k = 0; k < n; ++k) look.gluings.push_back(list[k].color());
  }
  if (node.has("seams")) read_seams(node["seams"], look.seams);
}

}  // namespace

Scene scene_from_json(const nlohmann::json& doc, const std::string& file) {
  const JsonNode root(doc, "", file);
  root.allow_keys({"name", "description", "polygons", "gluings", "boundary", "boundaries", "height",
                   "period", "floor", "objects", "singularities", "vertices", "camera", "look",
                   "imported_from"});
  Scene scene;
  scene.name =
      root.has("name") ? root["name"].string() : std::filesystem::path(file).stem().string();
  if (root.has("description")) scene.description = root["description"].string();
  if (root.has("imported_from")) {
    // The app's file it was converted from, relative to this scene's folder where relative.
    std::filesystem::path from = root["imported_from"].string();
    if (from.empty()) root["imported_from"].fail("an empty path");
    if (from.is_relative()) from = std::filesystem::path(file).parent_path() / from;
    scene.imported_from = from.lexically_normal().string();
  }
  if (root.has("height")) scene.height = root["height"].positive();
  if (root.has("period")) scene.period = root["period"].positive();
  if (root.has("floor")) scene.floor = root["floor"].boolean();
  if (scene.floor && scene.period)
    root["floor"].fail("a translation prism (\"period\") has no floor");

  read_polygons(root, scene,
                root.has("boundary") ? read_boundary(root["boundary"]) : EdgeKind::mirror);
  read_gluings(root, scene);
  read_boundaries(root, scene);
  derive_vertex_classes(scene);
  derive_topology(scene);
  read_objects(root, scene);
  read_markers(root, scene);
  read_camera(root, scene);
  read_look(root, scene);
  return scene;
}

nlohmann::json parse_json(std::string_view text, const std::string& file) {
  if (text.size() > SceneLimits::max_file_bytes)
    throw SceneError(
        file, "/",
        "the file is larger than " + std::to_string(SceneLimits::max_file_bytes >> 20) + " MiB");
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos)
    throw SceneError(file, "/", "the file is empty");
  check_depth(text, file);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    std::string msg = e.what();
    if (const size_t end = msg.find("] ");
        msg.starts_with("[json.exception") && end != std::string::npos)
      msg = msg.substr(end + 2);
    throw SceneError(file, "/", "invalid JSON: " + msg);
  }
}

nlohmann::json read_json_file(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw SceneError(file, "/", "is a directory, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(file, "/", "cannot open the file");
  std::string text;
  char buffer[1 << 16];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    text.append(buffer, static_cast<size_t>(in.gcount()));
    if (text.size() > SceneLimits::max_file_bytes)
      throw SceneError(
          file, "/",
          "the file is larger than " + std::to_string(SceneLimits::max_file_bytes >> 20) + " MiB");
  }
  return parse_json(text, file);
}

Scene parse_scene(std::string_view text, const std::string& file) {
  return scene_from_json(parse_json(text, file), file);
}

Scene load_scene(const std::filesystem::path& path) {
  Scene scene = scene_from_json(read_json_file(path), path.string());
  scene.source_file = path.string();
  return scene;
}

}  // namespace flatmarch
