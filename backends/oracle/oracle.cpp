#include "backends/oracle/oracle.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <tbb/parallel_for.h>

#include "backends/oracle/intersect.hpp"
#include "kernels/camera.hpp"
#include "kernels/compile.hpp"

namespace flatmarch {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The first vertex of the polygon the ray meets (passes within kVertexTolerance of) for
// t in (0, limit].
struct VertexMeet {
  double t = kInf;
  int vertex = -1;
};

VertexMeet find_vertex(const Polygon& polygon, Vec2 o, Vec2 dh, double limit) {
  VertexMeet meet;
  const double dh2 = glm::dot(dh, dh);
  if (dh2 == 0.0) return meet;
  const double dh_len = std::sqrt(dh2);
  for (int k = 0; k < polygon.size(); ++k) {
    if (polygon.is_ideal(k)) continue;  // no ray reaches a point at infinity
    const Vec2 w = polygon.vertex(k) - o;
    const double s = glm::dot(w, dh) / dh2;
    if (s <= 0.0 || s > limit + kVertexTolerance / dh_len || s >= meet.t) continue;
    if (std::abs(cross(w, dh)) / dh_len <= kVertexTolerance) meet = {s, k};
  }
  return meet;
}

struct ObjectMeet {
  double t = kInf;
  int index = -1;
  Vec3 normal{0.0};
};

// The first object or vertex marker of the room hit for t in [0, limit].
ObjectMeet find_object(const Scene& scene, int p, Vec3 o, Vec3 d, double limit) {
  ObjectMeet meet;
  const auto consider = [&](const std::optional<SolidHit>& hit, int index) {
    if (hit && hit->t < meet.t) meet = {hit->t, index, hit->normal};
  };
  for (size_t k = 0; k < scene.objects.size(); ++k)
    if (scene.objects[k].polygon == p)
      consider(intersect(scene.objects[k], o, d, 0.0, std::min(limit, meet.t)),
               static_cast<int>(k));
  if (!scene.markers.empty()) {
    const Polygon& polygon = scene.polygons[static_cast<size_t>(p)];
    const double top = scene.period ? *scene.period : scene.height;
    for (int v = 0; v < polygon.size(); ++v) {
      const int m = scene.marker_at(p, v);
      if (m < 0) continue;
      consider(intersect_cylinder(polygon.vertex(v), scene.markers[static_cast<size_t>(m)].radius,
                                  0.0, top, o, d, 0.0, std::min(limit, meet.t)),
               static_cast<int>(scene.objects.size()) + m);
    }
  }
  return meet;
}

double wrap(double z, double period) {
  return z - period * std::floor(z / period);
}

class Tracer {
 public:
  Tracer(const Scene& scene, const MarchParams& params, const OracleOptions& options,
         OracleResult& out)
      : scene_(scene), params_(params), options_(options), out_(out) {}

  void run(const Ray& ray) {
    p_ = ray.polygon;
    o_ = ray.from;
    d_ = glm::normalize(ray.dir);
    if (scene_.period) o_.z = wrap(o_.z, *scene_.period);
    if (!scene_.in_band(o_.z) && !enter_from_outside()) return;
    while (out_.end.steps < params_.max_steps) {
      ++out_.end.steps;
      if (step()) return;
    }
    finish(EventKind::max_steps, kHitMaxSteps, 0.0, -1);
  }

 private:
  // A camera above or below the band sees the rooms laid out as their coordinates place them.
  // Returns false when the ray ended without entering one.
  bool enter_from_outside() {
    const bool above = o_.z > scene_.height;
    if (above ? d_.z >= 0.0 : d_.z <= 0.0) {
      miss(params_.max_distance);
      return false;
    }
    const double s = ((above ? scene_.height : 0.0) - o_.z) / d_.z;
    if (s > params_.max_distance) {
      miss(params_.max_distance);
      return false;
    }
    const Vec3 q = o_ + s * d_;
    for (size_t k = 0; k < scene_.polygons.size(); ++k) {
      if (!scene_.polygons[k].contains(Vec2(q))) continue;
      p_ = static_cast<int>(k);
      if (!above && scene_.floor) {  // the underside of the floor
        finish(EventKind::floor, kHitFloor, s, -1, Vec3(0.0, 0.0, -1.0));
        return false;
      }
      record({.kind = EventKind::enter, .polygon = p_, .t = s, .at = q});
      add_path(q);
      o_ = q;
      t_ = s;
      return true;
    }
    miss(s);
    return false;
  }

  // One room segment; returns true when the ray has ended.
  bool step() {
    const Polygon& polygon = scene_.polygons[static_cast<size_t>(p_)];
    const Vec2 o(o_), dh(d_);
    // Where it leaves the room horizontally: the first edge it crosses outward.
    const Polygon::Exit exit = polygon.exit(o, dh, kVertexTolerance, kVertexTolerance);
    VertexMeet vertex = find_vertex(polygon, o, dh, exit.s);
    // A vertex met at the exit point may lie a rounding error beyond it; it still comes first.
    if (vertex.vertex >= 0) vertex.t = std::min(vertex.t, exit.s);

    double band = kInf;  // leaving the band: escape, floor, or a period wrap
    const double top = scene_.period ? *scene_.period : scene_.height;
    if (d_.z > 0.0) band = (top - o_.z) / d_.z;
    if (d_.z < 0.0) band = -o_.z / d_.z;
    const double remaining = params_.max_distance - t_;

    const ObjectMeet object =
        find_object(scene_, p_, o_, d_, std::min({exit.s, vertex.t, band, remaining}));
    // Ties go to the object, then the vertex, then the band, then the edge.
    const double first = std::min({object.t, vertex.t, band, exit.s});
    if (first > remaining) return finish(EventKind::max_distance, kHitMaxDistance, remaining, -1);
    if (object.t == first)
      return finish(EventKind::object, object.index, object.t, -1, object.normal);
    if (vertex.t == first) return finish(EventKind::vertex, kHitVertex, vertex.t, -1);
    if (band == first) {
      if (scene_.period) {  // z is taken modulo the period
        advance(band);
        tint(kernel::period_tint(scene_), d_.z, t_);
        o_.z = d_.z > 0.0 ? 0.0 : *scene_.period;
        return false;
      }
      if (d_.z < 0.0 && scene_.floor)
        return finish(EventKind::floor, kHitFloor, band, -1, Vec3(0, 0, 1));
      return finish(EventKind::escape, kHitEscape, band, -1);
    }
    if (exit.edge < 0)
      return finish(EventKind::vertex, kHitVertex, 0.0, -1);  // numerically cornered

    const Edge& edge = polygon.edges[static_cast<size_t>(exit.edge)];
    const Vec3 at = o_ + exit.s * d_;
    switch (edge.kind) {
      case EdgeKind::wall:
        return finish(EventKind::wall, kHitWall, exit.s, exit.edge, Vec3(-edge.normal, 0.0));
      case EdgeKind::mirror: {
        seam(exit.edge, at, t_ + exit.s);
        tint(edge, dh, t_ + exit.s);
        record({.kind = EventKind::mirror,
                .polygon = p_,
                .edge = exit.edge,
                .t = t_ + exit.s,
                .at = at});
        advance(exit.s);
        const Vec2 reflected = dh - 2.0 * glm::dot(dh, edge.normal) * edge.normal;
        d_ = glm::normalize(Vec3(reflected, d_.z));
        break;
      }
      case EdgeKind::glued: {
        seam(exit.edge, at, t_ + exit.s);
        tint(edge, dh, t_ + exit.s);
        record({.kind = EventKind::gluing,
                .polygon = p_,
                .edge = exit.edge,
                .to_polygon = edge.to.polygon,
                .to_edge = edge.to.edge,
                .t = t_ + exit.s,
                .at = at});
        advance(exit.s);
        o_ = Vec3(edge.map.apply(Vec2(o_)), o_.z);
        // Under a non-isometric map the horizontal direction follows the linear part and the
        // 3D direction is renormalised (DESIGN.md section 1).
        d_ = glm::normalize(Vec3(edge.map.apply_direction(Vec2(d_)), d_.z));
        p_ = edge.to.polygon;
        break;
      }
      case EdgeKind::infinity:  // never an exit: its normal is 0
        return finish(EventKind::max_distance, kHitMaxDistance, params_.max_distance - t_, -1);
    }
    ++out_.end.crossings;
    return false;
  }

  // A crossing of edge `e` of the ray's room at `at`, path length t, near a vertical edge of the
  // wall, its top or its bottom, passes a seam first (the kernel's seam_ray).
  void seam(int e, Vec3 at, double t) {
    const Look& look = scene_.look;
    if (!look.seams.on()) return;
    const Edge& edge = scene_.polygons[static_cast<size_t>(p_)].edges[static_cast<size_t>(e)];
    const double top = scene_.period ? *scene_.period : scene_.height;
    const double kind =
        maths_.seam_kind(at, glm::dvec4(edge.normal, 0.0, 0.0), kernel::seam_record(scene_, p_, e),
                         0.5 * look.seams.width * t, top);
    RayEnd& end = out_.end;
    const glm::dvec4 seams(look.seams.width, look.seams.opacity, look.seams.cone_opacity, 0.0);
    const double a = maths_.seam_opacity(kind, seams);
    const Vec3 colour = maths_.seam_colour(kind, glm::dvec4(look.seams.colour, 0.0),
                                           glm::dvec4(look.seams.cone, 0.0));
    end.light = maths_.tint_light(end.light, end.clear, a,
                                  maths_.fogged(colour, look.fog, t, look.fog_distance));
    end.clear *= 1.0 - a;
  }

  // The glued wall or mirror `edge`, met at path length t, tints what lies beyond it (the
  // kernel's cross_edge).
  void tint(const Edge& edge, Vec2 dh, double t) {
    tint(kernel::edge_tint(scene_.look, edge), glm::dot(dh, edge.normal), t);
  }

  // ... and likewise any glued plane of that tint, crossed with `cosine` along its normal.
  void tint(glm::dvec4 tint, double cosine, double t) {
    RayEnd& end = out_.end;
    const double a = maths_.wall_opacity(tint.w, cosine);
    const Vec3 colour = maths_.fogged(Vec3(tint), scene_.look.fog, t, scene_.look.fog_distance);
    end.light = maths_.tint_light(end.light, end.clear, a, colour);
    end.clear *= 1.0 - a;
  }

  void advance(double s) {
    add_path(o_ + s * d_);
    o_ += s * d_;
    t_ += s;
  }

  bool finish(EventKind kind, int hit, double s, int edge, Vec3 normal = Vec3(0.0)) {
    advance(s);
    RayEnd& end = out_.end;
    end.hit = hit;
    end.t = t_;
    end.polygon = p_;
    end.at = o_;
    end.dir = d_;
    end.normal = normal;
    record({.kind = kind,
            .polygon = p_,
            .edge = edge,
            .object = hit >= 0 ? hit : -1,
            .t = t_,
            .at = o_});
    return true;
  }

  void miss(double s) {
    out_.end.hit = kHitMiss;
    out_.end.t = s;
    out_.end.dir = d_;
    record({.kind = EventKind::miss, .polygon = -1, .t = s, .at = o_ + s * d_});
  }

  void record(const Event& e) {
    if (static_cast<int>(out_.trace.events.size()) < options_.max_events)
      out_.trace.events.push_back(e);
  }

  void add_path(Vec3 to) {
    if (options_.record_path) out_.path.push_back({p_, o_, to});
  }

  const Scene& scene_;
  const MarchParams& params_;
  const OracleOptions& options_;
  OracleResult& out_;
  kernel::Kernel<double, 0u> maths_;  // the kernel's appearance maths
  int p_ = 0;
  Vec3 o_{0.0}, d_{0.0};
  double t_ = 0.0;
};

}  // namespace

std::optional<std::string> ray_problem(const Scene& scene, const Ray& ray) {
  const auto finite = [](Vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  if (!finite(ray.from)) return "the ray's origin is not finite";
  if (!finite(ray.dir) || glm::length(ray.dir) == 0.0)
    return "the ray's direction is zero or not finite";
  if (ray.polygon < 0 || ray.polygon >= static_cast<int>(scene.polygons.size()))
    return "polygon " + std::to_string(ray.polygon) + " does not exist (the scene has " +
           std::to_string(scene.polygons.size()) + ")";
  if (scene.in_band(ray.from.z) &&
      !scene.polygons[static_cast<size_t>(ray.polygon)].contains(Vec2(ray.from))) {
    std::ostringstream s;
    s << "the origin (" << ray.from.x << ", " << ray.from.y << ", " << ray.from.z
      << ") is within the wall band but not strictly inside polygon " << ray.polygon;
    return s.str();
  }
  return std::nullopt;
}

OracleResult oracle_trace(const Scene& scene, const Ray& ray, const MarchParams& params,
                          const OracleOptions& options) {
  OracleResult result;
  Tracer(scene, params, options, result).run(ray);
  result.trace.steps = result.end.steps;
  return result;
}

Vec3 oracle_color(const Scene& scene, const RayEnd& end) {
  // The kernel's shading, in float64 and specialised on nothing: only its look is needed.
  using Shader = kernel::Kernel<double, 0u>;
  Shader shader;
  kernel::set_look<double>(scene.look, shader.params);
  Shader::Ray r{};
  r.hit = end.hit;
  r.crossings = end.crossings;
  r.t = end.t;
  r.o = end.at;
  r.d = end.dir;
  r.normal = end.normal;
  r.light = end.light;
  r.clear = end.clear;
  if (end.hit >= 0) {
    const Object* object = end.hit < static_cast<int>(scene.objects.size())
                               ? &scene.objects[static_cast<size_t>(end.hit)]
                               : nullptr;
    const glm::dvec4 color =
        object && object->color ? glm::dvec4(*object->color, 1.0) : glm::dvec4(0.0);
    r.surface = shader.solid_surface(color, end.normal);
  }
  return shader.shade(r);
}

std::string OracleBackend::description() const {
  return "exact analytic transport in float64 on the CPU: the ground truth";
}

Frame OracleBackend::render(const Scene& scene, const Camera& camera, int width, int height,
                            const MarchParams& params, const Progress& progress) const {
  Frame frame(width, height);
  const CameraBasis<double> basis =
      camera_basis(camera.yaw_deg, camera.pitch_deg, camera.fov_deg, width, height);
  constexpr int kRowsPerReport = 16;  // rows rendered in parallel between progress reports
  for (int band = 0; band < height; band += kRowsPerReport) {
    tbb::parallel_for(band, std::min(band + kRowsPerReport, height), [&](int j) {
      for (int i = 0; i < width; ++i) {
        const Ray ray{camera.polygon, camera.position, camera_ray(basis, i, j, width, height)};
        const RayEnd end = oracle_trace(scene, ray, params).end;
        frame.set(i, j, oracle_color(scene, end), end.steps, end.crossings, end.hit, end.t);
      }
    });
    if (progress) progress(static_cast<double>(std::min(band + kRowsPerReport, height)) / height);
  }
  return frame;
}

Trace OracleBackend::trace(const Scene& scene, const Ray& ray, const MarchParams& params,
                           int max_events) const {
  return oracle_trace(scene, ray, params, {.max_events = max_events}).trace;
}

}  // namespace flatmarch
