#include "scene/derive.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>

namespace flatmarch {

namespace {

std::string format_point(Vec2 p) {
  std::ostringstream s;
  s.precision(12);
  s << "(" << p.x << ", " << p.y << ")";
  return s.str();
}

bool near(const Mat2& m, const Mat2& n, double tol) {
  for (int c = 0; c < 2; ++c)
    for (int r = 0; r < 2; ++r)
      if (std::abs(m[c][r] - n[c][r]) > tol) return false;
  return true;
}

// The reflection taking unit vector u to unit vector v (in the line between them).
Mat2 reflection_between(Vec2 u, Vec2 v) {
  const Vec2 w = glm::length(u + v) > 1e-6 ? glm::normalize(u + v) : perp(u);
  return 2.0 * glm::outerProduct(w, w) - Mat2(1.0);
}

// The rotation by the angle from unit vector u to unit vector v.
Mat2 rotation_between(Vec2 u, Vec2 v) {
  const double c = glm::dot(u, v), s = cross(u, v);
  return Mat2(Vec2(c, s), Vec2(-s, c));
}

class UnionFind {
 public:
  explicit UnionFind(size_t n) : parent_(n) {
    std::iota(parent_.begin(), parent_.end(), size_t{0});
  }
  size_t find(size_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void unite(size_t a, size_t b) { parent_[find(a)] = find(b); }

 private:
  std::vector<size_t> parent_;
};

// Whether edges i and j (neither at infinity) of a polygon whose edge table is filled share a
// point, to within tol: rays are half-lines, exactly.
bool edges_touch(const Polygon& polygon, int i, int j, double tol) {
  const Edge& e = polygon.edges[static_cast<size_t>(i)];
  const Edge& f = polygon.edges[static_cast<size_t>(j)];
  const auto ends = [](const Edge& g) {
    std::vector<Vec2> points{g.start};
    if (!g.ray()) points.push_back(g.start + g.length * g.along);
    return points;
  };
  for (Vec2 p : ends(e))
    if (f.distance(p) <= tol) return true;
  for (Vec2 p : ends(f))
    if (e.distance(p) <= tol) return true;
  const double denom = cross(e.along, f.along);
  if (std::abs(denom) <= 1e-15) return false;  // parallel, and no end on the other
  const Vec2 w = f.start - e.start;
  const double s = cross(w, f.along) / denom, t = cross(w, e.along) / denom;
  return s > 0.0 && s < e.length && t > 0.0 && t < f.length;
}

}  // namespace

std::optional<PolygonProblem> check_polygon(Polygon& polygon, double scale) {
  const int n = polygon.size();
  const double tol = 1e-12 * scale;
  // Ideal vertices (DESIGN.md section 1, "Infinite surfaces"): at most two, next to each other.
  int ideal = 0, first_ideal = -1;
  for (int i = 0; i < n; ++i)
    if (polygon.is_ideal(i)) {
      if (++ideal > 2)
        return PolygonProblem{i, "a polygon has at most two ideal vertices (this is the third)"};
      if (first_ideal < 0) first_ideal = i;
    }
  if (ideal == 2 && !polygon.is_ideal(first_ideal + 1) && !polygon.is_ideal(first_ideal - 1))
    return PolygonProblem{first_ideal,
                          "the two ideal vertices of a polygon must be next to each other "
                          "(the edge between them lies at infinity)"};
  for (int i = 0; i < n; ++i) {
    if (polygon.is_ideal(i) || polygon.is_ideal(i + 1)) continue;
    if (glm::length(polygon.vertex(i + 1) - polygon.vertex(i)) <= tol)
      return PolygonProblem{(i + 1) % n, "repeats the previous vertex (edge " + std::to_string(i) +
                                             " has zero length)"};
  }
  for (int i = 0; i < n; ++i)
    for (int j = i + 2; j < n; ++j)
      if (!polygon.is_ideal(i) && !polygon.is_ideal(j) &&
          glm::length(polygon.vertex(j) - polygon.vertex(i)) <= tol)
        return PolygonProblem{
            j, "repeats vertex " + std::to_string(i) + " " + format_point(polygon.vertex(i))};
  for (int i = 0; i < n; ++i) {
    if (polygon.is_ideal(i + 1)) continue;  // no corner at an ideal vertex
    const Vec2 in = polygon.heading(i), out = polygon.heading(i + 1);
    if (glm::length(in) == 0.0 || glm::length(out) == 0.0) continue;
    if (std::abs(cross(in, out)) <= tol * glm::length(in) * glm::length(out) &&
        glm::dot(in, out) < 0.0)
      return PolygonProblem{(i + 1) % n,
                            "edges " + std::to_string(i) + " and " + std::to_string((i + 1) % n) +
                                " fold back onto each other: the polygon is not simple"};
  }
  init_edges(polygon, EdgeKind::mirror);
  for (int i = 0; i < n; ++i)
    for (int j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through vertex 0
      const auto at_infinity = [&](int k) {
        return polygon.edges[static_cast<size_t>(k)].shape == EdgeShape::at_infinity;
      };
      if (at_infinity(i) || at_infinity(j)) continue;
      if (edges_touch(polygon, i, j, tol))
        return PolygonProblem{-1, "edges " + std::to_string(i) + " and " + std::to_string(j) +
                                      " intersect: the polygon is not simple"};
    }
  // Only a simple polygon's signed area says its orientation; an unbounded one's is its
  // outline's, cut off far out.
  double area = polygon.area();
  if (polygon.infinite()) {
    const std::vector<Vec2> outline = polygon.outline(1e6 * scale);
    area = 0.0;
    for (size_t i = 0; i < outline.size(); ++i)
      area += 0.5 * cross(outline[i], outline[(i + 1) % outline.size()]);
  }
  if (std::abs(area) <= tol * scale) return PolygonProblem{-1, "the polygon has zero area"};
  if (area < 0.0)
    return PolygonProblem{-1, "the vertices are listed clockwise; list them counterclockwise"};
  return std::nullopt;
}

GluingMapResult derive_gluing_map(const Scene& scene, EdgeRef a, EdgeRef b, GluingMap map,
                                  const Mat2& matrix) {
  const Polygon& p = scene.polygons[static_cast<size_t>(a.polygon)];
  const Polygon& q = scene.polygons[static_cast<size_t>(b.polygon)];
  const Edge& ea = scene.edge(a);
  const Edge& eb = scene.edge(b);
  const auto name = [](EdgeRef e) {
    return "edge [" + std::to_string(e.polygon) + ", " + std::to_string(e.edge) + "]";
  };
  for (EdgeRef e : {a, b})
    if (scene.edge(e).shape == EdgeShape::at_infinity)
      return {{},
              name(e) +
                  " lies at infinity (between two ideal vertices): nothing reaches it, "
                  "so it cannot be glued"};
  if (ea.ray() != eb.ray()) {
    const EdgeRef ray = ea.ray() ? a : b, segment = ea.ray() ? b : a;
    return {{},
            "a segment cannot be glued to a ray: " + name(ray) + " runs to infinity, " +
                name(segment) + " is a segment"};
  }
  if (ea.ray()) {
    // Rays (DESIGN.md section 1, "Infinite surfaces"): g takes the finite end of one to that
    // of the other, and the direction of the one's ideal point to that of the other's.
    const bool same_way = ea.shape == eb.shape;
    GluingMapResult r;
    switch (map) {
      case GluingMap::similarity:
      case GluingMap::matrix:
        return {{},
                std::string("rays are glued by an isometry (or \"map\": \"reflection\"); ") +
                    (map == GluingMap::matrix ? "a \"matrix\"" : "\"similarity\"") +
                    " would not keep their lengths, which are infinite"};
      case GluingMap::isometry:
        if (same_way)
          return {{},
                  name(a) + " and " + name(b) + " both run " +
                      (ea.shape == EdgeShape::ray_out ? "out to" : "in from") +
                      " infinity: an isometry glues a ray running out to one running in "
                      "(\"map\": \"reflection\" glues two running the same way)"};
        r.g.linear = rotation_between(ea.along, eb.along);
        break;
      case GluingMap::reflection: {
        if (!same_way)
          return {{},
                  "a reflection glues two rays running the same way; " + name(a) + " runs " +
                      (ea.shape == EdgeShape::ray_out ? "out to" : "in from") + " infinity and " +
                      name(b) + " the other way (drop \"map\" for an isometry)"};
        r.g.linear = reflection_between(ea.along, eb.along);
        break;
      }
    }
    r.g.translation = eb.start - r.g.linear * ea.start;
    return r;
  }
  const Vec2 A = p.vertex(a.edge), B = p.vertex(a.edge + 1);
  const Vec2 C = q.vertex(b.edge), D = q.vertex(b.edge + 1);
  const double la = glm::length(B - A), lb = glm::length(D - C);
  const auto lengths_differ = [&] {
    std::ostringstream s;
    s.precision(12);
    s << "the glued edges differ in length (" << la << " and " << lb
      << "); an isometry needs equal lengths";
    return s.str();
  };
  const bool same_length = std::abs(la - lb) <= kLengthTolerance * std::max(la, lb);
  GluingMapResult r;
  switch (map) {
    case GluingMap::isometry: {
      if (!same_length) return {{}, lengths_differ()};
      r.g.linear = rotation_between((B - A) / la, (C - D) / lb);
      r.g.translation = D - r.g.linear * A;
      return r;
    }
    case GluingMap::reflection: {
      if (!same_length) return {{}, lengths_differ()};
      const Vec2 u = (B - A) / la, v = (D - C) / lb;
      r.g.linear = reflection_between(u, v);
      r.g.translation = C - r.g.linear * A;
      return r;
    }
    case GluingMap::similarity: {
      r.g.linear = (lb / la) * rotation_between((B - A) / la, (C - D) / lb);
      r.g.translation = D - r.g.linear * A;
      return r;
    }
    case GluingMap::matrix: {
      const double det = glm::determinant(matrix);
      if (!(std::abs(det) > 1e-12)) return {{}, "the matrix is singular (determinant 0)"};
      // Orientation-preserving maps send A to D as the default isometry does; reversing ones
      // send A to C as a reflection does. Either way the outside of a lands inside b.
      const Vec2 to_a = det > 0.0 ? D : C, to_b = det > 0.0 ? C : D;
      r.g.linear = matrix;
      r.g.translation = to_a - matrix * A;
      const Vec2 image = r.g.apply(B);
      if (glm::length(image - to_b) > kLengthTolerance * std::max({lb, la, 1.0}))
        return {{},
                "the matrix does not carry edge [" + std::to_string(a.polygon) + ", " +
                    std::to_string(a.edge) + "] onto edge [" + std::to_string(b.polygon) + ", " +
                    std::to_string(b.edge) + "]: with " + format_point(A) + " -> " +
                    format_point(to_a) + ", " + format_point(B) + " goes to " +
                    format_point(image) + " instead of " + format_point(to_b)};
      return r;
    }
  }
  return r;
}

GluingType classify(const Mat2& linear) {
  constexpr double tol = 1e-9;
  const Mat2 gram = glm::transpose(linear) * linear;
  const double det = glm::determinant(linear);
  if (near(gram, Mat2(1.0), tol)) {
    if (det < 0.0) return GluingType::reflection;
    if (near(linear, Mat2(1.0), tol)) return GluingType::translation;
    if (near(linear, Mat2(-1.0), tol)) return GluingType::half_translation;
    return GluingType::rotation;
  }
  const double s2 = gram[0][0];
  if (det > 0.0 && near(gram, Mat2(s2), tol * s2)) return GluingType::similarity;
  return GluingType::affine;
}

void init_edges(Polygon& polygon, EdgeKind boundary) {
  polygon.edges.assign(polygon.vertices.size(), Edge{});
  for (int i = 0; i < polygon.size(); ++i) {
    Edge& e = polygon.edges[static_cast<size_t>(i)];
    const Vec2 d = polygon.heading(i);
    e.kind = boundary;
    if (polygon.is_ideal(i) && polygon.is_ideal(i + 1)) {
      e.kind = EdgeKind::infinity;
      e.shape = EdgeShape::at_infinity;
      e.length = std::numeric_limits<double>::infinity();
      continue;  // no points, no normal
    }
    e.length = glm::length(d);
    e.normal = -perp(d) / e.length;  // the interior of a counterclockwise polygon is on the left
    e.start = polygon.vertex(i);
    e.along = d / e.length;
    if (polygon.is_ideal(i + 1)) {
      e.shape = EdgeShape::ray_out;
    } else if (polygon.is_ideal(i)) {
      e.shape = EdgeShape::ray_in;
      e.start = polygon.vertex(i + 1);
      e.along = -e.along;
    }
    if (e.ray()) e.length = std::numeric_limits<double>::infinity();
  }
}

void attach_gluing(Scene& scene, int index) {
  const Gluing& gl = scene.gluings[static_cast<size_t>(index)];
  const auto attach = [&](EdgeRef from, EdgeRef to, const Affine2& map) {
    Edge& e =
        scene.polygons[static_cast<size_t>(from.polygon)].edges[static_cast<size_t>(from.edge)];
    e.kind = EdgeKind::glued;
    e.gluing = index;
    e.to = to;
    e.map = map;
  };
  attach(gl.a, gl.b, gl.g);
  attach(gl.b, gl.a, gl.g.inverse());
}

void derive_vertex_classes(Scene& scene) {
  std::vector<size_t> offset(scene.polygons.size() + 1, 0);
  for (size_t p = 0; p < scene.polygons.size(); ++p)
    offset[p + 1] = offset[p] + scene.polygons[p].vertices.size();
  const auto corner = [&](int p, int v) {
    const int n = scene.polygons[static_cast<size_t>(p)].size();
    return offset[static_cast<size_t>(p)] + static_cast<size_t>(((v % n) + n) % n);
  };

  UnionFind classes(offset.back());
  for (const Gluing& gl : scene.gluings) {
    // A -> D and B -> C for orientation-preserving maps, A -> C and B -> D for reversing ones.
    const bool preserving = gl.g.determinant() > 0.0;
    classes.unite(corner(gl.a.polygon, gl.a.edge),
                  corner(gl.b.polygon, gl.b.edge + (preserving ? 1 : 0)));
    classes.unite(corner(gl.a.polygon, gl.a.edge + 1),
                  corner(gl.b.polygon, gl.b.edge + (preserving ? 0 : 1)));
  }

  scene.vertex_classes.clear();
  scene.corner_class.assign(scene.polygons.size(), {});
  std::map<size_t, int> class_of_root;
  for (size_t p = 0; p < scene.polygons.size(); ++p) {
    const Polygon& polygon = scene.polygons[p];
    scene.corner_class[p].resize(polygon.vertices.size());
    for (int v = 0; v < polygon.size(); ++v) {
      if (polygon.is_ideal(v)) {  // a point at infinity is no vertex of the surface
        scene.corner_class[p][static_cast<size_t>(v)] = -1;
        continue;
      }
      const size_t root = classes.find(corner(static_cast<int>(p), v));
      auto [it, added] =
          class_of_root.try_emplace(root, static_cast<int>(scene.vertex_classes.size()));
      if (added) scene.vertex_classes.emplace_back();
      VertexClass& vc = scene.vertex_classes[static_cast<size_t>(it->second)];
      vc.corners.push_back({static_cast<int>(p), v});
      vc.cone_angle += polygon.corner_angle(v);
      const EdgeKind in =
          polygon.edges[static_cast<size_t>((v + polygon.size() - 1) % polygon.size())].kind;
      const EdgeKind out = polygon.edges[static_cast<size_t>(v)].kind;
      vc.boundary = vc.boundary || in != EdgeKind::glued || out != EdgeKind::glued;
      scene.corner_class[p][static_cast<size_t>(v)] = it->second;
    }
  }
  for (VertexClass& vc : scene.vertex_classes)
    vc.singular = std::abs(vc.cone_angle - (vc.boundary ? kPi : 2.0 * kPi)) > 1e-9;
}

void derive_topology(Scene& scene) {
  Topology& t = scene.topology;
  const size_t np = scene.polygons.size();

  // Connected components and orientability: give each polygon an orientation sign, flipped
  // across orientation-reversing gluings; a contradiction makes the surface non-orientable.
  std::vector<std::vector<std::pair<int, bool>>> neighbours(np);
  for (const Gluing& gl : scene.gluings) {
    const bool flips = gl.g.determinant() < 0.0;
    neighbours[static_cast<size_t>(gl.a.polygon)].push_back({gl.b.polygon, flips});
    neighbours[static_cast<size_t>(gl.b.polygon)].push_back({gl.a.polygon, flips});
  }
  std::vector<int> sign(np, 0);
  t.components = 0;
  t.orientable = true;
  for (size_t start = 0; start < np; ++start) {
    if (sign[start] != 0) continue;
    ++t.components;
    sign[start] = 1;
    std::vector<size_t> stack{start};
    while (!stack.empty()) {
      const size_t p = stack.back();
      stack.pop_back();
      for (auto [q, flips] : neighbours[p]) {
        const int want = flips ? -sign[p] : sign[p];
        int& s = sign[static_cast<size_t>(q)];
        if (s == 0) {
          s = want;
          stack.push_back(static_cast<size_t>(q));
        } else if (s != want) {
          t.orientable = false;
        }
      }
    }
  }

  // Boundary components: boundary edges link the boundary vertex classes into cycles.
  UnionFind boundary(scene.vertex_classes.size());
  int boundary_edges = 0;
  for (size_t p = 0; p < np; ++p) {
    const Polygon& polygon = scene.polygons[p];
    for (int i = 0; i < polygon.size(); ++i) {
      const EdgeKind kind = polygon.edges[static_cast<size_t>(i)].kind;
      if (kind == EdgeKind::glued || kind == EdgeKind::infinity) continue;
      ++boundary_edges;
      const int from = scene.corner_class[p][static_cast<size_t>(i)];
      const int to = scene.corner_class[p][static_cast<size_t>((i + 1) % polygon.size())];
      if (from >= 0 && to >= 0)  // a boundary ray links its finite end to nothing
        boundary.unite(static_cast<size_t>(from), static_cast<size_t>(to));
    }
  }
  t.boundary_components = 0;
  for (size_t c = 0; c < scene.vertex_classes.size(); ++c)
    if (scene.vertex_classes[c].boundary && boundary.find(c) == c) ++t.boundary_components;

  const int vertices = static_cast<int>(scene.vertex_classes.size());
  const int edges = static_cast<int>(scene.gluings.size()) + boundary_edges;
  t.infinite = false;
  for (const Polygon& polygon : scene.polygons) t.infinite = t.infinite || polygon.infinite();
  t.euler_characteristic.reset();
  t.genus.reset();
  if (t.infinite) return;  // no Euler characteristic, no genus
  t.euler_characteristic = vertices - edges + static_cast<int>(np);
  if (t.components == 1) {
    const int deficit = 2 - *t.euler_characteristic - t.boundary_components;
    t.genus = t.orientable ? deficit / 2 : deficit;
  }
}

}  // namespace flatmarch
