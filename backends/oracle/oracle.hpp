// The oracle: exact transport in float64, the truth every backend is measured against.
// Per room segment it finds, by analytic intersection, the exit edge, the band, the first object
// and any vertex on the way, and takes whichever comes first. One step is one room segment.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "backends/backend.hpp"

namespace flatmarch {

// How a ray ended, with what shading needs.
struct RayEnd {
  int hit = kHitMiss;
  int crossings = 0;
  int steps = 0;
  double t = 0.0;
  int polygon = 0;
  Vec3 at{0.0};        // end point in `polygon`'s frame
  Vec3 dir{0.0};       // unit direction there
  Vec3 normal{0.0};    // surface normal there (objects, walls, the floor)
  Vec3 light{0.0};     // what the glued walls and mirrors crossed give (the kernel's Ray.light)
  double clear = 1.0;  // the share of light beyond them they let through
};

// The straight piece of a ray's path inside one room, for floor plans.
struct PathSegment {
  int polygon = 0;
  Vec3 from{0.0}, to{0.0};
};

struct OracleOptions {
  int max_events = 0;        // events to record in `trace`
  bool record_path = false;  // fill `path`
};

struct OracleResult {
  RayEnd end;
  Trace trace;
  std::vector<PathSegment> path;
};

// Why `ray` cannot be traced in `scene` (an origin within the band but outside its polygon, a
// zero or non-finite direction), or nothing.
std::optional<std::string> ray_problem(const Scene& scene, const Ray& ray);

// Follows `ray` (which must pass ray_problem) under params.max_steps and params.max_distance.
OracleResult oracle_trace(const Scene& scene, const Ray& ray, const MarchParams& params,
                          const OracleOptions& options = {});

// The linear colour of a finished ray.
Vec3 oracle_color(const Scene& scene, const RayEnd& end);

class OracleBackend final : public Backend {
 public:
  std::string name() const override { return "oracle"; }
  std::string description() const override;
  Availability availability() const override { return {}; }
  std::vector<Method> methods() const override { return {Method::oracle}; }
  Frame render(const Scene& scene, const Camera& camera, int width, int height,
               const MarchParams& params, const Progress& progress) const override;
  Trace trace(const Scene& scene, const Ray& ray, const MarchParams& params,
              int max_events) const override;
};

}  // namespace flatmarch
