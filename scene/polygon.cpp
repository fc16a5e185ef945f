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
