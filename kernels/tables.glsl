// The flat tables a compiled scene hands every backend (GLSL subset, see glsl.hpp). Records are
// made of 4-vectors so that their layout is the same in C++ and in a std430 shader buffer.
//
// polygons[p] = ivec4(first edge, edge count, first object, object count): the polygon's edges
// and the solids in its room are contiguous runs of `edges` and `objects`.

// One edge of a polygon, with everything a ray that reaches it needs.
struct EdgeRecord {
  vec4 segment;     // from vertex a (x, y) to vertex b (z, w), counterclockwise
  vec4 line;        // outward unit normal n (x, y), dot(n, a) (z), 1 / |b - a|^2 (w)
  vec4 map_linear;  // the gluing map's linear part, columns (x, y) and (z, w)
  vec4 map_shift;   // its translation (x, y), 0, 0
  ivec4 link;       // kind (kEdge*), destination polygon, destination edge, 0 (unused)
  vec4 tint;        // glued or mirror: the colour (xyz) a crossing mixes in, and its opacity at
                    // normal incidence (w); a wall: 0
  vec4 seam;        // where its ends lie along it, dot(end, (-n.y, n.x)): the counterclockwise
                    // start (x) and end (y); what they are (z, w): 0 no corner (out at infinity),
                    // 1 a corner, 2 a cone point's corner (the seams, DESIGN.md section 1)
};

// One solid in one polygon's room.
struct ObjectRecord {
  vec4 center;  // x, y, z; radius of a bounding sphere (w)
  vec4 shape;   // sphere: radius; box: half-extents; hollow cube: size (xyz), hole (w);
                // cylinder: radius, half-height
  vec4 color;   // its own colour (xyz) when w > 0; otherwise the normal colours it
  ivec4 info;   // solid (kSolid*), index in the hit AOV, 0, 0
};

// Per-frame constants: the march parameters (DESIGN.md section 3), the band and the look. As a
// std140 block the vec4s start at a 16-byte boundary after the 12 scalars; ALIGN16 says so in C++.
struct KernelParams {
  int method;  // kMethod*
  int max_steps;
  int polygon_count;
  int convex;  // 1 where every room of the scene is convex (march.glsl's wall_distance), else 0
  real eps;
  real offset;
  real max_distance;
  real omega;
  real height;            // the walls span [0, height]
  real top;               // the period of a translation prism, else the height
  real vertex_tolerance;  // analytic: an exit this close to a vertex meets the vertex
  real fog_distance;      // path length at which a surface is half fog
  ALIGN16 vec4 fog;       // the look (DESIGN.md section 1), linear RGB (xyz)
  vec4 sky;
  vec4 ground;
  vec4 wall;
  vec4 floor_colour;
  vec4 period_tint;  // a translation prism's floor and ceiling, glued: as an edge's tint
  vec4 seams;        // width per unit of path length (x; 0: no seams), opacity (y), the same at
                     // cone points (z)
  vec4 seam_colour;  // of a seam at a corner, the top or the bottom of a wall (xyz)
  vec4 cone_colour;  // ... at a cone point's corner (xyz)
};
