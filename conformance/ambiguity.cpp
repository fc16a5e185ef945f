#include "conformance/ambiguity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <tbb/parallel_for.h>

#include "backends/oracle/intersect.hpp"
#include "kernels/camera.hpp"

namespace flatmarch::conformance {

namespace {

// The oracle follows rays much further than a kernel's max_steps would let it (one of its steps
// is a whole room), bounded still.
constexpr int kTruthMaxSteps = 100000;

double unit_roundoff(Precision p) {
  return p == Precision::f32 ? 0x1p-24 : 0x1p-53;
}

// Where object or vertex marker `index` of room `p` (numbered as in the hit AOV) meets the line
// o + s d for s in [0, limit] first, as the oracle intersects them.
std::optional<SolidHit> meet(const Scene& scene, int p, int index, Vec3 o, Vec3 d, double limit) {
  const int objects = static_cast<int>(scene.objects.size());
  if (index < objects)
    return intersect(scene.objects[static_cast<size_t>(index)], o, d, 0.0, limit);
  const Polygon& polygon = scene.polygons[static_cast<size_t>(p)];
  const double top = scene.period ? *scene.period : scene.height;
  std::optional<SolidHit> first;
  for (int v = 0; v < polygon.size(); ++v)
    if (scene.marker_at(p, v) == index - objects)
      if (auto hit = intersect_cylinder(polygon.vertex(v),
                                        scene.markers[static_cast<size_t>(index - objects)].radius,
                                        0.0, top, o, d, 0.0, limit))
        if (!first || hit->t < first->t) first = hit;
  return first;
}

// The objects and markers that can be met in room p, by their hit index.
std::vector<int> solids_in(const Scene& scene, int p) {
  std::vector<int> found;
  for (size_t k = 0; k < scene.objects.size(); ++k)
    if (scene.objects[k].polygon == p) found.push_back(static_cast<int>(k));
  const Polygon& polygon = scene.polygons[static_cast<size_t>(p)];
  for (int v = 0; v < polygon.size(); ++v)
    if (const int m = scene.marker_at(p, v); m >= 0) {
      const int index = static_cast<int>(scene.objects.size()) + m;
      if (std::find(found.begin(), found.end(), index) == found.end()) found.push_back(index);
    }
  return found;
}

// The ambiguity of one room segment of the exact path, at `delta` (grown with the crossings so
// far); `last` and `end` say whether and how the path ends with it, `crease` is the width over
// which the kernel's normal (a finite difference) blurs an edge of a solid.
// How a line o + s d, s in [0, length], passes a solid: how far it clears the solid's bounding
// volume (0 if it enters it), and the sideways shift that takes it through the volume's centre
// (its axis, for a vertex marker's cylinder).
struct Approach {
  double clearance = 0.0;
  Vec3 towards{0.0};
};

Approach approach(const Scene& scene, int p, int index, Vec3 o, Vec3 d, double length) {
  const int objects = static_cast<int>(scene.objects.size());
  Approach best{std::numeric_limits<double>::infinity(), Vec3(0.0)};
  const auto consider = [&](Vec3 centre, double radius, bool vertical) {
    // The closest point of the line (in the plane for a vertical axis) within the segment.
    const Vec3 w = centre - o;
    const Vec3 along = vertical ? Vec3(d.x, d.y, 0.0) : d;
    const double norm = glm::dot(along, along);
    const double s =
        norm > 0.0
            ? std::clamp(glm::dot(vertical ? Vec3(w.x, w.y, 0.0) : w, along) / norm, 0.0, length)
            : 0.0;
    Vec3 off = centre - (o + s * d);
    if (vertical) off.z = 0.0;
    const double clearance = std::max(0.0, glm::length(off) - radius);
    if (clearance < best.clearance) best = {clearance, off};
  };
  if (index < objects) {
    const Object& object = scene.objects[static_cast<size_t>(index)];
    const double h = std::max(object.z_max() - object.center.z, object.center.z - object.z_min());
    consider(object.center, std::hypot(object.footprint_radius(), h), false);
  } else {
    const Polygon& polygon = scene.polygons[static_cast<size_t>(p)];
    for (int v = 0; v < polygon.size(); ++v)
      if (scene.marker_at(p, v) == index - objects)
        consider(Vec3(polygon.vertex(v), 0.0),
                 scene.markers[static_cast<size_t>(index - objects)].radius, true);
  }
  return best;
}

uint8_t segment_ambiguity(const Scene& scene, const PathSegment& seg, bool last, const RayEnd& end,
                          double delta, double eps, double crease) {
  const Polygon& polygon = scene.polygons[static_cast<size_t>(seg.polygon)];
  const Vec2 from(seg.from), to(seg.to);
  const double on = 1e-9 * scene.scale;  // a point this close to an edge lies on it
  if (!scene.in_band(seg.from.z))  // entering from above or below: near the polygon's outline?
    return polygon.distance_to_boundary(to) < delta ? kBandEdge : 0;

  uint8_t bits = 0;
  bool ends_on_edge = false;
  for (int v = 0; v < polygon.size(); ++v) {
    const Edge& edge = polygon.edges[static_cast<size_t>(v)];
    if (!polygon.is_ideal(v) && distance_to_segment(polygon.vertex(v), from, to) < delta)
      bits |= kNearVertex;
    // Two segments (or a segment and a ray) that do not cross come closest at an end of one of
    // them: the edge's ends are the vertices; the path's ends count unless they lie on this
    // edge. Nothing comes near an edge at infinity.
    for (const Vec2 q : {from, to}) {
      const double d = edge.distance(q);
      if (d >= on && d < delta) bits |= kNearEdge;
    }
    ends_on_edge |= edge.distance(to) < on;
  }
  if (!scene.period) {
    const bool at_band = std::abs(seg.to.z) < on || std::abs(seg.to.z - scene.height) < on;
    if (ends_on_edge && (seg.to.z < delta || scene.height - seg.to.z < delta)) bits |= kBandEdge;
    if (at_band && !ends_on_edge && polygon.distance_to_boundary(to) < delta) bits |= kBandEdge;
  }

  const Vec3 step = seg.to - seg.from;
  const double length = glm::length(step);
  if (length == 0.0) return bits;
  const Vec3 d = step / length;
  Vec3 e1 = glm::cross(d, Vec3(0.0, 0.0, 1.0));
  if (glm::length(e1) < 1e-6) e1 = Vec3(1.0, 0.0, 0.0);
  e1 = glm::normalize(e1);
  const Vec3 e2 = glm::cross(d, e1);
  for (const int index : solids_in(scene, seg.polygon)) {
    const bool exact = last && end.hit == index;
    // A shifted line meets a solid where the surface has moved away: further on where the ray
    // hits it, within the room (and delta) where it does not.
    // Every method stops within eps of a solid: a line passing that close counts as a hit.
    const double shifted = delta + eps;
    const double limit = length + shifted + (exact ? scene.scale : 0.0);
    // A solid whose bounding volume the line clears by more than that cannot be grazed.
    const Approach near = approach(scene, seg.polygon, index, seg.from, d, length);
    if (!exact && near.clearance > shifted) continue;
    // Shifts in eight directions 45 degrees apart, half and 1.1 times as far (whichever way the
    // nearest point of the solid lies, one of them moves the line at least `shifted` towards it:
    // cos 22.5 > 1/1.1), and towards the solid's centre, in quarters and right through it, so
    // that a solid smaller than the shift is not jumped over.
    std::vector<Vec3> shifts;
    for (int k = 0; k < 8; ++k) {
      const double a = kPi / 4.0 * k;
      const Vec3 dir = std::cos(a) * e1 + std::sin(a) * e2;
      shifts.push_back(0.55 * shifted * dir);
      shifts.push_back(1.1 * shifted * dir);
    }
    const double gap = glm::length(near.towards);
    if (gap > 0.0) {
      for (const double f : {0.25, 0.5, 0.75, 1.0})
        shifts.push_back(std::min(f * 1.1 * shifted, gap) * near.towards / gap);
      if (gap <= 1.1 * shifted) shifts.push_back(near.towards);
    }
    for (const Vec3& shift : shifts)
      if (meet(scene, seg.polygon, index, seg.from + shift, d, limit).has_value() != exact) {
        bits |= kSilhouette;
        break;
      }
    // At an edge of the solid the normal, and so the colour, jumps: a hit within the kernel's
    // normal step of one is a crease.
    if (!exact || (bits & kSilhouette)) continue;
    // On a smooth surface the normals a shift to either side finds differ from this one by as
    // much; across an edge one side jumps.
    const double reach = std::max(shifted, crease);
    for (const Vec3 axis : {e1, e2}) {
      const auto plus = meet(scene, seg.polygon, index, seg.from + reach * axis, d, limit);
      const auto minus = meet(scene, seg.polygon, index, seg.from - reach * axis, d, limit);
      if (!plus || !minus ||
          std::abs(glm::length(plus->normal - end.normal) -
                   glm::length(minus->normal - end.normal)) > 0.1) {
        bits |= kCrease;
        break;
      }
    }
  }
  return bits;
}

}  // namespace

double ambiguity_delta(const Scene& scene, const MarchParams& params) {
  const double rounding = 16.0 * unit_roundoff(params.precision) * scene.scale;
  if (params.method == Method::analytic) return 2.0 * rounding;  // and the vertex tolerance
  return params.eps + params.offset + rounding;
}

RayTruth ray_truth(const Scene& scene, const Ray& ray, const MarchParams& params, double delta) {
  MarchParams exact;
  exact.method = Method::oracle;
  exact.max_distance = params.max_distance;
  exact.max_steps = kTruthMaxSteps;
  const OracleResult r = oracle_trace(scene, ray, exact, {.record_path = true});
  RayTruth truth{r.end, 0};
  if (r.end.hit == kHitVertex) truth.ambiguity |= kNearVertex;
  const double crease = 1.5 * std::cbrt(unit_roundoff(params.precision)) * scene.scale;
  const double on = 1e-9 * scene.scale;
  // At a crossing the kernel places its point `offset` inside the new room, from wherever within
  // eps of the edge it stopped: the ray moves (eps + offset) sin(angle) sideways, the angle
  // between the ray and the edge's normal. The drifts add up, as they may in the worst case.
  // The analytic method crosses at the exit point it computed, with no push: only rounding.
  const double u = unit_roundoff(params.precision);
  const double push = params.method == Method::analytic ? 0.0 : params.eps + params.offset;
  double drift = delta;
  int crossings = 0;
  for (size_t k = 0; k < r.path.size(); ++k) {
    const PathSegment& seg = r.path[k];
    const bool last = k + 1 == r.path.size();
    truth.ambiguity |= segment_ambiguity(scene, seg, last, r.end, drift, params.eps, crease);
    // The direction is rounded too: the ray turns by about 2^-24, so drifts that much a unit.
    drift += 4.0 * u * glm::length(seg.to - seg.from);
    if (last || !scene.in_band(seg.from.z)) continue;
    const Polygon& polygon = scene.polygons[static_cast<size_t>(seg.polygon)];
    for (int e = 0; e < polygon.size(); ++e)
      if (polygon.edges[static_cast<size_t>(e)].distance(Vec2(seg.to)) < on) {
        const Vec3 step = seg.to - seg.from;
        const double length = glm::length(step);
        const Vec3 n(polygon.edges[static_cast<size_t>(e)].normal, 0.0);
        const double along = length > 0.0 ? glm::dot(n, step) / length : 0.0;
        drift += push * std::sqrt(std::max(0.0, 1.0 - along * along)) + 16.0 * u * scene.scale;
        if (push > 0.0) truth.t_slack += params.eps / std::max(std::abs(along), 1e-3) + push;
        ++crossings;
        break;
      }
  }
  if (!r.path.empty() && (r.end.hit >= 0 || (r.end.hit == kHitWall && push > 0.0))) {
    const Vec3 step = r.path.back().to - r.path.back().from;
    const double length = glm::length(step);
    const double cosine = length > 0.0 ? std::abs(glm::dot(step, r.end.normal)) / length : 1.0;
    truth.t_slack += params.eps / std::max(cosine, 1e-3);
  }
  // t is summed step by step: in float32 it drifts by about 2^-24 of the distance a step. A ray
  // whose end lies that close to max_distance, on either side, may end either way.
  // A solid counts as hit within eps of it, sooner by eps / cos(incidence): 10 eps covers
  // incidences up to 84 degrees.
  const double slack = drift + push * static_cast<double>(crossings) +
                       64.0 * u * params.max_distance + 10.0 * params.eps;
  if (r.end.hit == kHitMaxDistance) {
    exact.max_distance = params.max_distance + slack;
    if (oracle_trace(scene, ray, exact).end.hit != kHitMaxDistance)
      truth.ambiguity |= kNearDistance;
  } else if (r.end.t > params.max_distance - slack) {
    truth.ambiguity |= kNearDistance;
  }
  return truth;
}

size_t FrameTruth::ambiguous() const {
  return static_cast<size_t>(
      std::count_if(ambiguity.begin(), ambiguity.end(), [](uint8_t a) { return a != 0; }));
}

FrameTruth frame_truth(const Scene& scene, const Camera& camera, int width, int height,
                       const MarchParams& params) {
  FrameTruth truth;
  truth.frame = Frame(width, height);
  truth.ambiguity.assign(static_cast<size_t>(width) * static_cast<size_t>(height), 0);
  truth.t_slack.assign(truth.ambiguity.size(), 0.0f);
  truth.unit_roundoff = unit_roundoff(params.precision);
  truth.delta = ambiguity_delta(scene, params);
  const CameraBasis<double> basis =
      camera_basis(camera.yaw_deg, camera.pitch_deg, camera.fov_deg, width, height);
  tbb::parallel_for(0, height, [&](int j) {
    for (int i = 0; i < width; ++i) {
      const Ray ray{camera.polygon, camera.position, camera_ray(basis, i, j, width, height)};
      const RayTruth r = ray_truth(scene, ray, params, truth.delta);
      truth.frame.set(i, j, oracle_color(scene, r.end), r.end.steps, r.end.crossings, r.end.hit,
                      r.end.t);
      truth.ambiguity[truth.frame.pixel(i, j)] = r.ambiguity;
      truth.t_slack[truth.frame.pixel(i, j)] = static_cast<float>(r.t_slack);
    }
  });
  return truth;
}

}  // namespace flatmarch::conformance
