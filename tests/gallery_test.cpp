// Every gallery scene loads with the structure its surface has, worked out from the mathematics,
// and its camera shows something.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include "backends/oracle/oracle.hpp"
#include "output/image_io.hpp"
#include "scene/load.hpp"
#include "tests/gallery.hpp"
#include "tests/process.hpp"

namespace flatmarch {
namespace {

namespace fs = std::filesystem;

struct Surface {
  std::vector<double> cone_angles_over_pi;  // of the singular vertex classes, ascending
  std::optional<int> euler_characteristic;  // none for an infinite surface
  bool orientable;
  std::optional<int> genus;  // handles, or cross-caps when non-orientable
  int boundary_components;
  bool infinite = false;
};

// Translation surfaces of genus 2 with one cone point of 6 pi (Gauss-Bonnet: 2 pi - 6 pi =
// 2 pi chi); their prisms and marked versions have the same floor plan.
const Surface kGenus2{{6.0}, -2, true, 2, 0};
const Surface kTorus{{}, 0, true, 1, 0};
// Mirror rooms are disks (chi = 1, one boundary circle); every corner is a boundary class of
// its own whose angle is the corner's.
Surface mirror_room(std::vector<double> corners_over_pi) {
  std::sort(corners_over_pi.begin(), corners_over_pi.end());
  return {corners_over_pi, 1, true, 0, 1};
}

const std::map<std::string, Surface>& expected() {
  static const std::map<std::string, Surface> table = {
      {"torus", kTorus},
      {"torus_prism", kTorus},
      // Affine tori: corner angles still sum to 2 pi at the one vertex class.
      {"affine_torus", kTorus},
      {"affine_two_rooms", kTorus},
      {"l_shape", kGenus2},
      {"l_shape_prism", kGenus2},
      {"l_shape_singularities", kGenus2},
      {"double_pentagon", kGenus2},
      {"double_pentagon_prism", kGenus2},
      {"double_pentagon_singularities", kGenus2},
      // Eight corners of three right angles each: the sphere, 8 (2 pi - 3 pi / 2) = 4 pi.
      {"cube", {std::vector<double>(8, 1.5), 2, true, 0, 0}},
      // Four corners of angle pi: the sphere again.
      {"pillowcase", {std::vector<double>(4, 1.0), 2, true, 0, 0}},
      // One regular point, chi = 1 - 2 + 1, two cross-caps.
      {"klein_bottle", {{}, 0, false, 2, 0}},
      {"mirror_square", mirror_room({0.5, 0.5, 0.5, 0.5})},
      {"mirror_pentagon", mirror_room({0.6, 0.6, 0.6, 0.6, 0.6})},
      // Two pentagons sharing an edge: the shared edge's ends have 2 x 3 pi / 5.
      {"mirror_double_pentagon", mirror_room({0.6, 0.6, 0.6, 0.6, 0.6, 0.6, 1.2, 1.2})},
      {"mirror_triangle_1rad", mirror_room({1.0 / kPi, 0.5, 0.5 - 1.0 / kPi})},
      {"mirror_triangle_30_60_90", mirror_room({1.0 / 6, 1.0 / 3, 0.5})},
      {"mirror_triangle_equilateral", mirror_room({1.0 / 3, 1.0 / 3, 1.0 / 3})},
      // Infinite surfaces (DESIGN.md section 1): a cone's one cone point has the angle of its
      // wedge, or of its two wedges; a cylinder's one vertex class is regular: two right angles
      // on the half-cylinder's wall (a boundary class of angle pi), four without one.
      {"cone_half_pi", {{0.5}, std::nullopt, true, std::nullopt, 0, true}},
      {"cone_pi", {{1.0}, std::nullopt, true, std::nullopt, 0, true}},
      {"cone_three_half_pi", {{1.5}, std::nullopt, true, std::nullopt, 0, true}},
      {"cone_three_pi", {{3.0}, std::nullopt, true, std::nullopt, 0, true}},
      {"half_cylinder", {{}, std::nullopt, true, std::nullopt, 1, true}},
      {"cylinder", {{}, std::nullopt, true, std::nullopt, 0, true}},
  };
  return table;
}

TEST(Gallery, HasEverySurfaceOfThePaperAndTheApp) {
  std::set<std::string> stems;
  for (const fs::path& f : test::gallery_files()) stems.insert(f.stem().string());
  for (const auto& [name, surface] : expected())
    EXPECT_TRUE(stems.count(name)) << name << " is missing";
}

// The affine scenes' side gluings, worked out by hand from DESIGN.md section 1 (g(A) = D,
// g(B) = C for edge a from A to B and edge b from C to D): the matrix as the file gives it (rows)
// and the translation that then takes A to D.
TEST(Gallery, AffineMapsAreTheMatricesGiven) {
  struct Want {
    const char* scene;
    int gluing;
    Mat2 linear;  // glm: columns
    Vec2 translation;
    GluingType type;
  };
  const Want wants[] = {
      // Right (3,0)-(3,3) to left (0,3)-(0,0): (x, y) -> (x, x/2 + y) + t, t = (0,0) - (3, 1.5).
      {"affine_torus", 1, Mat2(Vec2(1, 0.5), Vec2(0, 1)), {-3, -1.5}, GluingType::affine},
      // The square's right (1,0)-(1,1) to the long room's left (2,1)-(2,0): x2 in x, no shift.
      {"affine_two_rooms", 0, Mat2(Vec2(2, 0), Vec2(0, 1)), {0, 0}, GluingType::affine},
      // The long room's right (4,0)-(4,1) to the square's left (0,1)-(0,0): (2, 0) + t = (0, 0).
      {"affine_two_rooms", 1, Mat2(Vec2(0.5, 0), Vec2(0, 1)), {-2, 0}, GluingType::affine},
  };
  for (const Want& w : wants) {
    const Scene& s = test::gallery_scene(w.scene);
    const Gluing& g = s.gluings[static_cast<size_t>(w.gluing)];
    EXPECT_EQ(g.type, w.type) << w.scene;
    for (int c = 0; c < 2; ++c)
      for (int r = 0; r < 2; ++r) EXPECT_NEAR(g.g.linear[c][r], w.linear[c][r], 1e-12) << w.scene;
    EXPECT_NEAR(g.g.translation.x, w.translation.x, 1e-12) << w.scene;
    EXPECT_NEAR(g.g.translation.y, w.translation.y, 1e-12) << w.scene;
  }
}

// The infinite surfaces' gluings, by hand from DESIGN.md section 1: rays are glued with the
// finite end of one going to that of the other and the direction of one's ideal vertex to that
// of the other's. A cone's wedge from direction 0 to direction theta has its ray along 0 (edge
// 0) glued to its ray along theta (edge 2) by the rotation by theta about the apex.
TEST(Gallery, InfiniteSurfacesGlueTheirRaysByHand) {
  struct Want {
    const char* scene;
    int gluing;
    double rotation;  // radians
    Vec2 translation;
    GluingType type;
  };
  const Want wants[] = {
      {"cone_half_pi", 0, kPi / 2, {0, 0}, GluingType::rotation},
      {"cone_pi", 0, kPi, {0, 0}, GluingType::half_translation},
      {"cone_three_half_pi", 0, 3 * kPi / 2, {0, 0}, GluingType::rotation},
      // Wedge 0's ray along -y (edge 2) to wedge 1's ray along +x (edge 0): -y turns to +x by a
      // quarter turn; and wedge 1's to wedge 0's likewise.
      {"cone_three_pi", 0, kPi / 2, {0, 0}, GluingType::rotation},
      {"cone_three_pi", 1, kPi / 2, {0, 0}, GluingType::rotation},
      // The half-strip's right side (3,0) up to its left side coming down to (0,0): (3,0) goes to
      // (0,0), a translation by (-3, 0).
      {"half_cylinder", 0, 0, {-3, 0}, GluingType::translation},
      // The two half-strips share the base segment (0,0)-(3,0) as it lies: the identity.
      {"cylinder", 0, 0, {0, 0}, GluingType::translation},
      {"cylinder", 1, 0, {-3, 0}, GluingType::translation},
      // The lower half-strip's ray down from (0,0) to its ray up to (3,0): by (3, 0).
      {"cylinder", 2, 0, {3, 0}, GluingType::translation},
  };
  for (const Want& w : wants) {
    SCOPED_TRACE(std::string(w.scene) + " gluing " + std::to_string(w.gluing));
    const Scene& s = test::gallery_scene(w.scene);
    EXPECT_TRUE(s.topology.infinite);
    EXPECT_FALSE(s.topology.euler_characteristic.has_value());
    EXPECT_FALSE(s.topology.genus.has_value());
    const Gluing& g = s.gluings[static_cast<size_t>(w.gluing)];
    EXPECT_EQ(g.type, w.type);
    const Mat2 want(Vec2(std::cos(w.rotation), std::sin(w.rotation)),
                    Vec2(-std::sin(w.rotation), std::cos(w.rotation)));
    for (int c = 0; c < 2; ++c)
      for (int r = 0; r < 2; ++r) EXPECT_NEAR(g.g.linear[c][r], want[c][r], 1e-12);
    EXPECT_NEAR(g.g.translation.x, w.translation.x, 1e-12);
    EXPECT_NEAR(g.g.translation.y, w.translation.y, 1e-12);
  }
  // The finite scenes are not infinite.
  EXPECT_FALSE(test::gallery_scene("torus").topology.infinite);
}

class GalleryScene : public testing::TestWithParam<fs::path> {};

TEST_P(GalleryScene, HasTheStructureOfItsSurface) {
  const fs::path file = GetParam();
  const auto it = expected().find(file.stem().string());
  ASSERT_NE(it, expected().end()) << file << " has no entry in the table of surfaces";
  const Surface& want = it->second;
  const Scene s = load_scene(file);
  std::vector<double> angles;
  for (const VertexClass& vc : s.vertex_classes)
    if (vc.singular) angles.push_back(vc.cone_angle / kPi);
  std::sort(angles.begin(), angles.end());
  ASSERT_EQ(angles.size(), want.cone_angles_over_pi.size());
  for (size_t k = 0; k < angles.size(); ++k)
    EXPECT_NEAR(angles[k], want.cone_angles_over_pi[k], 1e-9);
  EXPECT_EQ(s.topology.euler_characteristic, want.euler_characteristic);
  EXPECT_EQ(s.topology.orientable, want.orientable);
  EXPECT_EQ(s.topology.genus, want.genus);
  EXPECT_EQ(s.topology.boundary_components, want.boundary_components);
  EXPECT_EQ(s.topology.infinite, want.infinite);
  EXPECT_FALSE(s.description.empty());
  // Each has the paper's test object.
  EXPECT_TRUE(std::any_of(s.objects.begin(), s.objects.end(),
                          [](const Object& o) { return o.type == ObjectType::hollow_cube; }));
}

TEST_P(GalleryScene, CameraShowsAnObjectAndMore) {
  const Scene s = load_scene(GetParam());
  const Frame f = OracleBackend().render(s, s.camera, 96, 54, {}, {});
  std::set<float> codes(f.hit.begin(), f.hit.end());
  EXPECT_GE(codes.size(), 2u) << "every pixel ends the same way";
  EXPECT_GE(*codes.rbegin(), 0.0f) << "no object in sight";
}

// What a person sees (issue 20): `flatmarch render` of the scene as a new user runs it (320x180,
// its default method, analytic), read back from the PNG. Its middle third of rows, where the
// horizon and the walls are, is neither washed out nor murky (mean luminance within 0.25-0.75 of
// white) and has contrast (standard deviation at least 0.08: walls, the horizon, objects), and
// no pixel is black: rays that failed are shaded as fog, and no scene of the gallery has a black
// surface. Luminance: Rec. 709 weights of the sRGB values, as an image viewer shows them.
TEST_P(GalleryScene, ReadsWellAsANewUserRendersIt) {
  const fs::path file = GetParam();
  if (!test::in_sanitized_sample(file))
    GTEST_SKIP() << "under the sanitizers, every " << test::kSanitizedStride
                 << "th scene (tests/gallery.hpp)";
  const std::string png = test::make_temp_dir() + "/reads_well_" + file.stem().string() + ".png";
  const auto r = test::run_flatmarch({"render", file.string(), "-o", png, "--size", "320x180"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("/analytic"), std::string::npos) << r.err;
  const Png image = read_png(png);
  ASSERT_EQ(image.width, 320);
  ASSERT_EQ(image.height, 180);
  double sum = 0.0, sum2 = 0.0;
  int n = 0, black = 0;
  for (int j = 0; j < image.height; ++j)
    for (int i = 0; i < image.width; ++i) {
      const uint8_t* p = &image.rgb[3 * (static_cast<size_t>(j) * 320 + static_cast<size_t>(i))];
      if (std::max({p[0], p[1], p[2]}) < 8) ++black;
      if (j < image.height / 3 || j >= 2 * image.height / 3) continue;
      const double y = (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0;
      sum += y;
      sum2 += y * y;
      ++n;
    }
  const double mean = sum / n, sd = std::sqrt(std::max(sum2 / n - mean * mean, 0.0));
  EXPECT_GE(mean, 0.25) << "the middle third is murky";
  EXPECT_LE(mean, 0.75) << "the middle third is washed out";
  EXPECT_GE(sd, 0.08) << "the middle third has no contrast (mean " << mean << ")";
  EXPECT_EQ(black, 0) << "black pixels";
}

INSTANTIATE_TEST_SUITE_P(Scenes, GalleryScene, testing::ValuesIn(test::gallery_files()),
                         [](const testing::TestParamInfo<fs::path>& p) {
                           return p.param.stem().string();
                         });

}  // namespace
}  // namespace flatmarch
