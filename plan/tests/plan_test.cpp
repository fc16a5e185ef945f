// Floor plans: well-formed SVG whose elements sit where the hand-computed layout puts them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "plan/floor_plan.hpp"
#include "scene/load.hpp"
#include "tests/process.hpp"
#include "tests/test_scenes.hpp"

namespace flatmarch {
namespace {

// Every element is closed in order and every attribute value is quoted.
bool well_formed(const std::string& svg) {
  std::vector<std::string> open;
  const std::regex tag(R"(<(/?)([a-zA-Z]+)((?:\s+[a-zA-Z0-9:-]+="[^"<]*")*)\s*(/?)>)");
  size_t pos = svg.find("?>");  // after the XML declaration
  if (svg.rfind("<?xml", 0) != 0 || pos == std::string::npos) return false;
  pos += 2;
  for (std::sregex_iterator it(svg.begin() + static_cast<long>(pos), svg.end(), tag), end;
       it != end; ++it) {
    const std::smatch& m = *it;
    // Only text may lie between tags.
    const std::string before = m.prefix().str();
    if (before.find('<') != std::string::npos || before.find('>') != std::string::npos)
      return false;
    if (!m[1].str().empty()) {
      if (open.empty() || open.back() != m[2].str()) return false;
      open.pop_back();
    } else if (m[4].str().empty()) {
      open.push_back(m[2].str());
    }
  }
  return open.empty();
}

struct Element {
  std::string name;
  std::map<std::string, std::string> attributes;
  std::string text;
  double number(const std::string& key) const { return std::stod(attributes.at(key)); }
};

// The elements of the given class (the whole class attribute).
std::vector<Element> elements(const std::string& svg, const std::string& cls) {
  std::vector<Element> out;
  const std::regex tag(R"(<([a-z]+) class=")" + cls + R"("([^>]*?)/?>(?:([^<]*)</[a-z]+>)?)");
  const std::regex attribute(R"(([a-z0-9-]+)="([^"]*)\")");
  for (std::sregex_iterator it(svg.begin(), svg.end(), tag), end; it != end; ++it) {
    Element e{(*it)[1].str(), {}, (*it)[3].str()};
    const std::string attrs = (*it)[2].str();
    for (std::sregex_iterator a(attrs.begin(), attrs.end(), attribute); a != end; ++a)
      e.attributes[(*a)[1]] = (*a)[2];
    out.push_back(e);
  }
  return out;
}

// The torus [0,4]^2 in an 800 pixel wide plan: a margin of 0.06 * 4 = 0.24, so 4.48 units span
// 800 pixels (178.571 a unit) below a 56 pixel title: (x, y) -> (178.571 (x + 0.24),
// 56 + 178.571 (4.24 - y)).
Vec2 torus_pixels(Vec2 p) {
  return {800.0 / 4.48 * (p.x + 0.24), 56.0 + 800.0 / 4.48 * (4.24 - p.y)};
}

TEST(FloorPlan, TorusLayoutObjectsAndRay) {
  const Scene s = parse_scene(
      test::torus_json(R"("objects": [{"type": "sphere", "center": [2, 2, 1], "radius": 0.5}])"),
      "torus.json");
  PlanOptions options;
  options.ray = Ray{0, {1, 1, 1}, glm::normalize(Vec3(3, 1, 0))};
  options.max_events = 3;
  const std::string svg = floor_plan_svg(s, options);
  ASSERT_TRUE(well_formed(svg)) << svg;

  const auto objects = elements(svg, "object");
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_NEAR(objects[0].number("cx"), 400.0, 0.01);
  EXPECT_NEAR(objects[0].number("cy"), 456.0, 0.01);
  EXPECT_NEAR(objects[0].number("r"), 0.5 * 800.0 / 4.48, 0.01);

  // The ray from (1, 1) along (3, 1) leaves through the right edge at (4, 2), comes back in at
  // (0, 2), leaves again at (4, 10/3) and comes in at (0, 10/3): three segments drawn.
  const auto ray = elements(svg, "ray");
  ASSERT_EQ(ray.size(), 3u);
  const Vec2 ends[][2] = {{{1, 1}, {4, 2}}, {{0, 2}, {4, 10.0 / 3}}, {{0, 10.0 / 3}, {2, 4}}};
  for (size_t k = 0; k < 3; ++k) {
    const Vec2 a = torus_pixels(ends[k][0]), b = torus_pixels(ends[k][1]);
    EXPECT_NEAR(ray[k].number("x1"), a.x, 0.01) << k;
    EXPECT_NEAR(ray[k].number("y1"), a.y, 0.01) << k;
    EXPECT_NEAR(ray[k].number("x2"), b.x, 0.01) << k;
    EXPECT_NEAR(ray[k].number("y2"), b.y, 0.01) << k;
  }
  // No cone points on the torus: its one vertex class is regular.
  EXPECT_TRUE(elements(svg, "cone-angle").empty());
  EXPECT_EQ(elements(svg, "vertex").size(), 4u);
}

TEST(FloorPlan, GluedEdgesShareAColourPerGluing) {
  const Scene s = load_scene(FLATMARCH_SOURCE_DIR "/scenes/double_pentagon.json");
  const std::string svg = floor_plan_svg(s, {});
  ASSERT_TRUE(well_formed(svg));
  std::map<std::string, std::vector<std::string>> colours;  // gluing -> strokes of its edges
  for (const Element& e : elements(svg, "edge glued"))
    colours[e.attributes.at("data-gluing")].push_back(e.attributes.at("stroke"));
  ASSERT_EQ(colours.size(), 5u);
  std::set<std::string> distinct;
  for (const auto& [gluing, strokes] : colours) {
    ASSERT_EQ(strokes.size(), 2u) << gluing;
    EXPECT_EQ(strokes[0], strokes[1]) << gluing;
    distinct.insert(strokes[0]);
  }
  EXPECT_EQ(distinct.size(), 5u);
  // An arrow on each glued edge.
  EXPECT_EQ(elements(svg, "arrow").size(), 10u);
}

TEST(FloorPlan, LShapeLabelsItsOneConePointAtEveryCorner) {
  const Scene s = load_scene(FLATMARCH_SOURCE_DIR "/scenes/l_shape.json");
  const std::string svg = floor_plan_svg(s, {});
  const auto labels = elements(svg, "cone-angle");
  ASSERT_EQ(labels.size(), 8u);
  for (const Element& e : labels) {
    EXPECT_EQ(e.text, "6π");
    EXPECT_EQ(e.attributes.at("data-class"), labels[0].attributes.at("data-class"));
  }
}

TEST(FloorPlan, MirrorsWallsAndMarkers) {
  // A mirror triangle with one wall and markers at every vertex: each corner is its own class.
  const Scene s = parse_scene(R"({"polygons": [[[0, 0], [4, 0], [0, 3]]],
      "boundaries": [{"edge": [0, 1], "boundary": "wall"}], "vertices": {"radius": 0.2}})",
                              "triangle.json");
  const std::string svg = floor_plan_svg(s, {});
  ASSERT_TRUE(well_formed(svg));
  EXPECT_EQ(elements(svg, "edge mirror").size(), 2u);
  EXPECT_EQ(elements(svg, "edge wall").size(), 1u);
  EXPECT_EQ(elements(svg, "marker").size(), 3u);
  // Corner angles: the right angle pi/2 and atan(4/3), atan(3/4) in radians.
  std::multiset<std::string> angles;
  for (const Element& e : elements(svg, "cone-angle")) angles.insert(e.text);
  EXPECT_EQ(angles, (std::multiset<std::string>{"π/2", "0.6435 rad", "0.9273 rad"}));
}

TEST(FloorPlan, UnboundedPolygonsAreCutOffBeyondTheObjectsAndTheCamera) {
  // cone_half_pi: the quarter-plane wedge with a hollow cube (half-size 0.35) at (2, 1.2) and
  // the camera at (3.2, 0.9). The farthest of them from the origin is the cube's footprint,
  // |(2, 1.2)| + 0.35 sqrt 2; the plan cuts the wedge's rays off a quarter beyond it.
  const Scene s = load_scene(FLATMARCH_SOURCE_DIR "/scenes/cone_half_pi.json");
  const double radius =
      1.25 * std::max(std::hypot(2.0, 1.2) + 0.35 * std::sqrt(2.0), std::hypot(3.2, 0.9));
  EXPECT_NEAR(plan_radius(s), radius, 1e-12);
  const std::string svg = floor_plan_svg(s, {});
  ASSERT_TRUE(well_formed(svg));
  // Two glued rays drawn (from the apex out to the radius), the edge at infinity not at all.
  const auto glued = elements(svg, "edge glued");
  ASSERT_EQ(glued.size(), 2u);
  const PlanLayout layout(s, 800.0);
  const Vec2 apex = layout.to_pixels({0, 0});
  for (const Element& e : glued) {
    const Vec2 a(e.number("x1"), e.number("y1")), b(e.number("x2"), e.number("y2"));
    EXPECT_NEAR(std::min(glm::length(a - apex), glm::length(b - apex)), 0.0, 0.01);  // pixels
    EXPECT_NEAR(std::max(glm::length(a - apex), glm::length(b - apex)), layout.to_pixels(radius),
                0.01);
  }
  // The apex is the one cone point, of angle pi/2.
  const auto labels = elements(svg, "cone-angle");
  ASSERT_EQ(labels.size(), 1u);
  EXPECT_EQ(labels[0].text, "π/2");
  // The picture spans the cut-off wedge: radius plus the 6% margin on each side.
  EXPECT_NEAR(layout.width(), 800.0, 1e-9);
  EXPECT_NEAR(layout.to_pixels(radius), 800.0 / 1.12, 1e-6);
}

TEST(FloorPlanCli, WritesThePlanAndChecksItsArguments) {
  const std::string dir = test::make_temp_dir();
  const std::string out = dir + "/l.svg";
  auto r = test::run_flatmarch({"plan", FLATMARCH_SOURCE_DIR "/scenes/l_shape.json", "-o", out,
                                "--from", "3.2,0.5,1", "--dir", "1,0.37,0"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(out);
  std::stringstream svg;
  svg << in.rdbuf();
  EXPECT_TRUE(well_formed(svg.str()));
  EXPECT_FALSE(elements(svg.str(), "ray").empty());
  r = test::run_flatmarch(
      {"plan", FLATMARCH_SOURCE_DIR "/scenes/l_shape.json", "-o", out, "--from", "3.2,0.5,1"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--dir"), std::string::npos) << r.err;
  r = test::run_flatmarch({"plan", FLATMARCH_SOURCE_DIR "/scenes/l_shape.json", "-o", out, "--from",
                           "3,3,1", "--dir", "1,0,0"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("not strictly inside polygon 0"), std::string::npos) << r.err;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace flatmarch
