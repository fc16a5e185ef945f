// The ray-marching kernel of DESIGN.md section 3, written once for every backend in the GLSL
// subset of kernels/glsl.hpp; the maths it does for one ray from numbers already read is in
// kernels/maths.glsl, which the SIMD backend runs on packets of rays. It reads the tables of
// kernels/tables.glsl (`polygons`, `edges`, `objects`, `params`) and calls `record_event`, both
// provided by whoever includes it; FEATURES is the feature set the kernel is specialised on
// (kFeature* in kernels/constants.glsl).
//
// A ray lives in one room at a time: its point `o` and unit direction `d` are in the
// coordinates of `polygon`. Per iteration only that polygon's edges and solids are evaluated.
//   sphere    sphere tracing against min(walls, solids) (Lander & Taha): a wall nearer than eps
//             is crossed, and the point placed `offset` inside the destination room
//   relaxed   the same, over-relaxed by omega (Keinert et al. 2014); a step whose unbounding
//             sphere does not overlap the last one is taken back and redone plainly
//   analytic  the exit edge and point computed exactly; sphere tracing only for solids, and
//             only from where the room segment enters a solid's bounding sphere
// The band [0, top] is left analytically by every method (z is linear along a ray).
//
// Defined failures: a ray within eps of two edges at once (sphere, relaxed) or exiting within
// vertex_tolerance of a vertex (analytic) ends with `vertex`; with offset <= eps a placed point
// is still within eps of the edge it came through and the ray crosses back and forth until
// max_steps; a ray grazing a wall creeps along it in steps of its distance to the wall until it
// gets there or reaches max_steps. The loop runs at most max_steps times.

bool has(uint feature) {
  return (FEATURES & feature) != 0u;
}

// The polygon whose table entries to read: `polygon`, or 0 in a scene of one polygon. The same
// number, but a shader with the scene baked in then reads constant entries, and its compiler
// unrolls the loops over the room's edges and folds their numbers in (no per-lane reads).
int room(int polygon) {
  return params.polygon_count == 1 ? 0 : polygon;
}

// Edge k of a polygon's room. In a baked shader of a one-polygon scene the software shape picks
// the edge from constants rather than read it at a per-ray index (a gather, the slowest read a
// SIMD shader core makes); the record is the same. (FLATMARCH_GPU_SHAPE, a shader's gpu shape:
// a GPU reads a table at a per-ray index from its caches, and the picking would read them all.)
EdgeRecord edge_at(int polygon, int k) {
#if defined(FLATMARCH_SHADER) && !defined(FLATMARCH_GPU_SHAPE)
  if (params.polygon_count == 1) {
    EdgeRecord e = edges[0];
    for (int j = 1; j < polygons[0].y; ++j) {
      if (j == k) e = edges[j];
    }
    return e;
  }
#endif
  return edges[polygons[room(polygon)].x + k];
}

// What a ray is doing, and once `done`, how it ended.
struct Ray {
  int polygon;
  vec3 o;  // point, in the coordinates of `polygon`
  vec3 d;  // unit direction
  real t;  // path length so far
  int steps;
  int crossings;  // gluings crossed and mirror bounces
  int hit;        // the hit AOV, once done
  bool done;
  int object;    // the index in the object table of the solid hit, or -1
  vec3 normal;   // of the solid, wall or floor hit
  vec3 surface;  // the colour of the solid hit
  vec3 light;    // what the walls crossed give (tint_light)
  real clear;    // the share of light beyond them that they let through
};

void advance(INOUT(Ray) r, real s) {
  r.o = r.o + s * r.d;
  r.t = r.t + s;
}

// Ends the ray `s` further on.
void finish(INOUT(Ray) r, int hit, int event, int edge, real s) {
  advance(r, s);
  r.hit = hit;
  r.done = true;
  record_event(event, r.polygon, edge, -1, -1, hit >= 0 ? hit : -1, r.t, r.o);
}

// ---- Walls -----------------------------------------------------------------------------------

bool inside_polygon(int polygon, vec2 p) {
  ivec4 poly = polygons[room(polygon)];
  bool inside = false;
  for (int k = poly.x; k < poly.x + poly.y; ++k) {
    vec4 s = edges[k].segment;
    vec2 a = vec2(s.x, s.y);
    if (crosses(p.y, s.y, s.y + (s.w - s.y), p - a, vec2(s.z, s.w) - a)) inside = !inside;
  }
  return inside;
}

// Distance from a point to the walls of its room: to the nearest edge (negative outside the
// polygon), which edge that is, and the distance to the next nearest one. Where the rooms are
// convex, outside is beyond the nearest edge's line, and the next nearest is the next nearest
// line's distance unless the nearest two lines are both within eps: no edge is nearer than its
// line, so only there can a second edge be within eps (a corner), and the same corners are found.
struct WallDistance {
  real d;
  int edge;
  real second;
};

WallDistance wall_distance(int polygon, vec2 p) {
  ivec4 poly = polygons[room(polygon)];
  if (params.convex != 0) {
    // The rooms are convex: inside, the nearest edge is as near as the nearest edge's line (the
    // foot of the perpendicular to that line lies on the edge), and a point is outside where it
    // is beyond a line. No edge is nearer than its line, so the segments are measured only
    // where the nearest and the next nearest line are both within eps: a corner, perhaps.
    WallDistance v;
    v.d = real(kFar);
    v.edge = -1;
    v.second = real(kFar);
    for (int k = 0; k < poly.y; ++k) {
      real gap = line_gap(p, edges[poly.x + k].line);
      if (gap < v.d) {
        v.second = v.d;
        v.d = gap;
        v.edge = k;
      } else if (gap < v.second) {
        v.second = gap;
      }
    }
    if (v.d < params.eps && v.second < params.eps) {
      // The edge is the nearest segment, the second the next: at a corner both are near; where
      // two edges lie on one line (a straight angle, as the web app's pillowcase has between
      // two edges glued to each other), their lines are, but the other segment may be far.
      real best = real(kFar);
      real next = real(kFar);
      for (int k = 0; k < poly.y; ++k) {
        vec4 s = edges[poly.x + k].segment;
        vec2 a = vec2(s.x, s.y);
        real d2 = segment_distance2(p - a, vec2(s.z, s.w) - a, edges[poly.x + k].line.w);
        if (d2 < best) {
          next = best;
          best = d2;
          v.edge = k;
        } else if (d2 < next) {
          next = d2;
        }
      }
      v.second = sqrt(next);
    }
    return v;
  }
  real best = real(kFar);
  real second = real(kFar);
  int edge = -1;
  bool inside = false;
  for (int k = 0; k < poly.y; ++k) {
    vec4 s = edges[poly.x + k].segment;
    vec2 a = vec2(s.x, s.y);
    vec2 ab = vec2(s.z, s.w) - a;
    real d2 = segment_distance2(p - a, ab, edges[poly.x + k].line.w);
    if (d2 < best) {
      second = best;
      best = d2;
      edge = k;
    } else if (d2 < second) {
      second = d2;
    }
    if (crosses(p.y, a.y, a.y + ab.y, p - a, ab)) inside = !inside;
  }
  WallDistance w;
  w.d = inside ? sqrt(best) : -sqrt(best);
  w.edge = edge;
  w.second = sqrt(second);
  return w;
}

// The edge through which a ray from o along dh leaves its polygon, at distance s along the ray
// (d's horizontal part has the length that makes s a 3D distance), and whether it leaves at a
// vertex. (Its loop, like the kernel's other loops, has no `continue` or early `return`:
// llvmpipe runs such loops at half the speed.)
struct Exit {
  real s;
  int edge;
  bool corner;
};

Exit exit_edge(int polygon, vec2 o, vec2 dh) {
  ivec4 poly = polygons[room(polygon)];
  Exit x;
  x.s = real(kFar);
  x.edge = -1;
  x.corner = false;
  for (int k = 0; k < poly.y; ++k) {
    vec4 line = edges[poly.x + k].line;
    vec2 n = vec2(line.x, line.y);
    real dn = dot(dh, n);
    if (dn > real(0)) {  // else the ray cannot leave through this edge
      real s = line_distance(o, n, line.z, dn);
      if (s >= -params.vertex_tolerance && s < x.s) {
        vec4 seg = edges[poly.x + k].segment;
        vec2 a = vec2(seg.x, seg.y);
        real u = edge_parameter(o + s * dh, a, vec2(seg.z, seg.w) - a, line.w);
        real tolerance = params.vertex_tolerance * sqrt(line.w);  // in units of u
        if (on_edge(u, tolerance)) {
          x.s = max(s, real(0));
          x.edge = k;
          x.corner = near_end(u, tolerance);
        }
      }
    }
  }
  return x;
}

// A glued wall or mirror of tint `tint` (the edge table's), crossed with the component
// `cosine` of the ray's direction along its normal, tints what lies beyond it (DESIGN.md
// section 1, Appearance), seen through the fog as far away as it is.
void tint_ray(INOUT(Ray) r, vec4 tint, real cosine) {
  real a = wall_opacity(tint.w, cosine);
  vec3 colour = fogged(vec3(tint), vec3(params.fog), r.t, params.fog_distance);
  r.light = tint_light(r.light, r.clear, a, colour);
  r.clear = r.clear * (real(1) - a);
}

// A ray crossing `edge` of its room near one of the wall's vertical edges, its top or its bottom
// passes a seam first (DESIGN.md section 1, Appearance): a line of a constant angle (params.seams.x
// radians: the same pixels wide near and far), drawn whatever crosses the wall, glued or mirror.
void seam_ray(INOUT(Ray) r, EdgeRecord edge) {
  if (params.seams.x > real(0)) {
    real half_width = real(0.5f) * params.seams.x * r.t;
    real kind = seam_kind(r.o, edge.line, edge.seam, half_width, params.top);
    real a = seam_opacity(kind, params.seams);
    vec3 colour = seam_colour(kind, params.seam_colour, params.cone_colour);
    colour = fogged(colour, vec3(params.fog), r.t, params.fog_distance);
    r.light = tint_light(r.light, r.clear, a, colour);
    r.clear = r.clear * (real(1) - a);
  }
}

// A ray at edge k of its polygon goes through it into the glued room, or is reflected by a
// mirror. Either way its point is then placed `push` inside the edge it is now behind (the
// paper's "safe distance greater than eps" from the new wall), wherever within eps of the old
// one it was.
void cross_edge(INOUT(Ray) r, int k, real push) {
  EdgeRecord edge = edge_at(r.polygon, k);
  vec4 line = edge.line;
  vec2 dh = vec2(r.d);
  seam_ray(r, edge);
  tint_ray(r, edge.tint, dot(dh, vec2(line.x, line.y)));
  if (has(kFeatureMirrors) && edge.link.x == kEdgeMirror) {
    record_event(kEventMirror, r.polygon, k, -1, -1, -1, r.t, r.o);
    r.o = vec3(place(vec2(r.o), line, push), r.o.z);
    r.d = vec3(mirror_direction(dh, line), r.d.z);
  } else {
    ivec4 link = edge.link;
    record_event(kEventGluing, r.polygon, k, link.y, link.z, -1, r.t, r.o);
    vec2 p = glue_point(edge.map_linear, edge.map_shift, vec2(r.o));
    dh = glue_direction(edge.map_linear, dh);
    r.o = vec3(place(p, edge_at(link.y, link.z).line, push), r.o.z);
    r.d = vec3(dh, r.d.z);
    // Under a map that is not an isometry the direction is renormalised (DESIGN.md section 1).
    if (has(kFeatureScaled)) r.d = normalize(r.d);
    r.polygon = link.y;
  }
  r.crossings += 1;
}

bool is_wall(int polygon, int k) {
  return has(kFeatureWalls) && edge_at(polygon, k).link.x == kEdgeWall;
}

// The ray ends on the opaque wall k of its room, `s` further on; its normal points into the room.
void hit_wall(INOUT(Ray) r, int k, real s) {
  finish(r, kHitWall, kEventWall, k, s);
  vec4 line = edge_at(r.polygon, k).line;
  r.normal = vec3(-line.x, -line.y, real(0));
}

// The ray reaches the top or bottom of the band, `s` further on.
void leave_band(INOUT(Ray) r, real s) {
  if (has(kFeaturePeriod)) {  // z is taken modulo the period
    advance(r, s);
    tint_ray(r, params.period_tint, r.d.z);
    r.o.z = r.d.z > real(0) ? real(0) : params.top;
  } else if (has(kFeatureFloor) && r.d.z < real(0)) {
    finish(r, kHitFloor, kEventFloor, -1, s);
    r.normal = vec3(real(0), real(0), real(1));
  } else {
    finish(r, kHitEscape, kEventEscape, -1, s);
  }
}

// ---- Solids ----------------------------------------------------------------------------------

// Signed distance from p to solid k of the object table.
real solid_distance(int k, vec3 p) {
  return solid_sdf(objects[k].info.x, vec3(objects[k].center), objects[k].shape, p);
}

struct SolidDistance {
  real d;
  int object;  // index in the object table
};

SolidDistance nearest_solid(int polygon, vec3 p) {
  SolidDistance best;
  best.d = real(kFar);
  best.object = -1;
  if (!has(kFeatureObjects)) return best;
  ivec4 poly = polygons[room(polygon)];
  for (int k = poly.z; k < poly.z + poly.w; ++k) {
    real d = solid_distance(k, p);
    if (d < best.d) {
      best.d = d;
      best.object = k;
    }
  }
  return best;
}

// Where a ray first comes within eps of a solid's bounding sphere in its room, or kFar.
real solid_entry(int polygon, vec3 o, vec3 d) {
  ivec4 poly = polygons[room(polygon)];
  real first = real(kFar);
  for (int k = poly.z; k < poly.z + poly.w; ++k) {
    vec4 c = objects[k].center;
    first = min(first, sphere_entry(o - vec3(c), d, c.w + params.eps));
  }
  return first;
}

// The unit normal of solid k of the object table at p.
vec3 solid_normal(int k, vec3 p) {
  return solid_normal_at(objects[k].info.x, vec3(objects[k].center), objects[k].shape, p);
}

// Its normal and colour are left to the end of the march (solid_look): a shader runs all of a
// loop's body for every ray, taken branch or not, and these are the costliest few lines.
void hit_solid(INOUT(Ray) r, int k) {
  r.object = k;
  finish(r, objects[k].info.y, kEventObject, -1, real(0));
}

void solid_look(INOUT(Ray) r) {
#if defined(FLATMARCH_FEW_OBJECTS) && !defined(FLATMARCH_GPU_SHAPE)
  // A few objects baked in: each solid's normal is evaluated with the solid's shape known (its
  // number a constant), and the one hit kept, rather than every shape's distance at a per-ray
  // index (the software shape: a GPU evaluates only the shapes its lanes hit).
  vec3 normal = vec3(real(0));
  vec4 color = vec4(real(0));
  for (int k = 0; k < objects.length(); ++k) {
    if (k == r.object) {
      normal = solid_normal(k, r.o);
      color = objects[k].color;
    }
  }
  r.normal = normal;
  r.surface = solid_surface(color, normal);
#else
  r.normal = solid_normal(r.object, r.o);
  r.surface = solid_surface(objects[r.object].color, r.normal);
#endif
}

// ---- Methods ---------------------------------------------------------------------------------

// State of over-relaxed sphere tracing within one room.
struct Relaxation {
  real omega;        // 1 after a failed over-relaxed step
  real last_radius;  // unbounding radius at the previous point
  real last_step;    // how far the previous step went
};

// Over-relaxation starts afresh in each room: after every crossing and period wrap.
void relax(INOUT(Relaxation) x) {
  x.omega = params.method == kMethodRelaxed ? params.omega : real(1);
  x.last_radius = real(0);
  x.last_step = real(0);
}

// One iteration of sphere or over-relaxed sphere tracing.
void sphere_step(INOUT(Ray) r, INOUT(Relaxation) x) {
  WallDistance wall = wall_distance(r.polygon, vec2(r.o));
  SolidDistance solid = nearest_solid(r.polygon, r.o);
  real radius = min(wall.d, solid.d);
  if (x.omega > real(1) && radius + x.last_radius < x.last_step) {
    // The unbounding spheres do not overlap: something may lie between. Go back and take the
    // plain step from the previous point (Keinert et al.'s fallback).
    advance(r, x.last_radius - x.last_step);
    x.last_step = x.last_radius;
    x.omega = real(1);
    return;
  }
  real wall_d = abs(wall.d);
  if (solid.d < params.eps && solid.d <= wall_d) {
    hit_solid(r, solid.object);
    return;
  }
  if (wall_d < params.eps) {
    if (wall.second < params.eps) {
      finish(r, kHitVertex, kEventVertex, -1, real(0));  // in a corner: no single edge to cross
    } else if (is_wall(r.polygon, wall.edge)) {
      hit_wall(r, wall.edge, real(0));
    } else {
      cross_edge(r, wall.edge, params.offset);
      relax(x);
    }
    return;
  }
  real safe = abs(radius);
  real band = band_exit(params.top, r.o.z, r.d.z);
  real remaining = params.max_distance - r.t;
  if (remaining <= min(safe, band)) {
    finish(r, kHitMaxDistance, kEventMaxDistance, -1, remaining);
  } else if (band <= safe) {
    leave_band(r, band);
    relax(x);
  } else {
    x.last_radius = safe;
    x.last_step = min(x.omega * safe, min(band, remaining));
    advance(r, x.last_step);
  }
}

// The current room segment of the analytic method, as distances from the ray's point.
struct Segment {
  bool known;
  Exit exit;
  real solids;  // where sphere tracing of the solids starts
};

void move_in_segment(INOUT(Ray) r, INOUT(Segment) seg, real s) {
  advance(r, s);
  seg.exit.s -= s;
  seg.solids = max(seg.solids - s, real(0));
}

// The room segment from the ray's point, unless it is known.
void find_segment(INOUT(Ray) r, INOUT(Segment) seg) {
  if (!seg.known) {
    seg.exit = exit_edge(r.polygon, vec2(r.o), vec2(r.d));
    seg.solids = has(kFeatureObjects) ? solid_entry(r.polygon, r.o, r.d) : real(kFar);
    seg.known = true;
  }
}

// Whether the known segment reaches a solid's bounding sphere before it ends (the end of the
// room, of the band or of max_distance).
bool near_solid(Ray r, Segment seg) {
  return has(kFeatureObjects) && seg.known &&
         seg.solids <
             min(min(seg.exit.s, band_exit(params.top, r.o.z, r.d.z)), params.max_distance - r.t);
}

// The rest of the room segment: the ray leaves the band, ends, or crosses the exit edge.
void segment_step(INOUT(Ray) r, INOUT(Segment) seg) {
  real remaining = params.max_distance - r.t;
  real band = band_exit(params.top, r.o.z, r.d.z);
  if (remaining < min(seg.exit.s, band)) {
    finish(r, kHitMaxDistance, kEventMaxDistance, -1, remaining);
  } else if (band <= seg.exit.s) {
    leave_band(r, band);
    seg.known = false;
  } else if (seg.exit.edge < 0 || seg.exit.corner) {
    finish(r, kHitVertex, kEventVertex, -1, seg.exit.edge < 0 ? real(0) : seg.exit.s);
  } else if (is_wall(r.polygon, seg.exit.edge)) {
    hit_wall(r, seg.exit.edge, seg.exit.s);
  } else {
    advance(r, seg.exit.s);
    cross_edge(r, seg.exit.edge, real(0));
    seg.known = false;
  }
}

// One iteration of the analytic method: a step of sphere tracing towards a solid, or the whole
// rest of the room segment.
void analytic_step(INOUT(Ray) r, INOUT(Segment) seg) {
  find_segment(r, seg);
  bool whole = true;  // the step takes the rest of the segment
  if (near_solid(r, seg)) {
    move_in_segment(r, seg, seg.solids);  // nothing to meet before the first bounding sphere
    SolidDistance solid = nearest_solid(r.polygon, r.o);
    if (solid.d < params.eps) {
      hit_solid(r, solid.object);
      whole = false;
    } else if (solid.d < min(min(seg.exit.s, band_exit(params.top, r.o.z, r.d.z)),
                             params.max_distance - r.t)) {
      move_in_segment(r, seg, solid.d);
      whole = false;
    }
  }
  if (whole) segment_step(r, seg);
}

// ---- A whole ray -----------------------------------------------------------------------------

// A ray from outside the band sees the rooms laid out as their coordinates place them: it enters
// the first polygon whose footprint it crosses at the band's top (or bottom).
void enter_band(INOUT(Ray) r) {
  bool above = r.o.z > params.height;
  real s = band_entry(params.height, r.o.z, r.d.z, params.max_distance);
  vec3 q = r.o + s * r.d;
  int entered = -1;  // the first polygon whose footprint q is in
  if (s < params.max_distance) {
    for (int k = params.polygon_count - 1; k >= 0; --k) {
      if (inside_polygon(k, vec2(q))) entered = k;
    }
  }
  if (entered >= 0) {
    r.polygon = entered;
    if (!above && has(kFeatureFloor)) {  // the underside of the floor
      finish(r, kHitFloor, kEventFloor, -1, s);
      r.normal = vec3(real(0), real(0), real(-1));
    } else {
      advance(r, s);
      record_event(kEventEnter, entered, -1, -1, -1, -1, r.t, r.o);
    }
    return;
  }
  advance(r, s);
  r.hit = kHitMiss;
  r.done = true;
  record_event(kEventMiss, -1, -1, -1, -1, -1, r.t, r.o);
}

// Follows a ray from `from` (in the coordinates of `polygon` when within the band) along `dir`.
Ray march(int polygon, vec3 from, vec3 dir) {
  Ray r;
  r.polygon = polygon;
  r.o = from;
  r.d = normalize(dir);
  r.t = real(0);
  r.steps = 0;
  r.crossings = 0;
  r.hit = kHitMaxSteps;
  r.done = false;
  r.object = -1;
  r.normal = vec3(real(0));
  r.surface = vec3(real(0));
  r.light = vec3(real(0));
  r.clear = real(1);
  if (has(kFeaturePeriod)) {
    r.o.z = mod(r.o.z, params.top);
  }
#ifndef FLATMARCH_FROM_BAND
  else if (r.o.z < real(0) || r.o.z > params.height) {
    enter_band(r);
  }
#endif
  Relaxation x;
  relax(x);
  Segment seg;
  seg.known = false;
  seg.exit.s = real(kFar);
  seg.exit.edge = -1;
  seg.exit.corner = false;
  seg.solids = real(kFar);
#ifdef FLATMARCH_GPU_SHAPE
  // A GPU's shader core leaves a loop once none of its lanes is left in it, and skips a branch
  // that none of them takes: one loop, testing first, the solids only in the steps near them
  // (analytic_step). The same steps in the same order as the software shape's loops below.
  while (!r.done && r.steps < params.max_steps) {
    r.steps += 1;
    if (params.method == kMethodAnalytic) {
      analytic_step(r, seg);
    } else {
      sphere_step(r, x);
    }
  }
#else
  // The software shape's loops test at their end (do-while), and every step is one iteration: a
  // software rasteriser's shader core runs a loop's body, masked, until no lane is left in it,
  // and a test at the top costs a whole masked pass more.
  if (params.max_steps > 0 && !r.done) {
    if (params.method == kMethodAnalytic && has(kFeatureObjects)) {
      // The analytic method's steps, in two loops: the steps that take a whole room segment, as
      // long as no solid is near, then the steps near solids, and again. The same steps in the
      // same order as analytic_step's loop, but the solids' distances are evaluated only in the
      // second loop, which most rays never enter or enter once.
      do {
        bool near = false;
        do {
          find_segment(r, seg);
          near = near_solid(r, seg);
          if (!near) {
            r.steps += 1;
            segment_step(r, seg);
          }
        } while (!r.done && r.steps < params.max_steps && !near);
        if (!r.done && r.steps < params.max_steps) {
          do {
            r.steps += 1;
            analytic_step(r, seg);
          } while (!r.done && r.steps < params.max_steps && near_solid(r, seg));
        }
      } while (!r.done && r.steps < params.max_steps);
    } else {
      do {
        r.steps += 1;
        if (params.method == kMethodAnalytic) {
          analytic_step(r, seg);
        } else {
          sphere_step(r, x);
        }
      } while (!r.done && r.steps < params.max_steps);
    }
  }
#endif
  if (!r.done) finish(r, kHitMaxSteps, kEventMaxSteps, -1, real(0));
  if (has(kFeatureObjects) && r.object >= 0) solid_look(r);
  return r;
}

// ---- Appearance (DESIGN.md section 1) --------------------------------------------------------

// The colour of a finished ray, linear and tone-mapped: its surface, lit and faded by distance
// into the fog, seen through the walls it crossed; the sky or the ground where it left the band
// or missed the rooms; the fog at the distance it reached where it failed (max_steps,
// max_distance, vertex: no black specks; the hit AOV keeps the failure).
vec3 shade(Ray r) {
  vec3 fog = vec3(params.fog);
  vec3 surface = fog;
  if (r.hit >= 0) {
    surface = lit(r.surface, r.normal);
  } else if (r.hit == kHitWall) {
    surface = lit(vec3(params.wall), r.normal);
  } else if (r.hit == kHitFloor) {
    surface = lit(floor_tone(vec2(r.o), r.t, r.d.z) * vec3(params.floor_colour), r.normal);
  }
  if (r.hit >= 0 || r.hit == kHitWall || r.hit == kHitFloor) {
    surface = fogged(surface, fog, r.t, params.fog_distance);
  } else if (r.hit == kHitEscape || r.hit == kHitMiss) {
    surface = sky_colour(fog, vec3(params.sky), vec3(params.ground), r.d.z);
  }
  return tone_map(r.light + r.clear * surface);
}
