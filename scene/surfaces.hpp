// Surface types, by which the report groups scenes and recommends parameters (and the tests and
// benchmarks pick them), and the generated surfaces of the scaling measurements: regular 2n-gons
// and staircases of squares.
#pragma once

#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace flatmarch {

// The kinds of surface whose rays meet different hazards, in the order the report lists them:
//   prism        a translation prism (z periodic): rays never escape, paths are long;
//   cone         an infinite surface with a rotation: rays pass a cone point and run out to
//                infinity (max_distance);
//   cylinder     an infinite surface of translations: rays run round it or out along it;
//   mirror       a billiard table: mirror edges, rays reflect;
//   dilation     similarity gluings: directions and lengths change at a crossing;
//   reflection   non-orientable gluings (the Klein bottle);
//   rotation     rotations or half-translations (unfolded polyhedra, the pillowcase): cone points;
//   translation  translation surfaces only.
// A scene of several kinds gets the first in this list.
const std::vector<std::string>& surface_types();
std::string surface_type(const Scene& scene);

// The regular 2n-gon (n >= 2) with opposite edges glued by translations (the square torus for
// n = 2, a genus-n/2 surface for even n), inradius 2, as a translation prism of period 2 with
// no objects: every ray runs to max_distance, crossing about as many edges whatever n.
Scene regular_polygon_surface(int n);

// A staircase of `squares` (even, >= 2) squares of side 2, each its own room: right edges glue
// square 2k to 2k+1, top edges 2k+1 to 2k+2 (cyclically), the rest follow (the classical
// staircase square-tiled surface). Also a prism of period 2 with no objects. Every square is
// drawn at [0, 2]^2; `apart`: square k at [2k, 2k + 2] x [0, 2] instead, the same surface with
// rooms that differ in their coordinates (named staircase_apart_N).
Scene staircase_surface(int squares, bool apart = false);

// The torus of side 4 as a translation prism with nothing in it: path length is max_distance.
Scene empty_torus_prism();

}  // namespace flatmarch
