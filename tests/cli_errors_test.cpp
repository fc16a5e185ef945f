// Every malformed scene and every bad argument ends with one line `error: FILE: /json/path: what
// is wrong` (arguments: `error: OPTION: ...`) and exit code 2, within a second, never a crash.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <utility>

#include "backends/backend.hpp"
#include "scene/load.hpp"
#include "tests/process.hpp"

namespace flatmarch {
namespace {

namespace fs = std::filesystem;
using test::run_flatmarch;

// A valid unit-square room to break one rule at a time.
constexpr const char* kSquare = R"("polygons": [[[0, 0], [1, 0], [1, 1], [0, 1]]])";

std::string with_square(const std::string& rest) {
  return std::string("{") + kSquare + (rest.empty() ? "" : ", ") + rest + "}";
}

struct Case {
  const char* name;
  std::string json;
  const char* pointer;
  const char* fragment;  // part of the message
};

std::vector<Case> cases() {
  const std::string torus_gluings = R"("gluings": [[[0, 0], [0, 2]], [[0, 1], [0, 3]]])";
  return {
      // Not a scene at all.
      {"empty", "", "/", "the file is empty"},
      {"whitespace", "  \n\t ", "/", "the file is empty"},
      {"not_json", "polygons: []", "/", "invalid JSON"},
      {"truncated", R"({"polygons": [[[0, 0], [1, 0])", "/", "invalid JSON"},
      {"top_level_array", "[1, 2]", "/", "expected an object"},
      {"nan_literal", R"({"polygons": [[[0, 0], [1, 0], [NaN, 1]]]})", "/", "invalid JSON"},
      {"infinity_literal", R"({"polygons": [[[0, 0], [1, 0], [Infinity, 1]]]})", "/",
       "invalid JSON"},
      {"huge_number", R"({"polygons": [[[0, 0], [1, 0], [1e400, 1]]]})", "/", "invalid JSON"},
      {"not_utf8", "{\"name\": \"\xff\xfe\", " + std::string(kSquare) + "}", "/", "invalid JSON"},
      {"deep_nesting", std::string(100000, '[') + std::string(100000, ']'), "/",
       "nested deeper than 64"},
      // Structure and types.
      {"missing_polygons", "{}", "/", "missing required key \"polygons\""},
      {"no_polygons", R"({"polygons": []})", "/polygons", "at least 1"},
      {"polygon_not_array", R"({"polygons": ["square"]})", "/polygons/0", "expected an array"},
      {"two_vertices", R"({"polygons": [[[0, 0], [1, 0]]]})", "/polygons/0", "at least 3"},
      {"vertex_not_number", R"({"polygons": [[[0, 0], [1, "a"], [0, 1]]]})", "/polygons/0/1/1",
       "expected a number"},
      {"vertex_three_coords", R"({"polygons": [[[0, 0], [1, 0, 0], [0, 1]]]})", "/polygons/0/1",
       "at most 2"},
      {"unknown_key", with_square(R"("hieght": 3)"), "/hieght", "unknown key \"hieght\""},
      {"name_not_string", with_square(R"("name": 5)"), "/name", "expected a string"},
      // Polygons (DESIGN.md section 1).
      {"clockwise", R"({"polygons": [[[0, 0], [0, 1], [1, 1], [1, 0]]]})", "/polygons/0",
       "clockwise"},
      {"collinear_triangle", R"({"polygons": [[[0, 0], [1, 0], [2, 0]]]})", "/polygons/0/2",
       "fold back"},
      {"self_intersecting", R"({"polygons": [[[0, 0], [1, 1], [1, 0], [0, 1]]]})", "/polygons/0",
       "not simple"},
      {"zero_length_edge", R"({"polygons": [[[0, 0], [1, 0], [1, 0], [0, 1]]]})", "/polygons/0/2",
       "zero length"},
      {"repeated_vertex", R"({"polygons": [[[0, 0], [2, 0], [1, 1], [2, 2], [0, 2], [1, 1]]]})",
       "/polygons/0/5", "repeats vertex 2"},
      {"fold_back", R"({"polygons": [[[0, 0], [2, 0], [1, 0], [1, 1]]]})", "/polygons/0/1",
       "fold back"},
      // Gluings.
      {"edge_out_of_range", with_square(R"("gluings": [[[0, 0], [0, 4]]])"), "/gluings/0/1/1",
       "out of range"},
      {"polygon_out_of_range", with_square(R"("gluings": [[[0, 0], [1, 2]]])"), "/gluings/0/1/0",
       "out of range"},
      {"index_not_integer", with_square(R"("gluings": [[[0, 0.5], [0, 2]]])"), "/gluings/0/0/1",
       "integer"},
      {"index_negative", with_square(R"("gluings": [[[0, -1], [0, 2]]])"), "/gluings/0/0/1",
       "out of range"},
      {"index_huge", with_square(R"("gluings": [[[0, 1)" + std::string(30, '0') + R"(], [0, 2]]])"),
       "/gluings/0/0/1", "out of range"},
      {"index_beyond_double",
       with_square(R"("gluings": [[[0, 1)" + std::string(400, '0') + R"(], [0, 2]]])"), "/",
       "number overflow"},
      {"gluing_wrong_arity", with_square(R"("gluings": [[[0, 0]]])"), "/gluings/0", "at least 2"},
      {"glued_twice", with_square(R"("gluings": [[[0, 0], [0, 2]], [[0, 0], [0, 1]]])"),
       "/gluings/1/0", "already glued by /gluings/0"},
      {"glued_to_itself", with_square(R"("gluings": [[[0, 1], [0, 1]]])"), "/gluings/0",
       "glued to itself"},
      {"lengths_differ",
       R"({"polygons": [[[0, 0], [2, 0], [2, 1], [0, 1]]], "gluings": [[[0, 0], [0, 1]]]})",
       "/gluings/0", "differ in length"},
      {"unknown_map", with_square(R"("gluings": [{"edges": [[0, 0], [0, 2]], "map": "shear"}])"),
       "/gluings/0/map", "unknown map"},
      {"map_and_matrix",
       with_square(
           R"("gluings": [{"edges": [[0, 0], [0, 2]], "map": "reflection", "matrix": [[1, 0], [0, 1]]}])"),
       "/gluings/0", "either \"map\" or \"matrix\""},
      {"singular_matrix",
       with_square(R"("gluings": [{"edges": [[0, 0], [0, 2]], "matrix": [[1, 2], [2, 4]]}])"),
       "/gluings/0", "singular"},
      {"matrix_misses_edge",
       with_square(R"("gluings": [{"edges": [[0, 0], [0, 2]], "matrix": [[2, 0], [0, 1]]}])"),
       "/gluings/0", "does not carry"},
      {"unknown_gluing_key", with_square(R"("gluings": [{"edges": [[0, 0], [0, 2]], "scale": 2}])"),
       "/gluings/0/scale", "unknown key"},
      // Boundaries.
      {"unknown_boundary", with_square(R"("boundary": "glass")"), "/boundary", "unknown boundary"},
      {"boundary_on_glued_edge",
       with_square(torus_gluings + R"(, "boundaries": [{"edge": [0, 0], "boundary": "wall"}])"),
       "/boundaries/0/edge", "is glued"},
      {"boundary_twice",
       with_square(
           R"("boundaries": [{"edge": [0, 0], "boundary": "wall"}, {"edge": [0, 0], "boundary": "mirror"}])"),
       "/boundaries/1/edge", "already has a boundary"},
      // The vertical.
      {"height_negative", with_square(R"("height": -2)"), "/height", "positive"},
      {"period_zero", with_square(R"("period": 0)"), "/period", "positive"},
      {"floor_and_period", with_square(R"("period": 2, "floor": true)"), "/floor", "no floor"},
      {"floor_not_boolean", with_square(R"("floor": 1)"), "/floor", "true or false"},
      // Objects.
      {"unknown_object", with_square(R"("objects": [{"type": "torus", "center": [0.5, 0.5, 1]}])"),
       "/objects/0/type", "unknown object type"},
      {"object_missing_center", with_square(R"("objects": [{"type": "sphere", "radius": 0.1}])"),
       "/objects/0", "missing required key \"center\""},
      {"object_outside",
       with_square(R"("objects": [{"type": "sphere", "center": [2, 0.5, 1], "radius": 0.1}])"),
       "/objects/0/center", "outside that polygon"},
      {"object_across_edge",
       with_square(R"("objects": [{"type": "sphere", "center": [0.9, 0.5, 1], "radius": 0.2}])"),
       "/objects/0", "reaches edge 1"},
      {"object_above_band",
       with_square(
           R"("objects": [{"type": "box", "center": [0.5, 0.5, 1.95], "half": [0.1, 0.1, 0.1]}])"),
       "/objects/0", "outside the wall band"},
      {"object_polygon_out_of_range",
       with_square(
           R"("objects": [{"type": "sphere", "polygon": 3, "center": [0.5, 0.5, 1], "radius": 0.1}])"),
       "/objects/0/polygon", "out of range"},
      {"hole_too_big",
       with_square(
           R"("objects": [{"type": "hollow_cube", "center": [0.5, 0.5, 1], "size": 0.1, "hole": 0.2}])"),
       "/objects/0/hole", "removes the whole cube"},
      {"box_flat",
       with_square(
           R"("objects": [{"type": "box", "center": [0.5, 0.5, 1], "half": [0.1, 0, 0.1]}])"),
       "/objects/0/half/1", "positive"},
      {"cylinder_bad_z",
       with_square(
           R"("objects": [{"type": "cylinder", "center": [0.5, 0.5, 1], "radius": 0.1, "z": [1, 0.5]}])"),
       "/objects/0/z", "z0 < z1"},
      {"sphere_key_of_box",
       with_square(
           R"("objects": [{"type": "sphere", "center": [0.5, 0.5, 1], "radius": 0.1, "half": [1, 1, 1]}])"),
       "/objects/0/half", "unknown key"},
      // Markers.
      {"marker_too_large",
       R"({"polygons": [[[0, 0], [2, 0], [4, 0], [4, 2], [2, 2], [2, 4], [0, 4], [0, 2]]],
          "gluings": [[[0, 0], [0, 5]], [[0, 1], [0, 3]], [[0, 2], [0, 7]], [[0, 4], [0, 6]]],
          "singularities": {"radius": 1.5}})",
       "/singularities/radius", "too large"},
      // The camera.
      {"camera_outside", with_square(R"("camera": {"position": [2, 0.5, 1]})"), "/camera/position",
       "not strictly inside polygon 0"},
      {"camera_fov", with_square(R"("camera": {"fov_deg": 180})"), "/camera/fov_deg",
       "field of view"},
      {"camera_pitch", with_square(R"("camera": {"pitch_deg": 91})"), "/camera/pitch_deg", "pitch"},
      {"camera_polygon", with_square(R"("camera": {"polygon": 1})"), "/camera/polygon",
       "out of range"},
      {"centroid_outside",
       R"({"polygons": [[[0, 0], [3, 0], [3, 0.2], [0.2, 0.2], [0.2, 2.8], [3, 2.8], [3, 3], [0, 3]]]})",
       "/", "give camera.position"},
      // Infinite surfaces (DESIGN.md section 1): ideal vertices {"to": [dx, dy]}.
      {"ray_glued_to_segment",
       R"({"polygons": [[[0, 0], [1, 0], {"to": [0, 1]}, {"to": [0, 1]}]],
          "gluings": [[[0, 0], [0, 1]]]})",
       "/gluings/0", "a segment cannot be glued to a ray"},
      {"three_ideal_vertices",
       R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, 1]}, {"to": [-1, 0]}]]})",
       "/polygons/0/3", "at most two ideal vertices"},
      {"ideal_vertices_apart",
       R"({"polygons": [[[0, 0], {"to": [1, 0]}, [1, 1], {"to": [0, 1]}]]})", "/polygons/0/1",
       "next to each other"},
      {"zero_direction", R"({"polygons": [[[0, 0], {"to": [0, 0]}, {"to": [0, 1]}]]})",
       "/polygons/0/1/to", "must not be zero"},
      {"ideal_vertex_key", R"({"polygons": [[[0, 0], {"from": [1, 0]}, {"to": [0, 1]}]]})",
       "/polygons/0/1/from", "unknown key \"from\""},
      {"similarity_on_rays",
       R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, 1]}]],
          "gluings": [{"edges": [[0, 0], [0, 2]], "map": "similarity"}]})",
       "/gluings/0", "\"similarity\" would not keep their lengths"},
      {"matrix_on_rays",
       R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, 1]}]],
          "gluings": [{"edges": [[0, 0], [0, 2]], "matrix": [[0, -1], [1, 0]]}]})",
       "/gluings/0", "a \"matrix\" would not keep their lengths"},
      {"rays_same_way",
       R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, 1]}], [[0, 0], {"to": [1, 0]}, {"to": [0, 1]}]],
          "gluings": [[[0, 0], [1, 0]]]})",
       "/gluings/0", "both run out to infinity"},
      {"edge_at_infinity_glued",
       R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, 1]}], [[0, 0], {"to": [1, 0]}, {"to": [0, 1]}]],
          "gluings": [[[0, 1], [1, 1]]]})",
       "/gluings/0", "lies at infinity"},
      {"boundary_at_infinity",
       R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, 1]}]],
          "boundaries": [{"edge": [0, 1], "boundary": "wall"}]})",
       "/boundaries/0/edge", "lies at infinity"},
      {"rays_cross", R"({"polygons": [[[0, 0], [4, 0], {"to": [-1, 1]}, {"to": [1, 1]}]]})",
       "/polygons/0", "edges 1 and 3 intersect"},
      {"strip_inside_out", R"({"polygons": [[[0, 0], [1, 0], {"to": [0, -1]}]]})", "/polygons/0",
       "clockwise"},
      {"camera_outside_unbounded",
       R"({"polygons": [[[0, 0], {"to": [1, 0]}, {"to": [0, 1]}]], "gluings": [[[0, 0], [0, 2]]],
          "camera": {"position": [-1, 5, 1]}})",
       "/camera/position", "not strictly inside polygon 0"},
      // The look.
      {"wall_tint", with_square(R"("look": {"wall_tint": 1.5})"), "/look/wall_tint", "[0, 1]"},
      {"fog_colour", with_square(R"("look": {"fog": [0.5, 2, 0.5]})"), "/look/fog/1", "[0, 1]"},
      {"background", with_square(R"("look": {"background": [1, 1, 1]})"), "/look/background",
       "give \"sky\""},
      {"fog_distance", with_square(R"("look": {"fog_distance": 0})"), "/look/fog_distance",
       "positive"},
      // The square has no gluings: no colour for one.
      {"gluing_colours", with_square(R"("look": {"gluings": [[1, 0, 0]]})"), "/look/gluings",
       "at most 0"},
      {"sky_colour", with_square(R"("look": {"sky": [0.5, 0.5]})"), "/look/sky", "3"},
      {"seams_kind", with_square(R"("look": {"seams": "dark"})"), "/look/seams", "object"},
      {"seams_key", with_square(R"("look": {"seams": {"colour": [0, 0, 0], "wdth": 1}})"),
       "/look/seams/wdth", "unknown key"},
      {"seams_width", with_square(R"("look": {"seams": {"width": 2}})"), "/look/seams/width",
       "radians"},
      {"seams_opacity", with_square(R"("look": {"seams": {"opacity": -0.5}})"),
       "/look/seams/opacity", "[0, 1]"},
      {"seams_cones", with_square(R"("look": {"seams": {"cones": true}})"), "/look/seams/cones",
       "false to draw cone points"},
  };
}

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.name;
}

class MalformedScene : public testing::TestWithParam<Case> {};

TEST_P(MalformedScene, ExitsWith2AndNamesThePointer) {
  const Case& c = GetParam();
  const fs::path file = fs::path(test::make_temp_dir()) / (std::string(c.name) + ".json");
  std::ofstream(file, std::ios::binary) << c.json;
  const auto r = run_flatmarch({"inspect", file.string()}, 10.0);
  EXPECT_FALSE(r.timed_out);
  EXPECT_EQ(r.signal, 0);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.out, "");
  const std::string prefix = "error: " + file.string() + ": " + c.pointer + ": ";
  EXPECT_EQ(r.err.rfind(prefix, 0), 0u) << r.err;
  EXPECT_NE(r.err.find(c.fragment), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  fs::remove_all(file.parent_path());
}

INSTANTIATE_TEST_SUITE_P(AllRules, MalformedScene, testing::ValuesIn(cases()),
                         [](const testing::TestParamInfo<Case>& p) {
                           return std::string(p.param.name);
                         });

TEST(MalformedScene, MissingFileAndDirectory) {
  auto r = run_flatmarch({"inspect", "/nonexistent/scene.json"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "error: /nonexistent/scene.json: /: cannot open the file\n");
  const std::string dir = test::make_temp_dir();
  r = run_flatmarch({"inspect", dir});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("is a directory"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

// Hostile documents built in memory are rejected quickly, without exhausting the stack.
TEST(HostileInput, MillionNestedBracketsAreRejected) {
  const std::string deep = std::string(1'000'000, '[') + std::string(1'000'000, ']');
  EXPECT_THROW(parse_scene(deep, "deep.json"), SceneError);
  const std::string deep_objects = [] {
    std::string s;
    for (int i = 0; i < 200000; ++i) s += "{\"a\":";
    return s + "1" + std::string(200000, '}');
  }();
  EXPECT_THROW(parse_scene(deep_objects, "deep.json"), SceneError);
}

TEST(HostileInput, StringsWithBracketsDoNotCountAsNesting) {
  const std::string name = std::string(1000, '[');
  const Scene scene =
      parse_scene(R"({"name": ")" + name + R"(", )" + std::string(kSquare) + "}", "brackets.json");
  EXPECT_EQ(scene.name, name);
}

TEST(HostileInput, TooManyPolygonsIsAnError) {
  std::string polygons;
  for (int i = 0; i <= SceneLimits::max_polygons; ++i)
    polygons += std::string(i ? "," : "") + "[[0,0],[1,0],[0,1]]";
  try {
    parse_scene(R"({"polygons": [)" + polygons + "]}", "many.json");
    FAIL() << "accepted " << SceneLimits::max_polygons + 1 << " polygons";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.pointer(), "/polygons");
  }
}

// Bad arguments: exit 2 and one `error:` line naming the option.
struct ArgCase {
  std::string name;
  std::vector<std::string> args;
  std::string fragment;
};

void PrintTo(const ArgCase& c, std::ostream* os) {
  *os << c.name;
}

class BadArguments : public testing::TestWithParam<ArgCase> {};

TEST_P(BadArguments, ExitWith2) {
  const ArgCase& c = GetParam();
  const std::string dir = test::make_temp_dir();
  std::vector<std::string> args;
  for (const std::string& a : c.args) {
    std::string s = a;
    if (const size_t at = s.find("@SCENES@"); at != std::string::npos)
      s.replace(at, 8, FLATMARCH_SOURCE_DIR "/scenes");
    if (const size_t at = s.find("@OUT@"); at != std::string::npos) s.replace(at, 5, dir);
    args.push_back(s);
  }
  const auto r = run_flatmarch(args, 20.0);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(c.fragment), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(fs::path(dir) / "x.png")) << "a failed command left an output behind";
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(
    Cli, BadArguments,
    testing::Values(
        ArgCase{"no_command", {}, "subcommand"}, ArgCase{"unknown_command", {"paint"}, "paint"},
        ArgCase{"size_zero",
                {"render", "@SCENES@/torus.json", "-o", "@OUT@/x.png", "--size", "0x5"},
                "--size"},
        ArgCase{"size_garbage",
                {"render", "@SCENES@/torus.json", "-o", "@OUT@/x.png", "--size", "big"},
                "--size"},
        ArgCase{"unknown_backend",
                {"render", "@SCENES@/torus.json", "-o", "@OUT@/x.png", "--backend", "cuda"},
                "unknown backend \"cuda\""},
        ArgCase{"method_not_run",
                {"render", "@SCENES@/torus.json", "-o", "@OUT@/x.png", "--backend", "oracle",
                 "--method", "sphere"},
                "does not run method sphere"},
        ArgCase{"unknown_method",
                {"render", "@SCENES@/torus.json", "-o", "@OUT@/x.png", "--method", "magic"},
                "unknown method"},
        ArgCase{"eps_negative",
                {"render", "@SCENES@/torus.json", "-o", "@OUT@/x.png", "--eps", "-1"},
                "--eps"},
        ArgCase{"eps_not_number",
                {"render", "@SCENES@/torus.json", "-o", "@OUT@/x.png", "--eps", "small"},
                "--eps"},
        ArgCase{"precision",
                {"render", "@SCENES@/torus.json", "-o", "@OUT@/x.png", "--precision", "f16"},
                "--precision"},
        ArgCase{"camera_outside",
                {"render", "@SCENES@/torus.json", "-o", "@OUT@/x.png", "--position", "9,9,1"},
                "not strictly inside polygon 0"},
        ArgCase{
            "fov", {"render", "@SCENES@/torus.json", "-o", "@OUT@/x.png", "--fov", "0"}, "--fov"},
        ArgCase{"missing_output", {"render", "@SCENES@/torus.json"}, "--output"},
        ArgCase{"from_two_numbers",
                {"trace", "@SCENES@/torus.json", "--from", "1,2", "--dir", "1,0,0"},
                "--from"},
        ArgCase{"dir_zero",
                {"trace", "@SCENES@/torus.json", "--from", "1,1,1", "--dir", "0,0,0"},
                "direction"},
        ArgCase{"from_outside",
                {"trace", "@SCENES@/torus.json", "--from", "5,1,1", "--dir", "1,0,0"},
                "not strictly inside polygon 0"},
        ArgCase{
            "trace_polygon",
            {"trace", "@SCENES@/torus.json", "--from", "1,1,1", "--dir", "1,0,0", "--polygon", "4"},
            "polygon 4 does not exist"},
        ArgCase{"max_events",
                {"trace", "@SCENES@/torus.json", "--from", "1,1,1", "--dir", "1,0,0",
                 "--max-events", "0"},
                "--max-events"},
        ArgCase{"gallery_not_folder",
                {"gallery", "@SCENES@/torus.json", "-o", "@OUT@"},
                "not a folder"}),
    [](const testing::TestParamInfo<ArgCase>& p) { return std::string(p.param.name); });

// The march parameters and backend options are declared once (cli/common.cpp) and held to one
// range each: every command that takes one rejects the same values with the same words.
std::vector<ArgCase> shared_option_cases() {
  const std::vector<std::pair<std::string, std::vector<std::string>>> commands{
      {"render", {"render", "@SCENES@/torus.json", "-o", "@OUT@/x.png"}},
      {"conform", {"conform", "--scene", "torus", "--json", "@OUT@/x.json"}},
      {"report", {"report", "--out", "@OUT@"}},
      {"sweep", {"sweep", "--scene", "torus", "--json", "@OUT@/x.json"}},
      {"view", {"view", "@SCENES@/torus.json", "--frames", "1"}}};
  const std::vector<std::tuple<std::string, std::vector<std::string>, std::string>> options{
      {"max_steps_zero", {"--max-steps", "0"}, "--max-steps: must lie in [1, 1e8]"},
      {"max_steps_huge", {"--max-steps", "200000000"}, "--max-steps: must lie in [1, 1e8]"},
      {"isa_unknown", {"--isa", "avx9000"}, "--isa: unknown instruction set \"avx9000\""},
      {"threads_negative", {"--threads", "-1"}, "--threads: must be 0 (all cores) or more"}};
  // --isa and --threads are options of a backend that a build may leave out
  // (FLATMARCH_WITH_<NAME>): where no registered backend takes one, the command has no such option.
  const auto taken = [](const std::string& flag) {
    return flag == "--max-steps" ||
           std::any_of(backend_registry().begin(), backend_registry().end(),
                       [&](const BackendEntry& e) {
                         return std::any_of(e.options.begin(), e.options.end(),
                                            [&](const BackendOption& o) { return o.flag == flag; });
                       });
  };
  std::vector<ArgCase> cases;
  for (const auto& [command, args] : commands)
    for (const auto& [name, option, fragment] : options) {
      if (command == "view" && option[0] != "--max-steps") continue;  // no backend options
      if (!taken(option[0])) continue;
#ifndef FLATMARCH_WITH_VIEWER
      if (command == "view") continue;  // a build without the viewer: `view` says so, exit 3
#endif
      std::vector<std::string> all = args;
      all.insert(all.end(), option.begin(), option.end());
      cases.push_back({command + "_" + name, all, fragment});
    }
  for (const size_t k : {1u, 3u}) {  // conform and sweep parse --precision themselves
    std::vector<std::string> all = commands[k].second;
    all.insert(all.end(), {"--precision", "f16"});
    cases.push_back({commands[k].first + "_precision", all, "--precision: expected f32 or f64"});
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(SharedOptions, BadArguments, testing::ValuesIn(shared_option_cases()),
                         [](const testing::TestParamInfo<ArgCase>& p) { return p.param.name; });

// A size whose work would not fit in memory is refused before anything is allocated, with how
// much it would need, under an address-space limit that the same command well within it meets.
TEST(Cli, ASizeBeyondMemoryIsRefusedBeforeItAllocates) {
#ifdef FLATMARCH_SANITIZE_BUILD
  GTEST_SKIP() << "a sanitizer reserves terabytes of address space: no RLIMIT_AS can hold it";
#endif
  const std::string dir = test::make_temp_dir();
  const std::string limit = "--as=" + std::to_string(size_t{3} << 30);  // 3 GiB
  const std::string scenes = FLATMARCH_SOURCE_DIR "/scenes";
  const std::vector<std::pair<std::vector<std::string>, std::string>> commands{
      // 8192 x 4096 x 8 frames x 32 bytes = 8 GiB
      {{"conform", "--scene", "torus", "--gallery", scenes, "--backend", "scalar", "--size",
        "8192x4096", "--json", dir + "/x.json"},
       "--size 8192x4096: a conformance case at this size holds about 8 frames of 32 bytes a "
       "pixel, 8 GiB, more than the 3 GiB of its address-space limit (RLIMIT_AS)"},
      {{"sweep", "--scene", "torus", "--gallery", scenes, "--size", "8192x4096", "--json",
        dir + "/x.json"},
       "--size 8192x4096: a sweep point's conformance case"},
      {{"report", "--out", dir, "--gallery", scenes, "--sweep-size", "8192x4096"},
       "--sweep-size 8192x4096"},
      // 16384 x 16384 x 2 frames x 32 bytes = 16 GiB
      {{"render", FLATMARCH_SOURCE_DIR "/scenes/torus.json", "-o", dir + "/x.png", "--size",
        "16384x16384"},
       "--size 16384x16384: a rendered image"}};
  for (const auto& [args, fragment] : commands) {
    std::vector<std::string> argv{"prlimit", limit, FLATMARCH_BINARY};
    argv.insert(argv.end(), args.begin(), args.end());
    const auto r = test::run_process(argv, 30.0);
    EXPECT_EQ(r.exit_code, 2) << args[0] << ": " << r.err;
    EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(fs::path(dir) / "x.png"));
  // Within the limit the same command runs.
  const auto ok = test::run_process(
      {"prlimit", limit, FLATMARCH_BINARY, "conform", "--scene", "torus", "--gallery", scenes,
       "--backend", "scalar", "--method", "analytic", "--size", "32x18", "--json", dir + "/x.json"},
      120.0);
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
}

TEST(Cli, EverySubcommandHasHelp) {
  for (const char* command : {"inspect", "render", "trace", "backends", "gallery", "import-peer",
                              "plan", "shader", "view"}) {
    const auto r = run_flatmarch({command, "--help"});
    EXPECT_EQ(r.exit_code, 0) << command;
    EXPECT_NE(r.out.find("Usage: flatmarch " + std::string(command)), std::string::npos)
        << command << r.out;
  }
  const auto r = run_flatmarch({"--help"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("Subcommands:"), std::string::npos);
}

}  // namespace
}  // namespace flatmarch
