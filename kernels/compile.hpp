// The scene compiler: a validated scene becomes the flat tables every backend consumes
// unchanged (kernels/tables.glsl), holding only what the scene uses.
#pragma once

#include <cmath>
#include <limits>
#include <vector>

#include "kernels/kernel.hpp"
#include "kernels/march_params.hpp"
#include "scene/scene.hpp"

namespace flatmarch::kernel {

template <typename real>
struct SceneTables {
  uint features = 0;  // kFeature* the scene uses
  std::vector<ivec4> polygons;
  std::vector<typename Tables<real>::EdgeRecord> edges;
  std::vector<typename Tables<real>::ObjectRecord> objects;
  typename Tables<real>::KernelParams params{};
};

// The feature set of a scene (kFeature*).
uint scene_features(const Scene& scene);

// An unbounded polygon (DESIGN.md section 1, "Infinite surfaces") is compiled as its outline
// cut off kFarRadius from its finite vertices (Polygon::outline), and rays must stay within
// kReach of the origin, a thousandth of that: there the outline's ray edges are the half-lines
// and its far links out of reach. In float the far points are rounded by ulp(2^40) = 2^17,
// which turns a ray edge by at most 2^-23 radians: what any float direction is rounded by.
inline constexpr double kFarRadius = 0x1p40;
inline constexpr double kReach = 0x1p30;

// Throws std::invalid_argument if rays from `camera` (or the scene's farthest finite vertex) in
// an unbounded scene would run beyond kReach within max_distance. compile_scene checks the
// scene's own camera; a caller that moves the camera checks its own.
void check_reach(const Scene& scene, double max_distance, Vec2 camera);

// `march.method` must be one the kernel runs (sphere, relaxed, analytic); throws as check_reach.
template <typename real>
SceneTables<real> compile_scene(const Scene& scene, const MarchParams& march);

// What crossing an edge does to a ray's colour: the colour it mixes in (xyz) and its opacity at
// normal incidence (w), as the edge table's `tint` holds it.
glm::dvec4 edge_tint(const Look& look, const Edge& edge);

// What crossing the glued floor and ceiling of a translation prism does to a ray's colour, as
// edge_tint: the colour after the gluings' (Look::gluing_colour).
glm::dvec4 period_tint(const Scene& scene);

// Edge `edge` of polygon `polygon` as the seams read it (the edge table's `seam`): where its
// counterclockwise start (x) and end (y) lie along it, as dot(vertex, (-n.y, n.x)) with n its
// outward normal, and what they are (z, w): 0 no corner (an ideal vertex; all 0 at infinity), 1 a
// corner, 2 a corner of a cone point (VertexClass::singular).
glm::dvec4 seam_record(const Scene& scene, int polygon, int edge);

// The appearance part of the kernel's parameters.
template <typename real>
void set_look(const Look& look, typename Tables<real>::KernelParams& params);

extern template SceneTables<float> compile_scene(const Scene&, const MarchParams&);
extern template SceneTables<double> compile_scene(const Scene&, const MarchParams&);
extern template void set_look<float>(const Look&, Tables<float>::KernelParams&);
extern template void set_look<double>(const Look&, Tables<double>::KernelParams&);

}  // namespace flatmarch::kernel
