// Floor plans (DESIGN.md section 5, `flatmarch plan`): the polygons as the scene lays them out,
// glued edges in matching colours with arrows that show how they match, mirrors and walls, cone
// points with their angles, objects, the camera, and optionally the path of a traced ray across
// the polygons (the paper's floor plans with a light ray).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "backends/backend.hpp"

namespace flatmarch {

// How far out a plan draws an unbounded polygon (DESIGN.md section 1, "Infinite surfaces"): its
// rays are cut off this far from their finite ends, a quarter beyond the farthest of the finite
// vertices, the objects and the camera from the origin (and at least a unit of scale).
double plan_radius(const Scene& scene);

// Edge i of a polygon as a plan draws it, from a to b (a ray cut off at `radius`); an edge at
// infinity is not drawn.
struct PlanEdge {
  Vec2 a{0.0}, b{0.0};
  bool drawn = true;
};
PlanEdge plan_edge(const Polygon& polygon, int i, double radius);

// Maps scene coordinates (y up) to picture pixels (y down): the polygons' bounding box (unbounded
// ones cut off at plan_radius), with a margin of 6% of its larger side, scaled to `width`
// pixels, below a title band.
class PlanLayout {
 public:
  static constexpr double kTitleHeight = 56.0;
  static constexpr double kMarginFraction = 0.06;

  PlanLayout(const Scene& scene, double width);
  Vec2 to_pixels(Vec2 p) const {
    return {(p.x - min_.x) * scale_, kTitleHeight + (max_.y - p.y) * scale_};
  }
  double to_pixels(double length) const { return length * scale_; }
  double width() const { return width_; }
  double height() const { return height_; }
  double radius() const { return radius_; }  // plan_radius
  // A polygon's outline as drawn: an unbounded one cut off at radius(), its arc at infinity
  // smooth.
  std::vector<Vec2> outline(const Polygon& polygon) const;

 private:
  double radius_ = 1.0;
  Vec2 min_{0.0}, max_{0.0};  // bounds with the margin
  double scale_ = 1.0, width_ = 0.0, height_ = 0.0;
};

struct PlanOptions {
  double width = 800.0;    // pixels
  std::optional<Ray> ray;  // a light ray to trace and draw
  int max_events = 200;    // events of the ray to draw at most
  MarchParams params;      // max_steps and max_distance of the ray
};

std::string floor_plan_svg(const Scene& scene, const PlanOptions& options);

// Text made safe for XML and HTML: & < > " escaped.
std::string xml_escape(const std::string& text);

}  // namespace flatmarch
