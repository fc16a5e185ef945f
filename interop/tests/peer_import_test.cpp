// import-peer: the original app's geometries convert into scenes that load, with the cone angles
// computed by hand, and the report names the fields that disagree with the derived maps.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "interop/peer_import.hpp"
#include "scene/load.hpp"
#include "tests/process.hpp"

namespace flatmarch {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using nlohmann::ordered_json;

const fs::path kPeerDir = fs::path(FLATMARCH_SOURCE_DIR) / "tests" / "data" / "peer-geometries";

PeerImport import_named(const std::string& name) {
  return import_peer_file(kPeerDir / (name + ".json"));
}

Scene load(const PeerImport& result) {
  return scene_from_json(json(result.scene), "converted.json");
}

std::vector<double> sorted_cone_angles(const Scene& scene) {
  std::vector<double> angles;
  for (const VertexClass& vc : scene.vertex_classes) angles.push_back(vc.cone_angle);
  std::sort(angles.begin(), angles.end());
  return angles;
}

void expect_cone_angles(const std::string& name, std::vector<double> expected, bool singular) {
  SCOPED_TRACE(name);
  const Scene scene = load(import_named(name));
  std::sort(expected.begin(), expected.end());
  const std::vector<double> angles = sorted_cone_angles(scene);
  ASSERT_EQ(angles.size(), expected.size());
  for (size_t i = 0; i < angles.size(); ++i) EXPECT_NEAR(angles[i], expected[i], 1e-7);
  for (const VertexClass& vc : scene.vertex_classes) EXPECT_EQ(vc.singular, singular);
}

std::vector<PeerFinding> findings_with(const PeerImport& result, Severity severity) {
  std::vector<PeerFinding> out;
  for (const PeerFinding& f : result.findings)
    if (f.severity == severity) out.push_back(f);
  return out;
}

const PeerFinding* finding_at(const PeerImport& result, const std::string& pointer,
                              Severity severity) {
  for (const PeerFinding& f : result.findings)
    if (f.pointer == pointer && f.severity == severity) return &f;
  return nullptr;
}

std::vector<std::string> pointers(const std::vector<PeerFinding>& findings) {
  std::vector<std::string> out;
  for (const PeerFinding& f : findings) out.push_back(f.pointer);
  std::sort(out.begin(), out.end());
  return out;
}

// The torus as the unit square, listed clockwise: edge 0 is the left side (0,0)->(0,1), 1 the
// top, 2 the right side, 3 the bottom; left is glued to right and top to bottom.
json clockwise_torus() {
  return json::parse(R"({
    "vertices": [[0, 0], [0, 1], [1, 1], [1, 0], [0, 0]],
    "gluing": [2, 3, 0, 1],
    "edges": [{"type": "translation", "vector": [1, 0]}, {"type": "translation", "vector": [0, -1]},
              {"type": "translation", "vector": [-1, 0]}, {"type": "translation", "vector": [0, 1]}],
    "normals": [[-1, 0], [0, 1], [1, 0], [0, -1]],
    "initialPosition": [0.5, 0.0, 0.5]
  })");
}

void expect_error(const json& peer, const std::string& pointer, const std::string& problem) {
  try {
    import_peer(peer, "bad.json");
    ADD_FAILURE() << "no error; expected one at " << pointer;
  } catch (const SceneError& e) {
    EXPECT_EQ(e.file(), "bad.json");
    EXPECT_EQ(e.pointer(), pointer) << e.what();
    EXPECT_NE(e.problem().find(problem), std::string::npos) << e.what();
  }
}

TEST(PeerImport, EveryPeerGeometryConvertsIntoALoadableScene) {
  int files = 0;
  for (const auto& entry : fs::directory_iterator(kPeerDir)) {
    if (entry.path().extension() != ".json" || entry.path().stem() == "manifest") continue;
    SCOPED_TRACE(entry.path().string());
    const PeerImport result = import_peer_file(entry.path());
    EXPECT_NO_THROW(load(result));
    ++files;
  }
  EXPECT_EQ(files, 16);
}

TEST(PeerImport, ConeAnglesOfTheTranslationSurfaces) {
  // The L (three squares) and the double pentagon: every corner is one point, whose angle is
  // the polygon's angle sum (n - 2) pi = 6 pi for their 8 vertices.
  for (const char* name : {"L_shape", "L_shapePillars", "L_shapePrism", "DoublePentagonTranslation",
                           "DoublePentagonPillars", "DoublePentagonTranslationPrism"})
    expect_cone_angles(name, {6.0 * kPi}, true);
  // The torus: the four corners of the square make one regular point.
  expect_cone_angles("torus", {2.0 * kPi}, false);
  expect_cone_angles("torus3D", {2.0 * kPi}, false);
  // The unfolded cube: its eight corners, three right angles each.
  expect_cone_angles("cube", std::vector<double>(8, 1.5 * kPi), true);
  // The pillowcase: four points of angle pi.
  expect_cone_angles("pillowCase", std::vector<double>(4, kPi), true);
}

TEST(PeerImport, MirrorRoomsKeepTheirCornerAngles) {
  // With mirrors only, each corner is its own boundary class whose angle is the corner's.
  expect_cone_angles("irrationalTriangle", {1.0, 0.5 * kPi, 0.5 * kPi - 1.0}, true);
  expect_cone_angles("rationalTriangle", {kPi / 6.0, kPi / 3.0, kPi / 2.0}, true);
  expect_cone_angles("equilateralTriangle", std::vector<double>(3, kPi / 3.0), true);
  expect_cone_angles("square_mirror", std::vector<double>(4, kPi / 2.0), true);
  expect_cone_angles("PentagonMirror", std::vector<double>(5, 0.6 * kPi), true);
  // The double pentagon as one octagon: six pentagon corners and the two where the pentagons meet.
  std::vector<double> octagon(6, 0.6 * kPi);
  octagon.insert(octagon.end(), 2, 1.2 * kPi);
  expect_cone_angles("DoublePentagon_mirror", octagon, true);
}

TEST(PeerImport, VerticalComponentAndWallHeight) {
  // Walls span y in [-wallHeight, wallHeight] in the app.
  EXPECT_EQ(import_named("irrationalTriangle").scene["height"], 20.0);
  const PeerImport line = import_named("L_shape");
  EXPECT_EQ(line.scene["height"], 4.0);
  EXPECT_FALSE(line.scene.contains("period"));
  EXPECT_NE(finding_at(line, "/vertical_wrap_amount", Severity::ignored), nullptr);
  const Scene prism = load(import_named("L_shapePrism"));
  ASSERT_TRUE(prism.period);
  EXPECT_EQ(*prism.period, 4.0);
}

TEST(PeerImport, CubeReportsTheInvertedLinearPartsAndTheWrongTranslation) {
  const PeerImport result = import_named("cube");
  // The rotations glue edges 0-13, 2-3, 5-6 and 8-9 (e.g. edge 0 (1,1)->(1,3) onto edge 13
  // (3,1)->(1,1): the quarter turn [[0, 1], [-1, 0]] with translation (0, 2)); the file writes
  // their inverses. The other gluings are translations or half-turns, their own inverses.
  const std::vector<std::string> expected{
      "/edges/0/transform/matrix", "/edges/11/transform/translation", "/edges/13/transform/matrix",
      "/edges/2/transform/matrix", "/edges/3/transform/matrix",       "/edges/5/transform/matrix",
      "/edges/6/transform/matrix", "/edges/8/transform/matrix",       "/edges/9/transform/matrix"};
  EXPECT_EQ(pointers(findings_with(result, Severity::disagrees)), expected);
  const PeerFinding* edge0 = finding_at(result, "/edges/0/transform/matrix", Severity::disagrees);
  ASSERT_NE(edge0, nullptr);
  EXPECT_NE(edge0->message.find("linear part is the inverse of the derived map"),
            std::string::npos);
  EXPECT_NE(edge0->message.find("[[0, 1], [-1, 0]]"), std::string::npos) << edge0->message;
  // Edge 11, (5,-1)->(5,1), is glued to edge 4, (-3,1)->(-3,-1): a translation by (-8, 0), not
  // the file's (-4, 0).
  const PeerFinding* edge11 =
      finding_at(result, "/edges/11/transform/translation", Severity::disagrees);
  ASSERT_NE(edge11, nullptr);
  EXPECT_NE(edge11->message.find("(-8, 0)"), std::string::npos) << edge11->message;

  const Scene scene = load(result);
  const Affine2& g = scene.polygons[0].edges[0].map;
  EXPECT_EQ(g.apply(Vec2(1.0, 1.0)), Vec2(1.0, 1.0));
  EXPECT_EQ(g.apply(Vec2(1.0, 3.0)), Vec2(3.0, 1.0));
}

TEST(PeerImport, LShapeAgreesAndIsReversed) {
  const PeerImport result = import_named("L_shape");
  EXPECT_TRUE(findings_with(result, Severity::disagrees).empty());
  EXPECT_NE(finding_at(result, "/vertices", Severity::converted), nullptr);
  const Scene scene = load(result);
  // The file's edge 0, (2,0)->(6,0), glued to its edge 2, (6,-4)->(2,-4), is our edge 7,
  // (6,0)->(2,0), glued to our edge 5, (2,-4)->(6,-4), translating by the file's (0, -4).
  const Polygon& p = scene.polygons[0];
  EXPECT_EQ(p.vertex(7), Vec2(6.0, 0.0));
  EXPECT_EQ(p.vertex(0), Vec2(2.0, 0.0));
  EXPECT_EQ(p.edges[7].to, (EdgeRef{0, 5}));
  EXPECT_EQ(p.edges[7].map.translation, Vec2(0.0, -4.0));
  EXPECT_EQ(p.edges[7].map.linear, Mat2(1.0));
  EXPECT_EQ(scene.name, "l_shape");
  EXPECT_EQ(scene.look.wall_tint, 0.05);
  EXPECT_EQ(scene.camera.position, Vec3(0.0, 0.0, 2.0));
  EXPECT_EQ(scene.camera.yaw_deg, -90.0);
}

TEST(PeerImport, ClockwiseInputIsRenumbered) {
  const PeerImport result = import_peer(clockwise_torus(), "square.json");
  EXPECT_EQ(result.scene["polygons"], ordered_json::parse("[[[0, 0], [1, 0], [1, 1], [0, 1]]]"));
  // Our edges: 0 bottom (the file's 3), 1 right (2), 2 top (1), 3 left (0).
  EXPECT_EQ(result.scene["gluings"], ordered_json::parse("[[[0, 3], [0, 1]], [[0, 2], [0, 0]]]"));
  EXPECT_TRUE(findings_with(result, Severity::disagrees).empty());
  const Scene scene = load(result);
  EXPECT_EQ(scene.polygons[0].edges[3].map.translation, Vec2(1.0, 0.0));
  EXPECT_EQ(scene.polygons[0].edges[2].map.translation, Vec2(0.0, -1.0));
  EXPECT_EQ(scene.camera.position, Vec3(0.5, 0.5, 2.0));
}

TEST(PeerImport, DisagreementsAreReportedAtTheFilesIndices) {
  json peer = clockwise_torus();
  peer["edges"][1]["vector"] = {0, 1};  // the top's map is (0, -1); (0, 1) is the way back
  peer["edges"][2]["vector"] = {-1, 0.5};
  peer["normals"][3] = {0, 1};  // the bottom's outward normal is (0, -1)
  peer["normals"][0] = {-0.8, 0.6};
  const PeerImport result = import_peer(peer, "square.json");
  EXPECT_EQ(
      pointers(findings_with(result, Severity::disagrees)),
      (std::vector<std::string>{"/edges/1/vector", "/edges/2/vector", "/normals/0", "/normals/3"}));
  EXPECT_NE(finding_at(result, "/edges/1/vector", Severity::disagrees)->message.find("back"),
            std::string::npos);
  EXPECT_NE(finding_at(result, "/normals/3", Severity::disagrees)->message.find("inward"),
            std::string::npos);
  EXPECT_NE(finding_at(result, "/normals/0", Severity::disagrees)->message.find("36.8698"),
            std::string::npos);
}

TEST(PeerImport, DecorationsFitOurRules) {
  // A hollow cube at the app's floor (y = -wallHeight) sinks half below our band: raised so
  // that its bottom (half-size 0.13 * 0.77) touches z = 0.
  const PeerImport triangle = import_named("irrationalTriangle");
  EXPECT_NE(finding_at(triangle, "/decorations/0", Severity::moved), nullptr);
  EXPECT_EQ(triangle.scene["objects"][0]["size"], 0.1001);
  EXPECT_EQ(triangle.scene["objects"][0]["hole"], 0.13);
  EXPECT_EQ(triangle.scene["objects"][0]["center"][2], 0.1001);
  // Its animated sphere starts at (1, 0), on edge 0: dropped. The camera, at vertex 0 in the
  // app, moves inside.
  EXPECT_NE(finding_at(triangle, "/decorations/1", Severity::dropped), nullptr);
  EXPECT_EQ(triangle.scene["objects"].size(), 1u);
  const Scene scene = load(triangle);
  EXPECT_TRUE(scene.polygons[0].contains(Vec2(scene.camera.position)));
  EXPECT_EQ(scene.camera.position.z, 10.0);

  const PeerImport cube = import_named("cube");
  // The animated sphere circles (0, 0) at radius 1.2 and starts at (1.2, 0); y 0.5 is z 2.5.
  EXPECT_EQ(cube.scene["objects"][1]["center"], ordered_json::parse("[1.2, 0.0, 2.5]"));
  EXPECT_NE(finding_at(cube, "/decorations/1/animation", Severity::converted), nullptr);
  // A sphere of radius 0.15 at y = 2 (z = 4) reaches over the walls: lowered to 3.85.
  EXPECT_EQ(cube.scene["objects"][5]["center"], ordered_json::parse("[4.0, 0.0, 3.85]"));
  EXPECT_NE(finding_at(cube, "/decorations/5", Severity::moved), nullptr);

  // The pillowcase's sphere at (-2, -2) is outside the polygon.
  EXPECT_NE(finding_at(import_named("pillowCase"), "/decorations/2", Severity::dropped), nullptr);
}

TEST(PeerImport, PillarsBecomeMarkers) {
  const PeerImport l = import_named("L_shapePillars");
  EXPECT_EQ(l.scene["singularities"], ordered_json::parse(R"({"radius": 0.02})"));
  const PeerFinding* f = finding_at(l, "/decorations/2", Severity::converted);
  ASSERT_NE(f, nullptr);
  EXPECT_NE(f->message.find("none at vertices 2"), std::string::npos) << f->message;
  EXPECT_EQ(l.scene["objects"].size(), 2u);
  EXPECT_EQ(load(l).markers.size(), 1u);

  const PeerImport pentagon = import_named("DoublePentagonPillars");
  EXPECT_EQ(pentagon.scene["singularities"], ordered_json::parse(R"({"radius": 0.02})"));
  EXPECT_NE(finding_at(pentagon, "/decorations/3", Severity::converted)
                ->message.find("none at vertices 5, 6, 7"),
            std::string::npos);

  // On the torus no class is singular: a pillar at a corner marks every vertex.
  json torus = clockwise_torus();
  torus["decorations"] = json::parse(R"([{"type": "cylinder", "position": [1, 0, 1],
                                          "radius": 0.05, "height": 4}])");
  const PeerImport marked = import_peer(torus, "torus.json");
  EXPECT_EQ(marked.scene["vertices"], ordered_json::parse(R"({"radius": 0.05})"));
}

TEST(PeerImport, NonIsometricAndReflectingAffineMaps) {
  // A quadrilateral whose right edge (4,0)->(4,2) is glued to its left edge (0,1)->(0,0) by
  // x -> x / 2 + (-2, 0); the bottom and top are mirrors.
  json peer = json::parse(R"({
    "vertices": [[0, 0], [4, 0], [4, 2], [0, 1], [0, 0]],
    "gluing": [0, 3, 2, 1],
    "edges": [{"type": "mirror"},
              {"type": "affine", "transform": {"matrix": [0.5, 0, 0, 0.5], "translation": [-2, 0]}},
              {"type": "mirror"},
              {"type": "affine", "transform": {"matrix": [2, 0, 0, 2], "translation": [4, 0]}}],
    "normals": [[0, -1], [1, 0], [-0.242535625, 0.9701425], [-1, 0]]
  })");
  const PeerImport dilation = import_peer(peer, "dilation.json");
  EXPECT_EQ(
      dilation.scene["gluings"],
      ordered_json::parse(R"([{"edges": [[0, 1], [0, 3]], "matrix": [[0.5, 0], [0, 0.5]]}])"));
  EXPECT_EQ(load(dilation).gluings[0].type, GluingType::similarity);
  EXPECT_EQ(finding_at(dilation, "/edges/1/transform/matrix", Severity::disagrees), nullptr);
  // With the app's inverted linear part the gluing is the same, and the report says so.
  peer["edges"][1]["transform"]["matrix"] = {2, 0, 0, 2};
  const PeerImport inverted = import_peer(peer, "dilation.json");
  EXPECT_EQ(inverted.scene["gluings"], dilation.scene["gluings"]);
  EXPECT_NE(finding_at(inverted, "/edges/1/transform/matrix", Severity::disagrees)
                ->message.find("inverse"),
            std::string::npos);

  // The Klein bottle: the unit square's sides glued by a reflection (x, y) -> (x - 1, 1 - y).
  const json klein = json::parse(R"({
    "vertices": [[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]],
    "gluing": [2, 3, 0, 1],
    "edges": [{"type": "affine", "transform": {"matrix": [1, 0, 0, 1], "translation": [0, 1]}},
              {"type": "affine", "transform": {"matrix": [1, 0, 0, -1], "translation": [-1, 1]}},
              {"type": "affine", "transform": {"matrix": [1, 0, 0, 1], "translation": [0, -1]}},
              {"type": "affine", "transform": {"matrix": [1, 0, 0, -1], "translation": [1, 1]}}],
    "normals": [[0, -1], [1, 0], [0, 1], [-1, 0]]
  })");
  const PeerImport bottle = import_peer(klein, "klein.json");
  EXPECT_EQ(bottle.scene["gluings"][1],
            ordered_json::parse(R"({"edges": [[0, 1], [0, 3]], "map": "reflection"})"));
  EXPECT_TRUE(findings_with(bottle, Severity::disagrees).empty());
  EXPECT_FALSE(load(bottle).topology.orientable);
}

TEST(PeerImport, MalformedFilesGiveErrorsWithPointers) {
  json peer = clockwise_torus();
  peer.erase("vertices");
  expect_error(peer, "/", "missing required key \"vertices\"");

  peer = clockwise_torus();
  peer["vertices"][4] = {0, 0.5};
  expect_error(peer, "/vertices/4", "not closed");

  peer = clockwise_torus();
  peer["vertices"][2][0] = "one";
  expect_error(peer, "/vertices/2/0", "expected a number");

  peer = clockwise_torus();
  peer["vertices"] = json::parse("[[0, 0], [3, 0], [0, 1], [1, 1], [0, 0]]");
  expect_error(peer, "/vertices", "edges 1 and 3 intersect");

  // A clockwise list with a repeated vertex: named by the file's index.
  peer = clockwise_torus();
  peer["vertices"] = json::parse("[[0, 0], [0, 2], [2, 2], [2, 0], [2, 0], [0, 0]]");
  expect_error(peer, "/vertices/4", "repeats the previous vertex (edge 3");

  peer = clockwise_torus();
  peer["gluing"][3] = 9;
  expect_error(peer, "/gluing/3", "out of range");

  peer = clockwise_torus();
  peer["gluing"] = {1, 2, 0, 3};
  expect_error(peer, "/gluing/0",
               "edge 0 is glued to edge 1, but /gluing/1 glues edge 1 to edge 2");

  peer = clockwise_torus();
  peer["gluing"] = {2, 3, 0};
  expect_error(peer, "/gluing", "one entry per edge (4)");

  peer = clockwise_torus();
  peer["edges"][1]["type"] = "rotation";
  expect_error(peer, "/edges/1/type", "unknown edge type");

  peer = clockwise_torus();
  peer["edges"][0] = json::parse(R"({"type": "affine"})");
  expect_error(peer, "/edges/0", "missing required key \"transform\"");

  peer = clockwise_torus();
  peer["normals"][2] = {1};
  expect_error(peer, "/normals/2", "expected at least 2 elements");

  peer = clockwise_torus();
  peer["vertical_component"] = "spiral";
  expect_error(peer, "/vertical_component", "expected line or circle");

  peer = clockwise_torus();
  peer["wallHeight"] = -1;
  expect_error(peer, "/wallHeight", "positive");

  peer = clockwise_torus();
  peer["decorations"] = json::parse(R"([{"type": "sphere", "position": [0.5, 0, 0.5, 1]}])");
  expect_error(peer, "/decorations/0/position", "at most 3");

  peer = clockwise_torus();
  peer["decorations"] = json::parse(R"([{"type": "sphere", "position": [0.5, 0.5]}])");
  expect_error(peer, "/decorations/0", "missing required key \"radius\"");

  // Edges of different lengths cannot be glued by an isometry: named at the file's gluing.
  peer = clockwise_torus();
  peer["vertices"] = json::parse("[[0, 0], [0, 1], [1, 2], [1, 0], [0, 0]]");
  expect_error(peer, "/gluing/0", "differ in length");

  expect_error(json::array(), "/", "expected an object");
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(PeerImportCli, WritesTheSceneAndTheReport) {
  const fs::path dir = fs::path(test::make_temp_dir()) / "peer_import_cli";
  fs::create_directories(dir);
  const fs::path cube = kPeerDir / "cube.json";
  const auto r =
      test::run_flatmarch({"import-peer", cube.string(), "-o", (dir / "cube.json").string(),
                           "--report-json", (dir / "report.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  const std::string& err = r.err;
  EXPECT_NE(err.find(cube.string() +
                     ": /edges/0/transform/matrix: disagrees: linear part is the inverse"),
            std::string::npos)
      << err;
  const Scene scene = load_scene(dir / "cube.json");
  EXPECT_EQ(scene.name, "cube");
  EXPECT_EQ(scene.vertex_classes.size(), 8u);
  const json report = json::parse(read_text(dir / "report.json"));
  EXPECT_EQ(report["file"], cube.string());
  EXPECT_EQ(report["findings"].size(), import_named("cube").findings.size());
  const json edge11 = {{"pointer", "/edges/11/transform/translation"},
                       {"severity", "disagrees"},
                       {"message", "translation (-4, 0) disagrees with the derived map's (-8, 0)"}};
  EXPECT_NE(std::find(report["findings"].begin(), report["findings"].end(), edge11),
            report["findings"].end());

  // Without -o the scene goes to stdout.
  const auto torus = test::run_flatmarch({"import-peer", (kPeerDir / "torus.json").string()});
  ASSERT_EQ(torus.exit_code, 0) << torus.err;
  EXPECT_EQ(json::parse(torus.out)["name"], "torus");
}

TEST(PeerImportCli, MalformedInputExitsWith2) {
  const fs::path dir = fs::path(test::make_temp_dir()) / "peer_import_cli_bad";
  fs::create_directories(dir);
  json peer = clockwise_torus();
  peer["gluing"] = {1, 2, 0, 3};
  const fs::path bad = dir / "bad.json";
  std::ofstream(bad) << peer.dump();
  auto r = test::run_flatmarch({"import-peer", bad.string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err.rfind("error: " + bad.string() + ": /gluing/0: ", 0), 0u) << r.err;
  std::ofstream(dir / "empty.json") << "";
  r = test::run_flatmarch({"import-peer", (dir / "empty.json").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("the file is empty"), std::string::npos);
}

}  // namespace
}  // namespace flatmarch
