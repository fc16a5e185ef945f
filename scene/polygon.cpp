#include <algorithm>
#include <cmath>
#include <limits>

#include "scene/scene.hpp"

namespace flatmarch {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The counterclockwise angle from unit vector u to unit vector v, in [0, 2pi).
double ccw_angle(Vec2 u, Vec2 v) {
  const double a = std::atan2(cross(u, v), glm::dot(u, v));
  return a < 0.0 ? a + 2.0 * kPi : a;
}

Vec2 rotated(Vec2 u, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * u.x - s * u.y, s * u.x + c * u.y};
}

}  // namespace

double Edge::distance(Vec2 p) const {
  if (shape == EdgeShape::at_infinity) return kInfinity;
  const double u = std::clamp(glm::dot(p - start, along), 0.0, length);
  return glm::length(p - (start + u * along));
}

bool Polygon::infinite() const {
  return std::find(ideal.begin(), ideal.end(), true) != ideal.end();
}

double Polygon::area() const {
  if (infinite()) return kInfinity;
  double twice = 0.0;
  for (int i = 0; i < size(); ++i) twice += cross(vertex(i), vertex(i + 1));
  return 0.5 * twice;
}

Vec2 Polygon::centroid() const {
  if (infinite()) {
    Vec2 mean{0.0}, first_direction{0.0}, last_direction{0.0};
    int finite = 0;
    for (int i = 0; i < size(); ++i) {
      if (!is_ideal(i)) {
        mean += vertex(i);
        ++finite;
      } else if (!is_ideal(i - 1)) {
        first_direction = last_direction = vertex(i);  // the first of one or two
      } else {
        last_direction = vertex(i);
      }
    }
    mean /= static_cast<double>(std::max(finite, 1));
    double spread = 1.0;
    for (int i = 0; i < size(); ++i)
      if (!is_ideal(i)) spread = std::max(spread, glm::length(vertex(i) - mean));
    const Vec2 middle = rotated(first_direction, 0.5 * ccw_angle(first_direction, last_direction));
    return mean + spread * middle;
  }
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

std::vector<Vec2> Polygon::far_points(double radius, int arc_steps) const {
  std::vector<Vec2> points;
  for (int i = 0; i < size(); ++i) {
    if (!is_ideal(i) || is_ideal(i - 1)) continue;  // from the first ideal vertex
    const Vec2 d = vertex(i);
    points.push_back(vertex(i - 1) + radius * d);
    if (is_ideal(i + 1)) {
      // The edge at infinity: an arc from this direction counterclockwise to the next one's,
      // about the middle of the finite ends of the two rays.
      const Vec2 next = vertex(i + 1);
      const double sweep = ccw_angle(d, next);
      const int steps = static_cast<int>(std::ceil(sweep / (2.0 * kPi / arc_steps)));
      const Vec2 centre = 0.5 * (vertex(i - 1) + vertex(i + 2));
      for (int k = 1; k < steps; ++k)
        points.push_back(centre + radius * rotated(d, sweep * k / steps));
      points.push_back(vertex(i + 2) + radius * next);
    } else {
      points.push_back(vertex(i + 1) + radius * d);
    }
  }
  return points;
}

std::vector<Vec2> Polygon::outline(double radius, int arc_steps) const {
  std::vector<Vec2> points;
  for (int i = 0; i < size(); ++i) {
    if (!is_ideal(i)) {
      points.push_back(vertex(i));
    } else if (!is_ideal(i - 1)) {
      const std::vector<Vec2> far = far_points(radius, arc_steps);
      points.insert(points.end(), far.begin(), far.end());
    }
  }
  return points;
}

bool Polygon::contains(Vec2 p, double margin) const {
  // Crossing-number test, on the polygon cut off far enough out to hold p; points within
  // `margin` of the boundary (or on it) are outside.
  double reach = glm::length(p) + 1.0;
  for (int i = 0; i < size(); ++i)
    if (!is_ideal(i)) reach = std::max(reach, glm::length(vertex(i)) + 1.0);
  const std::vector<Vec2> points = infinite() ? outline(8.0 * reach) : vertices;
  bool inside = false;
  const size_t n = points.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec2 a = points[i], b = points[(i + 1) % n];
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
    // The path cannot leave through this edge (nothing leaves through one at infinity, whose
    // normal is 0).
    if (glm::dot(d, edge.normal) <= 0.0) continue;
    const Vec2 a = edge.start, ab = edge.along;
    const double denom = cross(d, ab);
    const double s = cross(a - o, ab) / denom;  // where the path meets the edge's line
    const double u = cross(a - o, d) / denom;   // how far along the edge, in [0, length] on it
    if (u < -vertex_radius || u > edge.length + vertex_radius || s < -s_tolerance || s > s_max)
      continue;
    if (s < exit.s) exit = {std::max(s, 0.0), i};
  }
  return exit;
}

double Polygon::distance_to_boundary(Vec2 p) const {
  double d = kInfinity;
  for (const Edge& edge : edges) d = std::min(d, edge.distance(p));
  return d;
}

Vec2 Polygon::heading(int i) const {
  if (is_ideal(i)) return is_ideal(i + 1) ? Vec2(0.0) : -vertex(i);
  if (is_ideal(i + 1)) return vertex(i + 1);
  return vertex(i + 1) - vertex(i);
}

double Polygon::corner_angle(int i) const {
  const Vec2 in = heading(i - 1), out = heading(i);
  return kPi - std::atan2(cross(in, out), glm::dot(in, out));
}

}  // namespace flatmarch
