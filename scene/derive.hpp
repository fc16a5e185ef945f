// Derivations of DESIGN.md section 1: what a scene file never states but a renderer needs.
// Each function returns an error message instead of throwing, so that the loader can attach
// the JSON pointer of the element at fault.
#pragma once

#include <optional>
#include <string>

#include "scene/scene.hpp"

namespace flatmarch {

// Relative tolerance for lengths and endpoints that must agree.
inline constexpr double kLengthTolerance = 1e-9;

struct PolygonProblem {
  int vertex = -1;  // the vertex to point at, or -1 for the whole polygon
  std::string message;
};

// Checks the rules for one polygon (no repeated vertices or zero-length edges, counterclockwise,
// simple; at most two ideal vertices, next to each other), filling its edge table (as
// init_edges, every edge a mirror) on the way; `scale` sets the tolerance of the geometric
// predicates.
std::optional<PolygonProblem> check_polygon(Polygon& polygon, double scale);

// Derives the map of a gluing from its edges (and `matrix` for GluingMap::matrix), or says why
// it cannot be derived.
struct GluingMapResult {
  Affine2 g;
  std::string error;
};
GluingMapResult derive_gluing_map(const Scene& scene, EdgeRef a, EdgeRef b, GluingMap map,
                                  const Mat2& matrix);

GluingType classify(const Mat2& linear);

// Fills a polygon's edge table with lengths and outward normals, every edge of kind `boundary`.
void init_edges(Polygon& polygon, EdgeKind boundary);

// Records gluing `index` in the edge tables of both of its edges.
void attach_gluing(Scene& scene, int index);

// Vertex classes, their cone angles, and the topology of the glued surface.
void derive_vertex_classes(Scene& scene);
void derive_topology(Scene& scene);

}  // namespace flatmarch
