#include "motion/walk.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace flatmarch::motion {

namespace {

constexpr double kDeg = kPi / 180.0;
// A path that meets the boundary this close to a vertex (relative to scene.scale) meets the
// vertex: there the two edges' gluings disagree and no crossing is defined (DESIGN.md section 3,
// the oracle's `vertex` event).
constexpr double kVertexRadius = 1e-6;
// After a crossing the point is placed this far (relative to scene.scale) inside the edge it came
// in by, as the kernel's cross_edge places it `offset` inside, so that it lies strictly inside.
constexpr double kPush = 1e-9;

double wrap_yaw(double yaw_deg) {
  return std::remainder(yaw_deg, 360.0);  // exact, in [-180, 180]
}

bool finite(Vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

void check_camera(const Scene& scene, const Camera& camera) {
  if (camera.polygon < 0 || camera.polygon >= static_cast<int>(scene.polygons.size()))
    throw std::invalid_argument("walk: the camera's polygon " + std::to_string(camera.polygon) +
                                " does not exist (the scene has " +
                                std::to_string(scene.polygons.size()) + ")");
  if (!finite(camera.position) || !std::isfinite(camera.yaw_deg) ||
      !std::isfinite(camera.pitch_deg))
    throw std::invalid_argument("walk: the camera's position or angles are not finite");
  const Vec3 p = camera.position;
  if (scene.in_band(p.z) &&
      !scene.polygons[static_cast<size_t>(camera.polygon)].contains(Vec2(p))) {
    std::ostringstream s;
    s << "walk: the camera at (" << p.x << ", " << p.y << ", " << p.z
      << ") is within the wall band but not strictly inside polygon " << camera.polygon;
    throw std::invalid_argument(s.str());
  }
}

// The yaw after a gluing's linear part. A conformal map (translation, rotation, similarity) adds
// its angle; a reflection mirrors the yaw about its axis; any other affine map turns it to where
// it sends the forward direction.
double turned_yaw(const Gluing& gluing, const Mat2& linear, double yaw_deg) {
  const double angle = std::atan2(linear[0].y, linear[0].x) / kDeg;  // the image of (1, 0)
  switch (gluing.type) {
    case GluingType::reflection:
      return wrap_yaw(angle - yaw_deg);
    case GluingType::affine: {
      const Vec2 f = linear * Vec2(std::cos(yaw_deg * kDeg), std::sin(yaw_deg * kDeg));
      return std::atan2(f.y, f.x) / kDeg;
    }
    default:
      return wrap_yaw(yaw_deg + angle);
  }
}

// The horizontal walk by `d` inside the band: one room segment per iteration.
void walk_rooms(const Scene& scene, Vec2 d, WalkResult& result) {
  Camera& camera = result.camera;
  Vec2 o(camera.position);
  const double vertex_radius = kVertexRadius * scene.scale;
  for (int segment = 0; d != Vec2(0.0); ++segment) {
    if (segment == kMaxSegments) {
      result.blocked = true;
      break;
    }
    const Polygon& polygon = scene.polygons[static_cast<size_t>(camera.polygon)];
    if (const double reach = kWalkReach * scene.scale;
        polygon.infinite() && glm::length(o) + glm::length(d) > reach) {
      // No further than kWalkReach from the origin (the triangle inequality keeps o + d within).
      d *= std::max(reach - glm::length(o), 0.0) / glm::length(d);
      result.blocked = true;
      if (d == Vec2(0.0)) break;
    }
    // Where the path o + s d, s in [0, 1], first leaves the room.
    const Polygon::Exit exit =
        polygon.exit(o, d, vertex_radius, vertex_radius / glm::length(d), 1.0);
    if (exit.edge < 0) {
      // The path ends in this room; an end on the boundary by rounding is not taken.
      if (polygon.contains(o + d))
        o += d;
      else
        result.blocked = true;
      break;
    }
    const Edge& edge = polygon.edges[static_cast<size_t>(exit.edge)];
    const Vec2 at = o + exit.s * d;
    // Near a vertex (a ray's finite end; no walk reaches a point at infinity).
    const double to_vertex =
        std::min(glm::length(at - edge.start),
                 edge.ray() ? std::numeric_limits<double>::infinity()
                            : glm::length(at - (edge.start + edge.length * edge.along)));
    if (to_vertex <= vertex_radius) {
      o += std::max(exit.s - kWalkMargin / glm::length(d), 0.0) * d;
      result.blocked = true;
      break;
    }
    if (edge.kind != EdgeKind::glued) {
      // Stop kWalkMargin short of the mirror or wall (measured across it) and slide along it
      // with the rest of the path.
      const double s = std::max(exit.s - kWalkMargin / glm::dot(d, edge.normal), 0.0);
      o += s * d;
      const Vec2 rest = (1.0 - s) * d;
      d = rest - glm::dot(rest, edge.normal) * edge.normal;
      result.blocked = true;
      continue;
    }
    const Polygon& to = scene.polygons[static_cast<size_t>(edge.to.polygon)];
    const Edge& entry = to.edges[static_cast<size_t>(edge.to.edge)];
    const Vec2 p = edge.map.apply(at);
    o = p - (glm::dot(p - entry.start, entry.normal) + kPush * scene.scale) * entry.normal;
    d = edge.map.apply_direction((1.0 - exit.s) * d);
    camera.yaw_deg = turned_yaw(scene.gluings[static_cast<size_t>(edge.gluing)], edge.map.linear,
                                camera.yaw_deg);
    camera.polygon = edge.to.polygon;
    ++result.crossings;
  }
  camera.position.x = o.x;
  camera.position.y = o.y;
}

// z after moving within the band: kept inside it, or modulo the period of a translation prism.
double band_z(const Scene& scene, double z) {
  if (scene.period) return z - *scene.period * std::floor(z / *scene.period);
  const double margin = std::min(kWalkMargin, 0.25 * scene.height);
  return std::clamp(z, margin, scene.height - margin);
}

// A camera outside the band moves freely over the plan and enters the room under it (the first
// polygon that holds it, as rays enter, DESIGN.md section 1) when it comes into the band.
void fly(const Scene& scene, Vec2 d, double up, WalkResult& result) {
  Camera& camera = result.camera;
  Vec3& x = camera.position;
  const bool above = x.z > scene.height;
  x += Vec3(d, up);
  if (above ? x.z > scene.height : x.z < 0.0) return;
  if (above || !scene.floor)
    for (size_t k = 0; k < scene.polygons.size(); ++k)
      if (scene.polygons[k].contains(Vec2(x), kWalkMargin)) {
        camera.polygon = static_cast<int>(k);
        x.z = band_z(scene, x.z);
        return;
      }
  // Over no room (or under the floor): stay out of the band.
  x.z = above ? scene.height + kWalkMargin : -kWalkMargin;
}

}  // namespace

WalkResult walk(const Scene& scene, const Camera& camera, double forward, double right, double up) {
  check_camera(scene, camera);
  if (!std::isfinite(forward) || !std::isfinite(right) || !std::isfinite(up))
    throw std::invalid_argument("walk: the displacement is not finite");
  WalkResult result{camera};
  const double a = camera.yaw_deg * kDeg;
  const Vec2 d = forward * Vec2(std::cos(a), std::sin(a)) + right * Vec2(std::sin(a), -std::cos(a));
  if (scene.in_band(camera.position.z)) {
    walk_rooms(scene, d, result);
    result.camera.position.z = band_z(scene, camera.position.z + up);
  } else {
    fly(scene, d, up, result);
  }
  return result;
}

Camera look(const Camera& camera, double dyaw_deg, double dpitch_deg) {
  if (!std::isfinite(camera.yaw_deg + dyaw_deg) || !std::isfinite(camera.pitch_deg + dpitch_deg))
    throw std::invalid_argument("look: the camera's angles or their changes are not finite");
  Camera turned = camera;
  turned.yaw_deg = wrap_yaw(camera.yaw_deg + dyaw_deg);
  turned.pitch_deg = std::clamp(camera.pitch_deg + dpitch_deg, -kMaxPitchDeg, kMaxPitchDeg);
  return turned;
}

}  // namespace flatmarch::motion
