#include <algorithm>
#include <cmath>
#include <limits>

#include "scene/scene.hpp"

namespace flatmarch {

double Polygon::area() const {
  double twice = 0.0;
  for (int i = 0; i < size(); ++i) twice += cross(vertex(i), vertex(i + 1));
  return 0.5 * twice;
}

Vec2 Polygon::centroid() const {
  // Area centroid, computed relative to vertex 0 to keep the sums small.
  const Vec2 o = vertex(0);
  Vec2 sum{0.0};
  double twice_area = 0.0;
  for (int i = 0; i < size(); ++i) {
    const Vec2 a = vertex(i) - o, b = vertex(i + 1) - o;
    const double w = cross(a, b);
    sum += w * (a + b);
    twice_area += w;
  }
  return o + sum / (3.0 * twice_area);
}

bool Polygon::contains(Vec2 p, double margin) const {
  // Crossing-number test; points within `margin` of the boundary (or on it) are outside.
  bool inside = false;
  for (int i = 0; i < size(); ++i) {
    const Vec2 a = vertex(i), b = vertex(i + 1);
    if ((a.y > p.y) != (b.y > p.y)) {
      const double x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
      if (x > p.x) inside = !inside;
    }
  }
  return inside && distance_to_boundary(p) > margin;
}

Polygon::Exit Polygon::exit(Vec2 o, Vec2 d, double vertex_radius, double s_tolerance,
                            double s_max) const {
  Exit exit;
  if (d.x == 0.0 && d.y == 0.0) return exit;
  for (int i = 0; i < size(); ++i) {
    const Edge& edge = edges[static_cast<size_t>(i)];
    if (glm::dot(d, edge.normal) <= 0.0) continue;  // the path cannot leave through this edge
    const Vec2 a = vertex(i), ab = vertex(i + 1) - a;
    const double denom = cross(d, ab);
    const double s = cross(a - o, ab) / denom;  // where the path meets the edge's line
    const double u = cross(a - o, d) / denom;   // where along the edge, in [0, 1] on it
    const double u_tol = vertex_radius / edge.length;
    if (u < -u_tol || u > 1.0 + u_tol || s < -s_tolerance || s > s_max) continue;
    if (s < exit.s) exit = {std::max(s, 0.0), i};
  }
  return exit;
}

double Polygon::distance_to_boundary(Vec2 p) const {
  double d = std::numeric_limits<double>::infinity();
  for (int i = 0; i < size(); ++i)
    d = std::min(d, distance_to_segment(p, vertex(i), vertex(i + 1)));
  return d;
}

double Polygon::corner_angle(int i) const {
  const Vec2 in = vertex(i) - vertex(i - 1), out = vertex(i + 1) - vertex(i);
  return kPi - std::atan2(cross(in, out), glm::dot(in, out));
}

}  // namespace flatmarch
