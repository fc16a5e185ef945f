#include "conformance/ambiguity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <tbb/parallel_for.h>

#include "backends/oracle/intersect.hpp"
#include "kernels/camera.hpp"
#include "kernels/compile.hpp"

namespace flatmarch::conformance {

namespace {

// The oracle follows rays much further than a kernel's max_steps would let it (one of its steps
// is a whole room), bounded still.
constexpr int kTruthMaxSteps = 100000;

// The largest stretch of a linear map: its largest singular value.
double stretch(const Mat2& m) {
  const Mat2 mm = glm::transpose(m) * m;
  const double half = 0.5 * (mm[0][0] + mm[1][1]);
  const double det = mm[0][0] * mm[1][1] - mm[0][1] * mm[1][0];
  return std::sqrt(half + std::sqrt(std::max(0.0, half * half - det)));
}

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

// How far from a solid, in units of eps, its distance function (kernels/maths.glsl solid_sdf)
// may still read eps. An edge where faces with normals at an angle phi meet is a max() of their
// distances, which reads eps up to eps / cos(phi / 2) from the edge (1.5 times that where three
// faces meet): a box's or cylinder's right-angled edges and corners sqrt(3); at the rim of a
// hollow cube's hole a face meets the sphere at cos phi = -size / hole (2.9 eps for the default
// hole of 1.3 size).
double sdf_reach(const Scene& scene, int index) {
  if (index >= static_cast<int>(scene.objects.size())) return std::sqrt(2.0);  // a marker
  const Object& object = scene.objects[static_cast<size_t>(index)];
  switch (object.type) {
    case ObjectType::sphere:
      return 1.0;
    case ObjectType::box:
    case ObjectType::cylinder:
      return std::sqrt(3.0);
    case ObjectType::hollow_cube: {
      const double cosine = std::min(object.size / object.hole, 0.99);
      return std::max(std::sqrt(3.0), 1.5 * std::sqrt(2.0 / (1.0 - cosine)));
    }
  }
  return std::sqrt(3.0);
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
    // Every method stops where the solid's distance function falls below eps: a line passing
    // that close counts as a hit. Near an edge of a solid that is farther than eps (sdf_reach).
    const double shifted = delta + eps * sdf_reach(scene, index);
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
    // Where the ray hits, a shifted line that hits much nearer or farther (a hollow cube's face
    // in front of its hole) leaves t to chance, as a miss would the hit.
    const double jump = 0.01 * scene.scale;
    for (const Vec3& shift : shifts) {
      const auto hit = meet(scene, seg.polygon, index, seg.from + shift, d, limit);
      if (hit.has_value() != exact || (exact && std::abs(hit->t - length) > jump)) {
        bits |= kSilhouette;
        break;
      }
    }
    // At an edge of the solid the normal, and so the colour, jumps: a hit within `crease` of one
    // is a crease.
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
  // The kernel's normal is the gradient of the solid's term active at its point (maths.glsl's
  // solid_normal_at), which lies up to eps off the surface: only that near an edge of the solid,
  // and rounding, can give it the other side's (doubled, as the shifted lines cover).
  const double crease = 2.0 * (params.eps + 16.0 * unit_roundoff(params.precision) * scene.scale);
  const double on = 1e-9 * scene.scale;
  // At a crossing the kernel maps its point, which stopped s in [0, eps] short of the edge, into
  // the new room and places it `offset` inside the edge it is now behind: the point moves
  // (s + offset) along that edge's inward normal n, the ray sideways by (s + offset) times the
  // part of n across the new direction. The shifts of successive crossings are vectors: they add
  // with their signs (in an L-shaped room a ray meets edges on both of its sides, and their shifts
  // cancel in part) and turn with the gluings that carry the ray on. So this follows the kernel's
  // expected sideways shift, s = eps / 2 at each crossing, carried through every gluing's linear
  // part and every mirror, and around it a spread that adds up what cannot cancel: eps / 2 times
  // each push's sideways part, rounding (16 u scale a crossing) and the turn of a rounded
  // direction (4 u a unit of length). The analytic method crosses at the exit point it computed,
  // with no push: only rounding.
  const double u = unit_roundoff(params.precision);
  const double push = params.method == Method::analytic ? 0.0 : params.eps + params.offset;
  Vec3 shift(0.0);  // the expected sideways shift, in the current room's coordinates
  // What may lie around it, whatever the signs, kept in the camera's room's coordinates and
  // carried into the current room's by `carried` (the product of the linear parts of the gluings
  // and mirrors crossed): a stretch and its inverse, crossed in turn, then cancel as they do.
  double spread0 = 0.0;
  Mat2 carried(1.0);
  const auto spread = [&] { return stretch(carried) * spread0; };
  const auto add_spread = [&](double x) { spread0 += x * stretch(glm::inverse(carried)); };
  for (size_t k = 0; k < r.path.size(); ++k) {
    const PathSegment& seg = r.path[k];
    const bool last = k + 1 == r.path.size();
    const Vec3 step = seg.to - seg.from;
    const double length = glm::length(step);
    const Vec3 d = length > 0.0 ? step / length : Vec3(0.0);
    const double drift = delta + glm::length(shift - glm::dot(shift, d) * d) + spread();
    truth.ambiguity |= segment_ambiguity(scene, seg, last, r.end, drift, params.eps, crease);
    add_spread(4.0 * u * length);
    if (last || !scene.in_band(seg.from.z)) continue;
    const Polygon& polygon = scene.polygons[static_cast<size_t>(seg.polygon)];
    for (int e = 0; e < polygon.size(); ++e) {
      const Edge& edge = polygon.edges[static_cast<size_t>(e)];
      if (edge.distance(Vec2(seg.to)) >= on) continue;
      // The shift so far, carried into the next room: a vector under the gluing's linear part,
      // reflected by a mirror.
      Mat2 m(1.0);
      if (edge.kind == EdgeKind::mirror)
        m -= 2.0 * glm::outerProduct(edge.normal, edge.normal);
      else if (edge.kind == EdgeKind::glued)
        m = edge.map.linear;
      const Vec2 v = m * Vec2(shift);
      shift = Vec3(v, shift.z);
      carried = m * carried;
      const double scaled = stretch(m);
      const double along = glm::dot(Vec3(edge.normal, 0.0), d);
      if (push > 0.0) {
        // The push, along the inward normal of the edge the ray is now behind, across the
        // direction the ray goes on in.
        const PathSegment& next = r.path[k + 1];
        const Vec3 next_step = next.to - next.from;
        const double next_length = glm::length(next_step);
        const Vec3 dn = next_length > 0.0 ? next_step / next_length : d;
        const Polygon& behind = scene.polygons[static_cast<size_t>(next.polygon)];
        Vec2 n(0.0);
        for (int b = 0; b < behind.size(); ++b) {
          const Edge& candidate = behind.edges[static_cast<size_t>(b)];
          if (candidate.distance(Vec2(next.from)) < on) {
            n = -candidate.normal;  // inward
            break;
          }
        }
        const Vec3 n3(n, 0.0);
        const Vec3 across = n3 - glm::dot(n3, dn) * dn;
        const double s = 0.5 * params.eps * scaled;
        shift += (params.offset + s) * across;
        add_spread(s * glm::length(across));
        truth.t_slack += params.eps / std::max(std::abs(along), 1e-3) + push;
      }
      add_spread(16.0 * u * scene.scale);
      break;
    }
  }
  const double drift = delta + glm::length(shift) + spread();
  if (!r.path.empty() && (r.end.hit >= 0 || (r.end.hit == kHitWall && push > 0.0))) {
    const Vec3 step = r.path.back().to - r.path.back().from;
    const double length = glm::length(step);
    const double cosine = length > 0.0 ? std::abs(glm::dot(step, r.end.normal)) / length : 1.0;
    truth.t_slack += params.eps / std::max(cosine, 1e-3);
  }
  // t is summed step by step: in float32 it drifts by about 2^-24 of the distance a step. And
  // each crossing's stop short of the edge and push shorten or lengthen it (t_slack). A ray whose
  // end, or whose last crossing before max_distance, lies that close to max_distance, on either
  // side, may end either way: with another hit, or after another number of crossings.
  // A solid counts as hit within eps of it, sooner by eps / cos(incidence): 10 eps covers
  // incidences up to 84 degrees.
  const double slack = drift + truth.t_slack + 64.0 * u * params.max_distance + 10.0 * params.eps;
  if (r.end.hit == kHitMaxDistance) {
    for (const double reach : {params.max_distance - slack, params.max_distance + slack}) {
      exact.max_distance = std::max(reach, 0.0);
      const RayEnd e = oracle_trace(scene, ray, exact).end;
      if (e.hit != kHitMaxDistance || e.crossings != r.end.crossings) {
        truth.ambiguity |= kNearDistance;
        break;
      }
    }
  } else if (r.end.t > params.max_distance - slack) {
    truth.ambiguity |= kNearDistance;
  }
  return truth;
}

size_t FrameTruth::ambiguous() const {
  return static_cast<size_t>(std::count_if(ambiguity.begin(), ambiguity.end(),
                                           [](uint8_t a) { return (a & kPathAmbiguity) != 0; }));
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
