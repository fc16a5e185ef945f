// The scene model against hand-computed gluing maps, vertex classes, cone angles and topology.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scene/load.hpp"
#include "tests/test_scenes.hpp"

namespace flatmarch {
namespace {

constexpr double kTol = 1e-12;

void expect_near(Vec2 a, Vec2 b, double tol = kTol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
}

Scene load(const std::string& json) {
  return parse_scene(json, "test.json");
}

// The cone angles of the singular classes, in units of pi, sorted.
std::vector<double> singular_angles_over_pi(const Scene& s) {
  std::vector<double> angles;
  for (const VertexClass& vc : s.vertex_classes)
    if (vc.singular) angles.push_back(vc.cone_angle / kPi);
  std::sort(angles.begin(), angles.end());
  return angles;
}

TEST(GluingMap, TorusTranslations) {
  const Scene s = load(test::torus_json());
  ASSERT_EQ(s.gluings.size(), 2u);
  // Edge 0 runs A=(0,0) -> B=(4,0), edge 2 C=(4,4) -> D=(0,4): g(A) = D, g(B) = C.
  const Gluing& bottom_top = s.gluings[0];
  EXPECT_EQ(bottom_top.type, GluingType::translation);
  expect_near(bottom_top.g.apply({0, 0}), {0, 4});
  expect_near(bottom_top.g.apply({4, 0}), {4, 4});
  // A ray leaving through the bottom at (1, -0.1) continues from just below the top.
  expect_near(s.edge({0, 0}).map.apply({1, -0.1}), {1, 3.9});
  // The other direction uses the inverse map.
  expect_near(s.edge({0, 2}).map.apply({1, 4.1}), {1, 0.1});
  EXPECT_EQ(s.edge({0, 2}).to, (EdgeRef{0, 0}));
  // Edge 1 (4,0)->(4,4) to edge 3 (0,4)->(0,0): translation by (-4, 0).
  expect_near(s.edge({0, 1}).map.translation, {-4, 0});
  // Outward normals of the counterclockwise square.
  expect_near(s.edge({0, 0}).normal, {0, -1});
  expect_near(s.edge({0, 1}).normal, {1, 0});
}

// The pillowcase: two squares A = [0,2]^2 and B = [3,5]x[0,2] glued along all four edges.
constexpr const char* kPillowcase =
    R"({"polygons": [[[0, 0], [2, 0], [2, 2], [0, 2]], [[3, 0], [5, 0], [5, 2], [3, 2]]],
    "gluings": [[[0, 1], [1, 3]], [[0, 3], [1, 1]], [[0, 0], [1, 0]], [[0, 2], [1, 2]]]})";

TEST(GluingMap, HalfTranslation) {
  const Scene s = load(kPillowcase);
  // Bottoms: A=(0,0) -> D=(5,0), B=(2,0) -> C=(3,0): the linear part takes (2,0) to (-2,0), so
  // g(x, y) = (5 - x, -y), a half-translation.
  const Gluing& bottoms = s.gluings[2];
  EXPECT_EQ(bottoms.type, GluingType::half_translation);
  expect_near(bottoms.g.apply({1, -0.1}), {4, 0.1});
  // Tops: A=(2,2) -> D=(3,2), B=(0,2) -> C=(5,2): g(x, y) = (5 - x, 4 - y).
  expect_near(s.gluings[3].g.apply({1, 2.1}), {4, 1.9});
  // Right of A to left of B: (2,0) -> (3,0), a translation by (1, 0).
  EXPECT_EQ(s.gluings[0].type, GluingType::translation);
  expect_near(s.gluings[0].g.translation, {1, 0});
}

TEST(GluingMap, CubeRotations) {
  const Scene s = load(test::cube_json());
  // Top face's right edge A=(1,1)->B=(1,2) to the right face's top C=(2,1)->D=(1,1):
  // (0,1) turns into (1,0), a rotation by -90 degrees: g(x, y) = (y, -x) + (0, 2).
  const Gluing& g = s.gluings[6];
  EXPECT_EQ(g.type, GluingType::rotation);
  expect_near(g.g.apply({1, 1.5}), {1.5, 1});
  expect_near(g.g.apply_direction({1, 0}), {0, -1});
  // Top face's left edge (0,2)->(0,1) to the left face's top (0,1)->(-1,1): +90 degrees.
  expect_near(s.gluings[7].g.apply_direction({1, 0}), {0, 1});
  // Top face's far edge to the back face's top: a half turn.
  EXPECT_EQ(s.gluings[8].type, GluingType::half_translation);
  // Net neighbours: the zero translation.
  EXPECT_EQ(s.gluings[0].type, GluingType::translation);
  expect_near(s.gluings[0].g.translation, {0, 0});
}

// The Klein bottle: the torus square with its bottom glued to its top by a reflection.
constexpr const char* kKleinBottle = R"({"polygons": [[[0, 0], [4, 0], [4, 4], [0, 4]]],
    "gluings": [{"edges": [[0, 0], [0, 2]], "map": "reflection"}, [[0, 1], [0, 3]]]})";

TEST(GluingMap, ReflectionIsAGlideReflection) {
  const Scene s = load(kKleinBottle);
  // A=(0,0) -> C=(4,4), B=(4,0) -> D=(0,4): g(x, y) = (4 - x, y + 4).
  const Gluing& g = s.gluings[0];
  EXPECT_EQ(g.type, GluingType::reflection);
  expect_near(g.g.apply({1, -0.1}), {3, 3.9});
  EXPECT_NEAR(g.g.determinant(), -1.0, kTol);
}

TEST(GluingMap, ExplicitMatrices) {
  // The Klein bottle's reflection written as a matrix (det < 0: A -> C, B -> D).
  const Scene klein = load(R"({"polygons": [[[0, 0], [4, 0], [4, 4], [0, 4]]],
      "gluings": [{"edges": [[0, 0], [0, 2]], "matrix": [[-1, 0], [0, 1]]}, [[0, 1], [0, 3]]]})");
  expect_near(klein.gluings[0].g.apply({1, -0.1}), {3, 3.9});
  EXPECT_EQ(klein.gluings[0].type, GluingType::reflection);
  // A horizontal stretch (det > 0: A -> D, B -> C) from the unit square's right edge to the left
  // edge of [2,4]x[0,1]: g(x, y) = (2x, y), neither an isometry nor a similarity.
  const Scene stretch =
      load(R"({"polygons": [[[0, 0], [1, 0], [1, 1], [0, 1]], [[2, 0], [4, 0], [4, 1], [2, 1]]],
      "gluings": [{"edges": [[0, 1], [1, 3]], "matrix": [[2, 0], [0, 1]]}]})");
  EXPECT_EQ(stretch.gluings[0].type, GluingType::affine);
  expect_near(stretch.gluings[0].g.apply({1.1, 0.5}), {2.2, 0.5});
  expect_near(stretch.edge({1, 3}).map.apply({1.9, 0.5}), {0.95, 0.5});
}

TEST(GluingMap, Similarity) {
  // The unit square's right edge A=(1,0)->B=(1,1) to the left edge C=(2,2)->D=(2,0) of [2,4]^2:
  // scale |D - C| / |B - A| = 2, no rotation, g(A) = D: g(x, y) = 2 (x, y).
  const Scene s =
      load(R"({"polygons": [[[0, 0], [1, 0], [1, 1], [0, 1]], [[2, 0], [4, 0], [4, 2], [2, 2]]],
      "gluings": [{"edges": [[0, 1], [1, 3]], "map": "similarity"}]})");
  EXPECT_EQ(s.gluings[0].type, GluingType::similarity);
  expect_near(s.gluings[0].g.apply({1.1, 0.5}), {2.2, 1.0});
}

TEST(VertexClasses, Torus) {
  const Scene s = load(test::torus_json());
  ASSERT_EQ(s.vertex_classes.size(), 1u);
  EXPECT_EQ(s.vertex_classes[0].corners.size(), 4u);
  EXPECT_NEAR(s.vertex_classes[0].cone_angle, 2 * kPi, 1e-12);
  EXPECT_FALSE(s.vertex_classes[0].singular);
  EXPECT_EQ(s.topology.euler_characteristic, 0);
  EXPECT_TRUE(s.topology.orientable);
  EXPECT_EQ(s.topology.genus, 1);
  EXPECT_EQ(s.topology.boundary_components, 0);
}

TEST(VertexClasses, LShapeHasOneConePointOf6Pi) {
  // Corners: 5 right angles, the reflex corner (3 pi / 2) and two straight ones (pi):
  // 5 pi/2 + 3 pi/2 + 2 pi = 6 pi, all one point; chi = 1 - 4 + 1 = -2, genus 2.
  const Scene s = load_scene(FLATMARCH_SOURCE_DIR "/scenes/l_shape.json");
  ASSERT_EQ(s.vertex_classes.size(), 1u);
  EXPECT_EQ(s.vertex_classes[0].corners.size(), 8u);
  EXPECT_EQ(singular_angles_over_pi(s), std::vector<double>({6.0}));
  EXPECT_EQ(s.topology.euler_characteristic, -2);
  EXPECT_EQ(s.topology.genus, 2);
}

TEST(VertexClasses, DoublePentagonHasOneConePointOf6Pi) {
  // Ten corners of 3 pi / 5 make 6 pi; chi = 1 - 5 + 2 = -2.
  const Scene s = load_scene(FLATMARCH_SOURCE_DIR "/scenes/double_pentagon.json");
  ASSERT_EQ(s.vertex_classes.size(), 1u);
  EXPECT_NEAR(s.vertex_classes[0].cone_angle, 6 * kPi, 1e-9);
  EXPECT_EQ(s.topology.genus, 2);
}

TEST(VertexClasses, CubeHasEightConePointsOf3PiOver2) {
  const Scene s = load(test::cube_json());
  ASSERT_EQ(s.vertex_classes.size(), 8u);
  for (const VertexClass& vc : s.vertex_classes) {
    EXPECT_EQ(vc.corners.size(), 3u);
    EXPECT_NEAR(vc.cone_angle, 1.5 * kPi, 1e-12);
    EXPECT_TRUE(vc.singular);
  }
  // The cube's corner at (1,1) of the centre face is also corner 3 of the right face and corner
  // 1 of the top face.
  const int c = s.corner_class[0][2];
  EXPECT_EQ(s.corner_class[1][3], c);
  EXPECT_EQ(s.corner_class[4][1], c);
  // chi = 8 - 12 + 6 = 2: the sphere.
  EXPECT_EQ(s.topology.euler_characteristic, 2);
  EXPECT_TRUE(s.topology.orientable);
  EXPECT_EQ(s.topology.genus, 0);
}

TEST(VertexClasses, PillowcaseHasFourConePointsOfPi) {
  const Scene s = load(kPillowcase);
  EXPECT_EQ(singular_angles_over_pi(s), std::vector<double>({1.0, 1.0, 1.0, 1.0}));
  // A's corner (0,0) goes with B's (5,0) under the bottoms' half turn.
  EXPECT_EQ(s.corner_class[0][0], s.corner_class[1][1]);
  EXPECT_EQ(s.topology.euler_characteristic, 2);
  EXPECT_EQ(s.topology.genus, 0);
}

TEST(VertexClasses, KleinBottle) {
  // All four corners are one point of angle 2 pi; chi = 1 - 2 + 1 = 0, two cross-caps.
  const Scene s = load(kKleinBottle);
  ASSERT_EQ(s.vertex_classes.size(), 1u);
  EXPECT_NEAR(s.vertex_classes[0].cone_angle, 2 * kPi, 1e-12);
  EXPECT_EQ(s.topology.euler_characteristic, 0);
  EXPECT_FALSE(s.topology.orientable);
  EXPECT_EQ(s.topology.genus, 2);
}

TEST(VertexClasses, MirrorTriangleWithAnAngleOfOneRadian) {
  // Right angle at (1, 0); the angle at the origin is atan(tan 1) = 1 radian.
  const std::string json =
      R"({"polygons": [[[0, 0], [1, 0], [1, )" + std::to_string(std::tan(1.0)) + R"(]]]})";
  const Scene s = load(json);
  ASSERT_EQ(s.vertex_classes.size(), 3u);
  EXPECT_NEAR(s.vertex_classes[s.corner_class[0][0]].cone_angle, 1.0, 1e-6);
  EXPECT_NEAR(s.vertex_classes[s.corner_class[0][1]].cone_angle, kPi / 2, 1e-12);
  EXPECT_NEAR(s.vertex_classes[s.corner_class[0][2]].cone_angle, kPi / 2 - 1.0, 1e-6);
  for (const VertexClass& vc : s.vertex_classes) {
    EXPECT_TRUE(vc.boundary);
    EXPECT_TRUE(vc.singular);  // a boundary corner is regular only when straight
  }
  // A disk: chi = 3 - 3 + 1 = 1 with one boundary component.
  EXPECT_EQ(s.topology.euler_characteristic, 1);
  EXPECT_EQ(s.topology.boundary_components, 1);
  EXPECT_EQ(s.topology.genus, 0);
  for (const Polygon& p : s.polygons)
    for (const Edge& e : p.edges) EXPECT_EQ(e.kind, EdgeKind::mirror);
}

TEST(VertexClasses, StraightBoundaryPointIsRegular) {
  // A mirror rectangle with a vertex in the middle of its bottom: that corner is straight (pi).
  const Scene s =
      load(R"({"polygons": [[[0, 0], [1, 0], [2, 0], [2, 1], [0, 1]]], "boundary": "wall"})");
  EXPECT_FALSE(s.vertex_classes[s.corner_class[0][1]].singular);
  EXPECT_TRUE(s.vertex_classes[s.corner_class[0][0]].singular);
  EXPECT_EQ(s.edge({0, 3}).kind, EdgeKind::wall);
}

TEST(VertexClasses, SquareWithOneWall) {
  // A torus whose left/right gluing is replaced by a wall on the left and a mirror on the right:
  // a cylinder (annulus) with two boundary circles; chi = 2 - 3 + 1 = 0.
  const Scene s =
      load(R"({"polygons": [[[0, 0], [4, 0], [4, 4], [0, 4]]], "gluings": [[[0, 0], [0, 2]]],
      "boundaries": [{"edge": [0, 3], "boundary": "wall"}]})");
  EXPECT_EQ(s.edge({0, 3}).kind, EdgeKind::wall);
  EXPECT_EQ(s.edge({0, 1}).kind, EdgeKind::mirror);
  EXPECT_EQ(s.vertex_classes.size(), 2u);
  EXPECT_EQ(s.topology.euler_characteristic, 0);
  EXPECT_EQ(s.topology.boundary_components, 2);
  EXPECT_EQ(s.topology.genus, 0);
}

TEST(Polygon, NonConvexL) {
  const Scene s = load_scene(FLATMARCH_SOURCE_DIR "/scenes/l_shape.json");
  const Polygon& l = s.polygons[0];
  EXPECT_TRUE(l.contains({1, 3}));
  EXPECT_FALSE(l.contains({3, 3}));  // the missing square
  EXPECT_FALSE(l.contains({2, 1}, 1.5));
  EXPECT_TRUE(l.contains({1, 1}, 0.9));
  EXPECT_NEAR(l.corner_angle(4), 1.5 * kPi, 1e-12);  // the reflex corner (2,2)
  EXPECT_NEAR(l.corner_angle(1), kPi, 1e-12);        // straight (2,0)
  // Three 2x2 squares with centres (1,1), (3,1), (1,3): the centroid is their mean.
  expect_near(l.centroid(), {5.0 / 3.0, 5.0 / 3.0});
  EXPECT_NEAR(l.area(), 12.0, 1e-12);
  // (2.5, 2.5) lies in the missing square, 0.5 above the edge (4,2)-(2,2).
  EXPECT_NEAR(l.distance_to_boundary({2.5, 2.5}), 0.5, 1e-12);
}

TEST(Polygon, UnboundedWedgeOfThreeQuarterTurns) {
  // The non-convex wedge from the ray along +x counterclockwise to the ray along -y: every point
  // but the quarter x > 0, y < 0.
  const Scene s = load(R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, -1]}]]})");
  const Polygon& w = s.polygons[0];
  EXPECT_TRUE(w.infinite());
  EXPECT_TRUE(w.is_ideal(1) && w.is_ideal(2) && !w.is_ideal(0));
  EXPECT_EQ(w.edges[0].shape, EdgeShape::ray_out);
  EXPECT_EQ(w.edges[1].shape, EdgeShape::at_infinity);
  EXPECT_EQ(w.edges[1].kind, EdgeKind::infinity);
  EXPECT_EQ(w.edges[2].shape, EdgeShape::ray_in);
  expect_near(w.edges[0].normal, {0, -1});  // outward: below the ray along +x
  expect_near(w.edges[2].normal, {1, 0});   // right of the ray coming up the -y axis
  EXPECT_NEAR(w.corner_angle(0), 1.5 * kPi, 1e-12);
  EXPECT_TRUE(std::isinf(w.area()));
  EXPECT_TRUE(w.contains({1, 1}));
  EXPECT_TRUE(w.contains({-1e6, -1e6}));
  EXPECT_TRUE(w.contains({1e6, 1e-3}));
  EXPECT_FALSE(w.contains({1, -1}));
  EXPECT_FALSE(w.contains({1e6, -1e-3}));
  EXPECT_TRUE(w.contains(w.centroid()));
  // Distances to half-lines: beyond the apex a ray's nearest point is the apex.
  EXPECT_NEAR(w.distance_to_boundary({5, 2}), 2.0, 1e-12);
  EXPECT_NEAR(w.distance_to_boundary({-3, 4}), 5.0, 1e-12);
  EXPECT_NEAR(w.distance_to_boundary({-2, -7}), 2.0, 1e-12);
  // A path leaves through a ray, never through the edge at infinity.
  const Polygon::Exit down = w.exit({5, 2}, {0, -1}, 1e-9, 1e-9);
  EXPECT_EQ(down.edge, 0);
  EXPECT_NEAR(down.s, 2.0, 1e-12);
  const Polygon::Exit away = w.exit({5, 2}, {1, 1}, 1e-9, 1e-9);
  EXPECT_EQ(away.edge, -1);
  EXPECT_TRUE(std::isinf(away.s));
  // Cut off at radius 10: the apex, (10, 0), an arc about the apex at least every 45 degrees,
  // and (0, -10).
  const std::vector<Vec2> outline = w.outline(10.0);
  ASSERT_EQ(outline.size(), 1u + 7u);
  expect_near(outline[1], {10, 0});
  expect_near(outline[3], {0, 10});
  expect_near(outline[5], {-10, 0});
  expect_near(outline.back(), {0, -10});
}

TEST(Polygon, HalfStripWithOneIdealVertex) {
  // One ideal vertex: the two rays beside it run the same way, and there is no edge at
  // infinity. The half-strip 0 < x < 1, y > 0.
  const Scene s = load(R"({"polygons": [[[0, 0], [1, 0], {"to": [0, 1]}]]})");
  const Polygon& h = s.polygons[0];
  EXPECT_EQ(h.edges[1].shape, EdgeShape::ray_out);
  EXPECT_EQ(h.edges[2].shape, EdgeShape::ray_in);
  EXPECT_NEAR(h.corner_angle(0), kPi / 2, 1e-12);
  EXPECT_NEAR(h.corner_angle(1), kPi / 2, 1e-12);
  EXPECT_TRUE(h.contains({0.5, 1e5}));
  EXPECT_FALSE(h.contains({1.5, 1e5}));
  EXPECT_FALSE(h.contains({0.5, -0.1}));
  expect_near(h.centroid(), {0.5, 1.0});
  // Two mirrors running to infinity and the base: one boundary, no Euler characteristic.
  EXPECT_TRUE(s.topology.infinite);
  EXPECT_FALSE(s.topology.euler_characteristic);
  EXPECT_EQ(s.topology.boundary_components, 1);
}

TEST(GluingMap, RaysGluedByAReflection) {
  // Two wedges of a right angle glued along their rays along +x, which both run out to
  // infinity: "map": "reflection" takes (0,0) to (0,0) and +x to +x, the reflection in the
  // x-axis.
  const Scene s = load(R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, 1]}],
                                        [[0, 0], {"to": [1, 0]}, {"to": [0, 1]}]],
                           "gluings": [{"edges": [[0, 0], [1, 0]], "map": "reflection"}]})");
  const Gluing& g = s.gluings[0];
  EXPECT_EQ(g.type, GluingType::reflection);
  EXPECT_NEAR(g.g.linear[0][0], 1.0, 1e-12);
  EXPECT_NEAR(g.g.linear[1][1], -1.0, 1e-12);
  EXPECT_NEAR(glm::length(g.g.translation), 0.0, 1e-12);
  // A reversing gluing between two rooms leaves them orientable, as one piece.
  EXPECT_TRUE(s.topology.orientable);
  EXPECT_EQ(s.topology.components, 1);
}

TEST(VertexClasses, InfiniteSeedScenes) {
  // tests/data/infinite: a mirror wedge of pi/3 is a boundary cone point of its corner angle;
  // two quarter-planes glued along their rays by a reflection share their apex, pi in all, on
  // their walls: a regular boundary point.
  const std::string dir = FLATMARCH_SOURCE_DIR "/tests/data/infinite/";
  const Scene wedge = load_scene(dir + "mirror_wedge.json");
  ASSERT_EQ(wedge.vertex_classes.size(), 1u);
  EXPECT_NEAR(wedge.vertex_classes[0].cone_angle, kPi / 3, 1e-12);
  EXPECT_TRUE(wedge.vertex_classes[0].boundary && wedge.vertex_classes[0].singular);
  const Scene glued = load_scene(dir + "rays_glued_by_reflection.json");
  ASSERT_EQ(glued.vertex_classes.size(), 1u);
  EXPECT_NEAR(glued.vertex_classes[0].cone_angle, kPi, 1e-12);
  EXPECT_FALSE(glued.vertex_classes[0].singular);
  const Scene strip = load_scene(dir + "strip_one_ideal_vertex.json");
  EXPECT_EQ(strip.gluings[0].type, GluingType::translation);
  EXPECT_NEAR(strip.gluings[0].g.translation.x, -2.0, 1e-12);
}

TEST(Objects, FootprintsAndDefaults) {
  const Scene s = load(test::torus_json(R"("objects": [
      {"type": "hollow_cube", "center": [1, 1, 1], "size": 0.2},
      {"type": "cylinder", "center": [3, 3, 0], "radius": 0.1},
      {"type": "box", "center": [1, 3, 1], "half": [0.3, 0.4, 0.1]}])"));
  EXPECT_NEAR(s.objects[0].hole, 0.26, 1e-15);  // 1.3 x size by default
  EXPECT_NEAR(s.objects[0].footprint_radius(), 0.2 * std::sqrt(2.0), 1e-15);
  EXPECT_EQ(s.objects[1].z0, 0.0);  // the wall band by default
  EXPECT_EQ(s.objects[1].z1, 2.0);
  EXPECT_NEAR(s.objects[2].footprint_radius(), 0.5, 1e-15);
  // The default camera: polygon 0's centroid at half the height.
  EXPECT_EQ(s.camera.position, Vec3(2, 2, 1));
}

TEST(Markers, OneCylinderPerMarkedClass) {
  const Scene l = parse_scene(
      R"({"polygons": [[[0, 0], [2, 0], [4, 0], [4, 2], [2, 2], [2, 4], [0, 4], [0, 2]]],
      "gluings": [[[0, 0], [0, 5]], [[0, 1], [0, 3]], [[0, 2], [0, 7]], [[0, 4], [0, 6]]],
      "objects": [{"type": "sphere", "center": [1, 1, 1], "radius": 0.1}],
      "singularities": {"radius": 0.25}})",
      "l.json");
  ASSERT_EQ(l.markers.size(), 1u);
  EXPECT_EQ(l.markers[0].radius, 0.25);
  for (int v = 0; v < 8; ++v) EXPECT_EQ(l.marker_at(0, v), 0);
  // The torus has no singular point, so "singularities" marks nothing and "vertices" marks it.
  EXPECT_TRUE(load(test::torus_json(R"("singularities": {"radius": 0.2})")).markers.empty());
  EXPECT_EQ(load(test::torus_json(R"("vertices": {"radius": 0.2})")).markers.size(), 1u);
}

}  // namespace
}  // namespace flatmarch
