// The kernel's per-lane maths: what march.glsl computes for one ray from numbers it has already
// read, with no table reads, loops or branches on the ray's values. Written once and compiled
// three ways:
//   GLSL           real is float, lane_bool is bool (kernels/shader_prelude.glsl);
//   C++ with GLM   inside Kernel<real> (kernels/kernel.hpp, kernels/glsl.hpp), for the scalar
//                  backend in float and double;
//   Highway        real, vec2, vec3, vec4 and lane_bool are vectors of lanes, one ray per lane
//                  (backends/simd/maths-inl.h), for the SIMD backend.
// So the SIMD backend takes the scalar backend's steps by construction: the same operations in
// the same order. A choice that depends on the ray is select(c, a, b): a ternary in GLSL and C++,
// a blend of lanes on packets (both sides are computed; they must be safe to compute, and a
// division by zero or a square root of a negative number is, its lane discarded). A choice on
// a value that is the same for every lane of a packet (a solid's kind) may be an `if`.
//
// The room step's maths is here too (an edge's distance and crossing test, the exit parameters,
// the band exit, a solid's distance and bounding sphere): march.glsl and the SIMD backend read
// the tables their own way (one room per ray; broadcasts or lookups per packet) and hand the
// numbers to these. KINLINE marks each function to be inlined where the compiler would not on
// its own (on packets: each is a handful of vector operations, and a call would pass its vectors
// through memory).

// The camera's unit ray through the image point (x, y), in pixels from the top left corner of an
// image `size` pixels wide and high (DESIGN.md section 2): forward, right and up are the camera's
// basis, tan_half_fov the tangent of half its vertical field of view, aspect width / height.
KINLINE vec3 camera_ray(vec3 forward, vec3 right, vec3 up, real tan_half_fov, real aspect,
                        vec2 at, vec2 size) {
  real u = (real(2) * at.x / size.x - real(1)) * aspect * tan_half_fov;
  real v = (real(1) - real(2) * at.y / size.y) * tan_half_fov;
  return normalize(forward + u * right + v * up);
}

// Moves p along the normal of an edge's line so that it lies `inside` within it (negative:
// beyond it). line: the unit normal (x, y) and offset (z) of the edge's line.
KINLINE vec2 place(vec2 p, vec4 line, real inside) {
  vec2 n = vec2(line.x, line.y);
  return p - (dot(p, n) - line.z + inside) * n;
}

// A direction d reflected by a mirror along the line `line` (unit normal x, y).
KINLINE vec2 mirror_direction(vec2 d, vec4 line) {
  vec2 n = vec2(line.x, line.y);
  return d - real(2) * dot(d, n) * n;
}

// A gluing's map (DESIGN.md section 1) applied to a point: the linear part m (columns (x, y) and
// (z, w)), then the shift (x, y).
KINLINE vec2 glue_point(vec4 m, vec4 shift, vec2 p) {
  return vec2(m.x * p.x + m.z * p.y, m.y * p.x + m.w * p.y) + vec2(shift.x, shift.y);
}

// ... and to a direction: the linear part only.
KINLINE vec2 glue_direction(vec4 m, vec2 d) {
  return vec2(m.x * d.x + m.z * d.y, m.y * d.x + m.w * d.y);
}

// Signed distance from p to a solid of kind `solid` centred at c, of size `shape` (the paper's
// SDFs; kernels/tables.glsl's ObjectRecord says what shape holds per kind).
KINLINE real solid_sdf(int solid, vec3 c, vec4 shape, vec3 p) {
  vec3 q = p - c;
  if (solid == kSolidSphere) return length(q) - shape.x;
  if (solid == kSolidCylinder) {
    vec2 w = vec2(length(vec2(q)) - shape.x, abs(q.z) - shape.y);
    return min(max(w.x, w.y), real(0)) + length(max(w, vec2(real(0))));
  }
  vec3 w = abs(q) - vec3(shape);
  real box = length(max(w, vec3(real(0)))) + min(max(w.x, max(w.y, w.z)), real(0));
  if (solid == kSolidBox) return box;
  return max(box, shape.w - length(q));  // hollow cube: the cube minus the sphere
}

// +1 or -1 as x is not negative or is.
KINLINE real sign_of(real x) {
  return select(x < real(0), real(-1), real(1));
}

// The outward unit normal at p of a box of half-extents `size` centred at the origin (p = q): its
// face's where one of q's coordinates is beyond the box (or where q is inside, the nearest face's),
// the gradient of the distance to its edge or corner where two or three are.
KINLINE vec3 box_normal(vec3 q, vec3 size) {
  vec3 w = abs(q) - size;
  vec3 past = max(w, vec3(real(0)));
  vec3 s = vec3(sign_of(q.x), sign_of(q.y), sign_of(q.z));
  vec3 beyond = normalize(vec3(s.x * past.x, s.y * past.y, s.z * past.z));
  vec3 face = select(w.x >= w.y && w.x >= w.z, vec3(s.x, real(0), real(0)),
                     select(w.y >= w.z, vec3(real(0), s.y, real(0)), vec3(real(0), real(0), s.z)));
  return select(w.x > real(0) || w.y > real(0) || w.z > real(0), beyond, face);
}

// The solid's outward unit normal at p from its own formula (solid_sdf's): the gradient of the
// term of its distance that is active at p. A sphere's radius; a cylinder's side, cap or rim; a
// box's face, edge or corner; a hollow cube's box, or its hollow. No finite differences: a point
// near a crease takes the normal of its side, as the oracle's does.
KINLINE vec3 solid_normal_at(int solid, vec3 c, vec4 shape, vec3 p) {
  vec3 q = p - c;
  if (solid == kSolidSphere) return normalize(q);
  if (solid == kSolidCylinder) {
    real rho = length(vec2(q));
    vec2 w = vec2(rho - shape.x, abs(q.z) - shape.y);
    vec3 side = normalize(vec3(q.x, q.y, real(0)));
    vec3 cap = vec3(real(0), real(0), sign_of(q.z));
    vec3 rim = normalize(vec3(w.x * side.x, w.x * side.y, w.y * cap.z));
    return select(w.x > real(0) && w.y > real(0), rim, select(w.x > w.y, side, cap));
  }
  vec3 box = box_normal(q, vec3(shape));
  if (solid == kSolidBox) return box;
  // The hollow cube: the box where its distance is the larger term, else the hollow's sphere,
  // whose normal points into the hollow.
  vec3 w = abs(q) - vec3(shape);
  real box_distance = length(max(w, vec3(real(0)))) + min(max(w.x, max(w.y, w.z)), real(0));
  return select(box_distance >= shape.w - length(q), box, real(-1) * normalize(q));
}

// A solid's own colour when it has one (w > 0), else its normal's (DESIGN.md section 1).
KINLINE vec3 solid_surface(vec4 color, vec3 normal) {
  return select(color.w > real(0), vec3(color), real(0.5) + real(0.5) * normal);
}

// ---- A room's step ---------------------------------------------------------------------------

// The square of the distance from a point to the edge from a to a + ab: ap is the point less a,
// w is 1 / |ab|^2 (the edge table's line.w).
KINLINE real segment_distance2(vec2 ap, vec2 ab, real w) {
  real h = clamp(dot(ap, ab) * w, real(0), real(1));
  vec2 q = ap - h * ab;
  return dot(q, q);
}

// Whether the horizontal ray from a point at height py in +x crosses the edge from a to a + ab,
// whose ends are at heights ay and by (= ay + ab.y), ap being the point less a: the crossing
// number's test, which counts the edge's lower end and not its upper one.
KINLINE lane_bool crosses(real py, real ay, real by, vec2 ap, vec2 ab) {
  lane_bool over_a = py >= ay;
  lane_bool under_b = py < by;
  lane_bool left = ab.x * ap.y > ab.y * ap.x;
  return (over_a && under_b && left) || !(over_a || under_b || left);
}

// How far the point p lies inside the line of unit outward normal n (x, y) and offset c (z):
// negative beyond it.
KINLINE real line_gap(vec2 p, vec4 line) {
  return line.z - dot(p, vec2(line.x, line.y));
}

// How far a ray from o along dh goes to meet a line (unit normal n, offset c) that it moves
// towards, dn = dot(dh, n) > 0 (dh's length makes this a 3D distance).
KINLINE real line_distance(vec2 o, vec2 n, real c, real dn) {
  return (c - dot(o, n)) / dn;
}

// Where the point p lies along the edge from a to a + ab: 0 at a, 1 at the other end (w as in
// segment_distance2).
KINLINE real edge_parameter(vec2 p, vec2 a, vec2 ab, real w) {
  return dot(p - a, ab) * w;
}

// Whether the parameter u lies in [low, high].
KINLINE lane_bool on_edge_within(real u, real low, real high) {
  return u >= low && u <= high;
}

// Whether the parameter u is on its edge, to within `tolerance` of its ends. (The SIMD backend
// reads 1 + tolerance from a table, worked out once per edge, and calls on_edge_within.)
KINLINE lane_bool on_edge(real u, real tolerance) {
  return on_edge_within(u, -tolerance, real(1) + tolerance);
}

// Whether the parameter u is within `tolerance` of an end of its edge: the ray leaves by a vertex.
KINLINE lane_bool near_end(real u, real tolerance) {
  return u <= tolerance || u >= real(1) - tolerance;
}

// How far a ray at height z, rising dz per unit of its length, goes to leave the band [0, top];
// kFar if it runs level.
KINLINE real band_exit(real top, real z, real dz) {
  real s = select(dz > real(0), top - z, -z) / dz;
  return select(dz > real(0), s, select(dz < real(0), s, real(kFar)));
}

// How far a ray at height z, rising dz per unit of its length, from outside the band [0, height]
// goes to reach it; max_distance if it moves away from it or cannot reach it by then.
KINLINE real band_entry(real height, real z, real dz, real max_distance) {
  lane_bool above = z > height;
  lane_bool toward = select(above, dz < real(0), dz > real(0));
  real s = select(toward, (select(above, height, real(0)) - z) / dz, max_distance);
  return select(s > max_distance, max_distance, s);
}

// How far a ray from o along the unit d goes to come within `radius` of a point c (oc = o - c):
// 0 if it is already, kFar if it never does ahead of o.
KINLINE real sphere_entry(vec3 oc, vec3 d, real radius) {
  real b = dot(oc, d);
  real cc = dot(oc, oc) - radius * radius;
  real disc = b * b - cc;
  // (The root of a negative disc is never kept, but one taken in C++ calls the library to set
  // errno: 20% of the scalar analytic frame.)
  real ahead = select(b < real(0) && disc >= real(0), -b - sqrt(max(disc, real(0))), real(kFar));
  return select(cc <= real(0), real(0), ahead);
}

// ---- Appearance (DESIGN.md section 1) ----------------------------------------------------------

// The opacity of a glued wall or mirror whose opacity at normal incidence is `base`, crossed by a
// ray whose unit direction has the component `cosine` along the wall's normal: it grows towards
// four times `base` at grazing incidence, so that wall planes seen edge-on read as glass.
KINLINE real wall_opacity(real base, real cosine) {
  real grazing = real(1) - abs(cosine);
  return min(base * (real(1) + real(3) * grazing * grazing), real(1));
}

// The light a ray has gathered from the walls it crossed, `clear` being the share of light the
// walls before let through, after a wall of opacity a and colour `colour`: it mixes a of its
// colour into what passes. (The share after it is clear * (1 - a).)
KINLINE vec3 tint_light(vec3 light, real clear, real a, vec3 colour) {
  return light + (clear * a) * colour;
}

// A surface of colour c and unit normal n lit by a light from above and ambient light, so that
// walls facing different ways differ and no side is black.
KINLINE vec3 lit(vec3 c, vec3 n) {
  vec3 light = vec3(real(kLightX), real(kLightY), real(kLightZ));
  return (real(kAmbient) + real(1.0f - kAmbient) * max(dot(n, light), real(0))) * c;
}

// A surface's colour at path length t, faded towards the fog: half fog at `fog_distance`.
KINLINE vec3 fogged(vec3 surface, vec3 fog, real t, real fog_distance) {
  real f = t / (t + fog_distance);
  return surface + f * (fog - surface);
}

// Which seam a ray crossing a glued wall or a mirror at p passes (DESIGN.md section 1,
// Appearance): 2 where p lies within half_width of the wall's vertical edge at a cone point, 1
// within it of one at another corner or of the wall's bottom or top (z = 0, top), else 0. line:
// the edge's (its outward unit normal n in x, y); seam: the edge table's (where its ends lie along
// (-n.y, n.x), and what they are).
KINLINE real seam_kind(vec3 p, vec4 line, vec4 seam, real half_width, real top) {
  real u = dot(vec2(p.x, p.y), vec2(-line.y, line.x));  // along the edge, counterclockwise
  real corner = max(select(u - seam.x < half_width, seam.z, real(0)),
                    select(seam.y - u < half_width, seam.w, real(0)));
  return max(corner, select(p.z < half_width || p.z > top - half_width, real(1), real(0)));
}

// The opacity of a seam of kind `kind` (seam_kind): seams.y, at a cone point seams.z, none at 0.
KINLINE real seam_opacity(real kind, vec4 seams) {
  return select(kind > real(0.5f), select(kind > real(1.5f), seams.z, seams.y), real(0));
}

// ... and its colour: `cone` at a cone point, else `seam`.
KINLINE vec3 seam_colour(real kind, vec4 seam, vec4 cone) {
  return select(kind > real(1.5f), vec3(cone), vec3(seam));
}

// What a ray that leaves the band or misses every room sees, by the height dz of its unit
// direction: the fog at the horizon, growing towards the sky straight up and the ground
// straight down.
KINLINE vec3 sky_colour(vec3 fog, vec3 sky, vec3 ground, real dz) {
  real k = sqrt(abs(dz));
  return fog + k * (select(dz >= real(0), sky, ground) - fog);
}

// The floor's tone at p, reached at path length t by a ray whose unit direction falls dz per
// unit: checks kFloorCheck wide, 1 and kFloorDark (DESIGN.md section 1), their contrast fading
// towards their mean as a pixel's footprint on the floor grows, about t / |dz| times its angle
// (to half at t / |dz| = kFloorFade), so that checks smaller than a pixel near the horizon (an
// infinite floor runs to it) blur rather than alias into moire, while a floor seen from above
// keeps its checks.
KINLINE real floor_tone(vec2 p, real t, real dz) {
  real check = floor(p.x / real(kFloorCheck)) + floor(p.y / real(kFloorCheck));
  real tone = select(mod(check, real(2)) >= real(1), real(kFloorDark), real(1));
  real mean = real(0.5f) * (real(1) + real(kFloorDark));
  real far = t / (max(abs(dz), real(1e-6f)) * real(kFloorFade));
  return mean + (tone - mean) / (real(1) + far * far);
}

// Linear light brought into [0, 1] for display before sRGB encoding: a filmic curve (Narkowicz's
// fit of ACES, after an exposure of kExposure) that leaves the middle tones about where they are
// and rolls highlights off.
KINLINE real tone_curve(real c) {
  real x = real(kExposure) * c;
  return min(x * (real(2.51f) * x + real(0.03f)) / (x * (real(2.43f) * x + real(0.59f)) + real(0.14f)),
             real(1));
}

KINLINE vec3 tone_map(vec3 c) {
  return vec3(tone_curve(c.x), tone_curve(c.y), tone_curve(c.z));
}

#ifdef FLATMARCH_SHADER
// The sRGB transfer function (IEC 61966-2-1) of a linear colour, clamped to [0, 1]: as OpenImageIO
// encodes the PNGs of `render` (output/image_io.cpp), for the shaders that show or read back
// colour alone (the scene shaders' colour frames and web canvas, the viewer's window). The CPU
// backends leave the encoding to the image writer, so it is compiled as GLSL only.
vec3 srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
#endif
