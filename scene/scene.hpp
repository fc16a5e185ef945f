// The scene model of DESIGN.md section 1: polygons whose edges are glued in pairs (or act as
// mirrors or walls), thickened into rooms, with objects, a camera and a look. A Scene is only
// ever built by load_scene/parse_scene, which validate every rule and derive everything that
// can be derived (gluing maps, edge table, vertex classes, topology); nothing derived is read
// from the file.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "scene/geometry.hpp"

namespace flatmarch {

struct EdgeRef {
  int polygon = 0;
  int edge = 0;
  friend bool operator==(const EdgeRef&, const EdgeRef&) = default;
};

// How a gluing is written in the scene file.
enum class GluingMap { isometry, reflection, similarity, matrix };

// What the derived map is (DESIGN.md: translation, half-translation, rotation; plus the
// variants' kinds).
enum class GluingType { translation, half_translation, rotation, reflection, similarity, affine };

struct Gluing {
  EdgeRef a, b;
  GluingMap map = GluingMap::isometry;
  Affine2 g;  // carries the outside of a's polygon beyond a into b's polygon
  GluingType type = GluingType::translation;
};

// What an edge does to a ray that reaches it. An edge at infinity (between two ideal vertices,
// DESIGN.md section 1 "Infinite surfaces") is no wall: nothing reaches it.
enum class EdgeKind { glued, mirror, wall, infinity };

// Where an edge lies: a segment between finite vertices, a ray from a finite vertex out to an
// ideal one (ray_out) or in from an ideal one to a finite one (ray_in), or at infinity.
enum class EdgeShape { segment, ray_out, ray_in, at_infinity };

// One edge of a polygon, with everything a ray crossing it needs.
struct Edge {
  EdgeKind kind = EdgeKind::mirror;
  EdgeShape shape = EdgeShape::segment;
  int gluing = -1;      // index into Scene::gluings when glued
  EdgeRef to;           // destination edge when glued
  Affine2 map;          // this polygon's coordinates -> to.polygon's coordinates when glued
  Vec2 normal{0.0};     // outward unit normal (0 at infinity)
  double length = 0.0;  // infinite for rays and at infinity
  // The points of a segment or ray are start + u along, u in [0, length]: start is the finite
  // end (a ray_in's is its last vertex), along the unit direction into the edge.
  Vec2 start{0.0};
  Vec2 along{0.0};

  bool ray() const { return shape == EdgeShape::ray_out || shape == EdgeShape::ray_in; }
  // Distance from p to the edge's points (infinite at infinity).
  double distance(Vec2 p) const;
};

struct Polygon {
  std::vector<Vec2> vertices;  // counterclockwise; an ideal vertex holds its unit direction
  std::vector<bool> ideal;     // per vertex: the point at infinity in direction vertices[i]
  std::vector<Edge> edges;     // edge i runs from vertex i to vertex i+1 (mod n)

  size_t wrap(int i) const { return static_cast<size_t>(((i % size()) + size()) % size()); }
  int size() const { return static_cast<int>(vertices.size()); }
  // Vertex i's point, or an ideal vertex's direction (is_ideal says which).
  Vec2 vertex(int i) const { return vertices[wrap(i)]; }
  bool is_ideal(int i) const { return !ideal.empty() && ideal[wrap(i)]; }
  // Whether the polygon is unbounded (has an ideal vertex).
  bool infinite() const;
  // Infinite for an unbounded polygon.
  double area() const;
  // The area centroid; of an unbounded polygon, a point inside it a unit of scale in from its
  // finite vertices' mean, along the middle of its directions to infinity.
  Vec2 centroid() const;
  // The polygon cut off far out: each ideal vertex replaced by the point `radius` out along its
  // direction from its finite neighbour (two points when both neighbours are finite), and the
  // edge at infinity by an arc of points at least every 2pi / arc_steps. A finite polygon is
  // its vertices. Inside a disc of about radius / 2 it has the unbounded polygon's points.
  std::vector<Vec2> outline(double radius, int arc_steps = 8) const;
  // The points of the outline that stand in for the ideal vertices, in order: from the far
  // point of the ray running out to that of the ray running in. Empty for a finite polygon.
  std::vector<Vec2> far_points(double radius, int arc_steps = 8) const;
  // Strictly inside, at least `margin` away from every edge.
  bool contains(Vec2 p, double margin = 0.0) const;
  double distance_to_boundary(Vec2 p) const;
  // Interior angle at vertex i, in (0, 2pi).
  double corner_angle(int i) const;  // of a finite vertex
  // The direction in which edge i runs (not of unit length; 0 at infinity).
  Vec2 heading(int i) const;

  // Where the path o + s d, s in [0, s_max], first leaves the polygon: through the first edge it
  // crosses outward, at s (0 where it starts within s_tolerance behind the edge's line), or edge
  // -1 if none. Passing within `vertex_radius` of an end of an edge counts as meeting it. The
  // oracle's rays and the viewer's walks leave rooms by it.
  struct Exit {
    double s = std::numeric_limits<double>::infinity();
    int edge = -1;
  };
  Exit exit(Vec2 o, Vec2 d, double vertex_radius, double s_tolerance,
            double s_max = std::numeric_limits<double>::infinity()) const;
};

enum class ObjectType { hollow_cube, sphere, box, cylinder };

struct Object {
  ObjectType type = ObjectType::sphere;
  int polygon = 0;
  Vec3 center{0.0};
  double size = 0.0;          // hollow_cube: half-size of the cube
  double hole = 0.0;          // hollow_cube: radius of the removed sphere
  double radius = 0.0;        // sphere, cylinder
  Vec3 half{0.0};             // box half-extents
  double z0 = 0.0, z1 = 0.0;  // cylinder extent in z
  std::optional<Vec3> color;

  // Radius of the horizontal circle around the center that holds the object.
  double footprint_radius() const;
  // Lowest and highest z of the object.
  double z_min() const;
  double z_max() const;
};

// A vertical cylinder drawn around a vertex class ("singularities"/"vertices" in the scene):
// in each polygon it is the disk sector around each corner of the class. Its object index
// (hit AOV, traces) is Scene::objects.size() + its position in Scene::markers.
struct Marker {
  int vertex_class = 0;
  double radius = 0.0;
};

struct Corner {
  int polygon = 0;
  int vertex = 0;
};

struct VertexClass {
  std::vector<Corner> corners;
  double cone_angle = 0.0;  // sum of the corner angles
  bool boundary = false;    // touches a mirror or wall edge
  // Interior class: cone angle != 2pi. Boundary class: != pi (the cone angle 2x of the double
  // of the surface along its boundary differs from 2pi), so a straight boundary point is regular.
  bool singular = false;
};

struct Topology {
  int components = 1;
  // A polygon with an ideal vertex makes the surface infinite (DESIGN.md section 1): it has no
  // Euler characteristic or genus.
  bool infinite = false;
  std::optional<int> euler_characteristic;
  bool orientable = true;
  int boundary_components = 0;
  // Orientable: the number of handles; non-orientable: the number of cross-caps. Unset when
  // the scene has more than one component, or is infinite.
  std::optional<int> genus;
};

struct Camera {
  int polygon = 0;
  Vec3 position{0.0};
  double yaw_deg = 0.0;
  double pitch_deg = 0.0;
  double fov_deg = 75.0;
};

// How the rooms look (DESIGN.md section 1, "Appearance"), every colour linear RGB in [0, 1]. The
// defaults are chosen so that every gallery scene reads well: walls visible, the horizon a dark
// band between a light sky and a darker ground.
struct Look {
  // Opacity of a glued wall or a mirror crossed at normal incidence; about four times it at
  // grazing incidence. Each crossing takes that share of the light and gives its colour.
  double wall_tint = 0.05;
  Vec3 fog{0.035, 0.04, 0.05};     // what distance fades towards; the horizon
  double fog_distance = 15.0;      // path length at which a surface is half fog
  Vec3 sky{0.4, 0.5, 0.65};        // straight up, above the band; towards the horizon, the fog
  Vec3 ground{0.06, 0.055, 0.05};  // straight down, below it
  Vec3 wall{0.55, 0.55, 0.55};     // opaque walls, lit
  Vec3 floor{0.55, 0.55, 0.55};    // the floor's light checks, lit (the dark ones are darker)
  Vec3 mirror{0.05, 0.055, 0.07};  // a mirror's tint: a dark, bluish silver (lighter, the
                                   // reflections of an empty mirror room swam in it)
  // A colour per gluing, in the scene's gluing order, and in a translation prism one more for its
  // glued floor and ceiling; gluings beyond these take the palette's
  // at kPaletteShade of its light (the colours mix into what rays see, and far enough away
  // into the horizon: full-strength colours would wash it out).
  std::vector<Vec3> gluings;
  static constexpr double kPaletteShade = 0.4;
  // Seams: a ray crossing a glued wall or a mirror near one of the wall's vertical edges (a
  // corner of its polygon) or near its top or bottom passes a line painted on it first, so that
  // the panels of a tiling read at once. The line is `width` radians of view wide (at path length
  // t, width * t: the same number of pixels near and far); opacity 0 turns seams off. Corners
  // whose vertex class is a cone point (VertexClass::singular) take `cone` instead.
  struct Seams {
    double width = 0.008;            // about 1.9 pixels at the default 640x360, fov 75
    double opacity = 0.7;            // of the line; 0: no seams
    Vec3 colour{0.01, 0.01, 0.012};  // regular corners, the top and the bottom
    Vec3 cone{0.85, 0.35, 0.05};     // cone points
    double cone_opacity = 0.8;
    // Whether any line is drawn: off when both opacities are 0 (`"seams": false`).
    bool on() const { return opacity > 0.0 || cone_opacity > 0.0; }
  } seams;

  // The colour of gluing k (the floor plan draws the pair in it).
  Vec3 gluing_colour(int k) const;
};

// The palette glued pairs take by default, in sRGB as the floor plan writes it (Tableau 10
// without its pink, which the floor plan's light ray uses).
const std::vector<const char*>& gluing_palette();
// A linear value in [0, 1] encoded to sRGB (IEC 61966-2-1; clamped).
double encode_srgb(double linear);
// An sRGB value in [0, 1] decoded to linear (clamped).
double decode_srgb(double encoded);
// An sRGB "#rrggbb" colour as linear RGB, and back (rounded to 8 bits).
Vec3 linear_from_hex(const char* hex);
std::string hex_from_linear(Vec3 c);

struct Scene {
  std::string name;
  std::string description;
  std::vector<Polygon> polygons;
  std::vector<Gluing> gluings;
  double height = 2.0;
  std::optional<double> period;  // translation prism: z modulo period, nothing escapes
  bool floor = false;
  std::vector<Object> objects;
  std::vector<Marker> markers;
  Camera camera;
  Look look;
  // Where it came from: the file it was read from (empty for a scene made in code), and the web
  // app's geometry file it was converted from (`"imported_from"`, written by import-peer; empty
  // otherwise), which an external renderer that reads the app's format renders instead.
  std::string source_file;
  std::string imported_from;

  // Derived.
  std::vector<VertexClass> vertex_classes;
  std::vector<std::vector<int>> corner_class;  // [polygon][vertex] -> index in vertex_classes
  Topology topology;
  double scale = 1.0;  // largest absolute vertex coordinate, at least 1: the unit of tolerances

  const Edge& edge(EdgeRef e) const {
    return polygons[static_cast<size_t>(e.polygon)].edges[static_cast<size_t>(e.edge)];
  }
  // Index of the marker drawn at corner (p, v), or -1.
  int marker_at(int polygon, int vertex) const;
  // Whether z lies in the band of the walls (always in a translation prism).
  bool in_band(double z) const { return period || (z >= 0.0 && z <= height); }
};

const char* to_string(GluingType t);
const char* to_string(EdgeKind k);
const char* to_string(EdgeShape s);
const char* to_string(ObjectType t);

}  // namespace flatmarch
