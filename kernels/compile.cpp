#include "kernels/compile.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace flatmarch::kernel {

namespace {

bool is_isometry(const Affine2& map) {
  const Mat2 gram = glm::transpose(map.linear) * map.linear;
  constexpr double kTolerance = 1e-12;
  return std::abs(gram[0][0] - 1.0) <= kTolerance && std::abs(gram[1][1] - 1.0) <= kTolerance &&
         std::abs(gram[0][1]) <= kTolerance;
}

int kernel_method(Method m) {
  switch (m) {
    case Method::sphere:
      return kMethodSphere;
    case Method::relaxed:
      return kMethodRelaxed;
    case Method::analytic:
      return kMethodAnalytic;
    case Method::oracle:
      break;
  }
  return -1;
}

template <typename real>
typename Tables<real>::ObjectRecord object_record(const Object& o, int hit_index) {
  using vec4 = typename Types<real>::vec4;
  typename Tables<real>::ObjectRecord r{};
  double bound = 0.0;
  switch (o.type) {
    case ObjectType::sphere:
      r.info.x = kSolidSphere;
      r.shape = vec4(real(o.radius), 0, 0, 0);
      bound = o.radius;
      break;
    case ObjectType::box:
      r.info.x = kSolidBox;
      r.shape = vec4(glm::vec<3, real>(o.half), 0);
      bound = glm::length(o.half);
      break;
    case ObjectType::hollow_cube:
      r.info.x = kSolidHollowCube;
      r.shape = vec4(real(o.size), real(o.size), real(o.size), real(o.hole));
      bound = std::sqrt(3.0) * o.size;
      break;
    case ObjectType::cylinder: {
      const double half_height = 0.5 * (o.z1 - o.z0);
      r.info.x = kSolidCylinder;
      r.shape = vec4(real(o.radius), real(half_height), 0, 0);
      bound = std::hypot(o.radius, half_height);
      break;
    }
  }
  r.center = vec4(glm::vec<3, real>(o.center), real(bound));
  if (o.color) r.color = vec4(glm::vec<3, real>(*o.color), 1);
  r.info.y = hit_index;
  return r;
}

// Whether every room's outline, as its edges' segments run, is convex: each edge starts where
// the one before it ends and turns left of it or runs straight on (a simple counterclockwise
// polygon that never turns right is convex; DESIGN.md makes polygons simple).
template <typename real>
bool convex_rooms(const SceneTables<real>& t) {
  for (const ivec4& poly : t.polygons)
    for (int k = 0; k < poly.y; ++k) {
      const auto& s = t.edges[static_cast<size_t>(poly.x + k)].segment;
      const auto& next = t.edges[static_cast<size_t>(poly.x + (k + 1) % poly.y)].segment;
      const Vec2 ab(double(s.z) - double(s.x), double(s.w) - double(s.y));
      const Vec2 bc(double(next.z) - double(next.x), double(next.w) - double(next.y));
      if (next.x != s.z || next.y != s.w || ab.x * bc.y - ab.y * bc.x < 0.0) return false;
    }
  return true;
}

}  // namespace

uint scene_features(const Scene& scene) {
  uint f = 0;
  if (!scene.objects.empty() || !scene.markers.empty()) f |= kFeatureObjects;
  for (const Polygon& polygon : scene.polygons)
    for (const Edge& edge : polygon.edges) {
      if (edge.kind == EdgeKind::mirror) f |= kFeatureMirrors;
      if (edge.kind == EdgeKind::wall) f |= kFeatureWalls;
      if (edge.kind == EdgeKind::glued && !is_isometry(edge.map)) f |= kFeatureScaled;
    }
  if (scene.period) f |= kFeaturePeriod;
  if (scene.floor) f |= kFeatureFloor;
  return f;
}

template <typename real>
SceneTables<real> compile_scene(const Scene& scene, const MarchParams& march) {
  using vec4 = typename Types<real>::vec4;
  SceneTables<real> t;
  t.features = scene_features(scene);
  const double top = scene.period ? *scene.period : scene.height;

  for (size_t p = 0; p < scene.polygons.size(); ++p) {
    const Polygon& polygon = scene.polygons[p];
    const int first_edge = static_cast<int>(t.edges.size());
    const int first_object = static_cast<int>(t.objects.size());
    // An unbounded polygon's room is its outline cut off kFarRadius out (Polygon::outline):
    // a ray edge runs from its finite end to its far point, the edge at infinity is the first
    // link of the chain of far points, and the chain's other links follow the polygon's edges.
    // No ray gets near the far points (check_reach), so within its reach a ray edge is the
    // half-line exactly and the edge at infinity nothing at all, and the kernel is the one
    // finite scenes run.
    const std::vector<Vec2> far = polygon.far_points(kFarRadius);
    std::vector<std::pair<Vec2, Vec2>> chain;
    for (size_t k = 0; k + 1 < far.size(); ++k) chain.push_back({far[k], far[k + 1]});
    // An edge's segment from a to b and its line, of outward unit normal `normal`.
    const auto record = [&](Vec2 a, Vec2 b, Vec2 normal) {
      typename Tables<real>::EdgeRecord r{};
      r.segment = vec4(real(a.x), real(a.y), real(b.x), real(b.y));
      r.line = vec4(real(normal.x), real(normal.y), real(glm::dot(normal, a)),
                    real(1.0 / glm::dot(b - a, b - a)));
      return r;
    };
    const auto far_link = [&](Vec2 a, Vec2 b) {
      // Outward: the room lies on the left. Never reached: nothing to cross, no wall feature.
      auto r = record(a, b, -glm::normalize(perp(b - a)));
      r.link.x = kEdgeWall;
      return r;
    };
    size_t next_link = 0;
    for (int i = 0; i < polygon.size(); ++i) {
      const Edge& edge = polygon.edges[static_cast<size_t>(i)];
      if (edge.shape == EdgeShape::at_infinity) {
        const auto [a, b] = chain[next_link++];
        t.edges.push_back(far_link(a, b));
        continue;
      }
      Vec2 a = polygon.vertex(i), b = polygon.vertex(i + 1);
      if (edge.shape == EdgeShape::ray_out) a = edge.start, b = far.front();
      if (edge.shape == EdgeShape::ray_in) a = edge.start, b = far.back();
      auto r = record(a, b, edge.normal);
      r.link.x = edge.kind == EdgeKind::glued    ? kEdgeGlued
                 : edge.kind == EdgeKind::mirror ? kEdgeMirror
                                                 : kEdgeWall;
      if (edge.kind == EdgeKind::glued) {
        const Mat2& m = edge.map.linear;
        r.map_linear = vec4(real(m[0][0]), real(m[0][1]), real(m[1][0]), real(m[1][1]));
        r.map_shift = vec4(real(edge.map.translation.x), real(edge.map.translation.y), 0, 0);
        r.link.y = edge.to.polygon;
        r.link.z = edge.to.edge;
      }
      r.seam = vec4(seam_record(scene, static_cast<int>(p), i));
      r.tint = vec4(edge_tint(scene.look, edge));
      t.edges.push_back(r);
    }
    for (; next_link < chain.size(); ++next_link) {
      const auto [a, b] = chain[next_link];
      t.edges.push_back(far_link(a, b));
    }
    const int edge_count = static_cast<int>(t.edges.size()) - first_edge;
    // The room's solids: its objects, then a cylinder at each corner that carries a marker.
    for (size_t k = 0; k < scene.objects.size(); ++k)
      if (scene.objects[k].polygon == static_cast<int>(p))
        t.objects.push_back(object_record<real>(scene.objects[k], static_cast<int>(k)));
    for (int v = 0; v < polygon.size(); ++v) {
      const int m = scene.marker_at(static_cast<int>(p), v);
      if (m < 0) continue;
      Object cylinder;
      cylinder.type = ObjectType::cylinder;
      cylinder.center = Vec3(polygon.vertex(v), 0.5 * top);
      cylinder.radius = scene.markers[static_cast<size_t>(m)].radius;
      cylinder.z0 = 0.0;
      cylinder.z1 = top;
      t.objects.push_back(
          object_record<real>(cylinder, static_cast<int>(scene.objects.size()) + m));
    }
    t.polygons.push_back(ivec4(first_edge, edge_count, first_object,
                               static_cast<int>(t.objects.size()) - first_object));
  }

  typename Tables<real>::KernelParams& k = t.params;
  k.method = kernel_method(march.method);
  k.max_steps = march.max_steps;
  k.polygon_count = static_cast<int>(scene.polygons.size());
  // Where every room is convex, a step far from the walls finds its distance to them from
  // the edges' lines alone (march.glsl's wall_distance).
  k.convex = convex_rooms(t) ? 1 : 0;
  k.eps = real(march.eps);
  k.offset = real(march.offset);
  k.max_distance = real(march.max_distance);
  check_reach(scene, march.max_distance, Vec2(scene.camera.position));
  k.omega = real(march.omega);
  k.height = real(scene.height);
  k.top = real(top);
  // Rounding decides which of two edges a ray leaving near their vertex takes: within a few
  // ulps of the scene's scale (never less than the oracle's tolerance) it meets the vertex.
  constexpr double kUlp = std::numeric_limits<real>::epsilon();
  k.vertex_tolerance = real(std::max(kVertexTolerance, 8.0 * kUlp * scene.scale));
  set_look<real>(scene.look, k);
  k.period_tint = vec4(period_tint(scene));
  return t;
}

void check_reach(const Scene& scene, double max_distance, Vec2 camera) {
  if (!scene.topology.infinite) return;
  double reach = glm::length(camera);
  for (const Polygon& polygon : scene.polygons)
    for (int v = 0; v < polygon.size(); ++v)
      if (!polygon.is_ideal(v)) reach = std::max(reach, glm::length(polygon.vertex(v)));
  reach += max_distance;
  if (!(reach <= kReach)) {
    std::ostringstream s;
    s << "an unbounded scene is modelled out to 2^30 (" << kReach
      << ") from its origin, and rays from this camera (or the scene's farthest vertex) run out to "
      << reach << "; lower max_distance";
    throw std::invalid_argument(s.str());
  }
}

glm::dvec4 seam_record(const Scene& scene, int polygon, int edge) {
  const Polygon& room = scene.polygons[static_cast<size_t>(polygon)];
  const Edge& e = room.edges[static_cast<size_t>(edge)];
  if (e.shape == EdgeShape::at_infinity) return glm::dvec4(0.0);
  const Vec2 along(-e.normal.y, e.normal.x);  // counterclockwise, from vertex edge to edge + 1
  // Where a vertex lies along the edge, and what it is: an ideal one, nothing.
  const auto end = [&](int v) -> std::pair<double, double> {
    if (room.is_ideal(v)) return {0.0, 0.0};
    const int c = scene.corner_class[static_cast<size_t>(polygon)][room.wrap(v)];
    const bool cone = c >= 0 && scene.vertex_classes[static_cast<size_t>(c)].singular;
    return {glm::dot(room.vertex(v), along), cone ? 2.0 : 1.0};
  };
  const auto [from, start_mark] = end(edge);
  const auto [to, end_mark] = end(edge + 1);
  return {from, to, start_mark, end_mark};
}

glm::dvec4 edge_tint(const Look& look, const Edge& edge) {
  switch (edge.kind) {
    case EdgeKind::glued:
      return {look.gluing_colour(edge.gluing), look.wall_tint};
    case EdgeKind::mirror:
      return {look.mirror, look.wall_tint};
    case EdgeKind::wall:
    case EdgeKind::infinity:
      break;
  }
  return glm::dvec4(0.0);
}

template <typename real>
void set_look(const Look& look, typename Tables<real>::KernelParams& params) {
  using vec4 = typename Types<real>::vec4;
  const auto colour = [](Vec3 c) { return vec4(glm::vec<3, real>(c), 0); };
  params.fog_distance = real(look.fog_distance);
  params.fog = colour(look.fog);
  params.sky = colour(look.sky);
  params.ground = colour(look.ground);
  params.wall = colour(look.wall);
  params.floor_colour = colour(look.floor);
  const Look::Seams& seams = look.seams;
  params.seams =
      vec4(real(seams.on() ? seams.width : 0.0), real(seams.opacity), real(seams.cone_opacity), 0);
  params.seam_colour = colour(seams.colour);
  params.cone_colour = colour(seams.cone);
}

glm::dvec4 period_tint(const Scene& scene) {
  return {scene.look.gluing_colour(static_cast<int>(scene.gluings.size())), scene.look.wall_tint};
}

template SceneTables<float> compile_scene(const Scene&, const MarchParams&);
template SceneTables<double> compile_scene(const Scene&, const MarchParams&);
template void set_look<float>(const Look&, Tables<float>::KernelParams&);
template void set_look<double>(const Look&, Tables<double>::KernelParams&);

}  // namespace flatmarch::kernel
