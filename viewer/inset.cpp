#include "viewer/inset.hpp"

#include <algorithm>
#include <cmath>

#include "plan/floor_plan.hpp"

namespace flatmarch::viewer {

namespace {

constexpr double kMaxWidthFraction = 0.25, kMaxHeightFraction = 0.4, kMaxWidth = 280.0;
constexpr double kMargin = 8.0;  // pixels between the inset and the window's edges

struct Colour {
  float r, g, b;
};
constexpr Colour kBackdrop{0.1f, 0.1f, 0.12f};
constexpr Colour kMirror{0.55f, 0.75f, 0.95f};
constexpr Colour kWall{0.75f, 0.75f, 0.75f};
constexpr Colour kCurrent{1.0f, 1.0f, 0.55f};  // the camera's polygon, under its edges
constexpr Colour kCamera{0.95f, 0.2f, 0.35f};

// Width and height of the plan (PlanLayout without its title band) drawn `width` pixels wide.
Vec2 plan_size(const Scene& scene, double width) {
  const PlanLayout layout(scene, width);
  return {layout.width(), layout.height() - PlanLayout::kTitleHeight};
}

class Triangles {
 public:
  void quad(Vec2 a, Vec2 b, Vec2 c, Vec2 d, Colour colour) {
    for (const Vec2& p : {a, b, c, a, c, d})
      out_.push_back(
          {static_cast<float>(p.x), static_cast<float>(p.y), colour.r, colour.g, colour.b});
  }
  // A segment `width` pixels wide, with square ends.
  void line(Vec2 a, Vec2 b, double width, Colour colour) {
    if (glm::length(b - a) < 1e-9) return;
    const Vec2 d = glm::normalize(b - a) * (0.5 * width), n = perp(d);
    quad(a - d + n, b + d + n, b + d - n, a - d - n, colour);
  }
  std::vector<InsetVertex> take() { return std::move(out_); }

 private:
  std::vector<InsetVertex> out_;
};

}  // namespace

InsetBox inset_box(const Scene& scene, int window_width, int window_height) {
  const Vec2 unit = plan_size(scene, 1.0);  // height per pixel of width
  double width = std::min(kMaxWidth, kMaxWidthFraction * window_width);
  width = std::min(width, kMaxHeightFraction * window_height * unit.x / unit.y);
  const double height = width * unit.y / unit.x;
  return {window_width - kMargin - width, kMargin, width, height};
}

// A glued edge in its gluing's colour (the one it tints the rooms with and the floor plan draws
// it in), brightened to show on the dark backdrop: the same hue, its brightest channel 0.95.
Colour gluing_colour(const Look& look, int gluing) {
  const Vec3 c = look.gluing_colour(gluing);
  const double top = std::max({c.x, c.y, c.z, 1e-6});
  const auto encode = [&](double v) { return static_cast<float>(0.95 * encode_srgb(v / top)); };
  return {encode(c.x), encode(c.y), encode(c.z)};
}

std::vector<InsetVertex> inset_triangles(const Scene& scene, const Camera& camera,
                                         const InsetBox& box) {
  const PlanLayout layout(scene, box.width);
  const auto at = [&](Vec2 p) {
    return layout.to_pixels(p) + Vec2(box.x, box.y - PlanLayout::kTitleHeight);
  };
  Triangles t;
  t.quad({box.x, box.y}, {box.x + box.width, box.y}, {box.x + box.width, box.y + box.height},
         {box.x, box.y + box.height}, kBackdrop);
  const Polygon& current = scene.polygons[static_cast<size_t>(camera.polygon)];
  // Unbounded polygons as the floor plan cuts them off; their edges at infinity are not drawn.
  for (int i = 0; i < current.size(); ++i)
    if (const PlanEdge e = plan_edge(current, i, layout.radius()); e.drawn)
      t.line(at(e.a), at(e.b), 5.0, kCurrent);
  for (const Polygon& polygon : scene.polygons)
    for (int i = 0; i < polygon.size(); ++i) {
      const Edge& edge = polygon.edges[static_cast<size_t>(i)];
      const PlanEdge e = plan_edge(polygon, i, layout.radius());
      if (!e.drawn) continue;
      t.line(at(e.a), at(e.b), 2.0,
             edge.kind == EdgeKind::glued    ? gluing_colour(scene.look, edge.gluing)
             : edge.kind == EdgeKind::mirror ? kMirror
                                             : kWall);
    }
  const Vec2 c = at(Vec2(camera.position));
  const double yaw = camera.yaw_deg * kPi / 180.0;
  const Vec2 heading(std::cos(yaw), -std::sin(yaw));  // y down on the screen
  t.line(c, c + std::max(12.0, 0.08 * box.width) * heading, 2.0, kCamera);
  t.line(c - Vec2(2.5, 0.0), c + Vec2(2.5, 0.0), 5.0, kCamera);
  return t.take();
}

}  // namespace flatmarch::viewer
