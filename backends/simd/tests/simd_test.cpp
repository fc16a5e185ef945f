// The SIMD backend against the scalar backend: the same kernel, its per-lane maths one file
// (kernels/maths.glsl) and its control flow the same steps in the same order, so for every
// gallery scene and method at 320x180 every pixel's hit, steps, crossings, t and colour must be
// the scalar backend's, bit for bit, on every instruction set this CPU runs (issues 18 and 73).
// Also: the exit by the nearest line and its fallback, traces, lane counts, and an unknown
// instruction set
// (backend_contract_test holds it to what every backend promises).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numeric>
#include <stdexcept>

#include "backends/scalar/scalar.hpp"
#include "backends/simd/packet.hpp"
#include "backends/simd/simd.hpp"
#include "backends/simd/tuning.hpp"
#include "scene/load.hpp"
#include "scene/surfaces.hpp"
#include "tests/gallery.hpp"
#include "tests/process.hpp"

namespace flatmarch {
namespace {

struct Agreement {
  size_t pixels = 0, hit = 0, steps = 0, crossings = 0, t = 0, colour = 0;
};

// How many pixels of two frames of the same size are equal, bit for bit, in each AOV and in
// colour.
Agreement compare(const Frame& a, const Frame& b) {
  Agreement n;
  n.pixels = a.hit.size();
  for (size_t p = 0; p < n.pixels; ++p) {
    n.hit += a.hit[p] == b.hit[p];
    n.steps += a.steps[p] == b.steps[p];
    n.crossings += a.crossings[p] == b.crossings[p];
    n.t += a.t[p] == b.t[p];
    n.colour += a.rgb[3 * p] == b.rgb[3 * p] && a.rgb[3 * p + 1] == b.rgb[3 * p + 1] &&
                a.rgb[3 * p + 2] == b.rgb[3 * p + 2];
  }
  return n;
}

// Every pixel equal in every AOV and in colour.
void expect_identical(const Agreement& n, const std::string& what) {
  EXPECT_EQ(n.hit, n.pixels) << what << ": hit";
  EXPECT_EQ(n.steps, n.pixels) << what << ": steps";
  EXPECT_EQ(n.crossings, n.pixels) << what << ": crossings";
  EXPECT_EQ(n.t, n.pixels) << what << ": t";
  EXPECT_EQ(n.colour, n.pixels) << what << ": colour";
}

struct Case {
  std::string scene;
  Method method;
};

class SimdAgainstScalar : public testing::TestWithParam<Case> {};

TEST_P(SimdAgainstScalar, HitAndStepsAgree) {
  const Scene& scene = test::gallery_scene(GetParam().scene);
  MarchParams params;
  params.method = GetParam().method;
#ifdef FLATMARCH_SANITIZE_BUILD
  // A quarter of the pixels under the sanitizers: they check memory and arithmetic, which the
  // smaller frame exercises the same way, and the prisms' stuck rays take a minute each at 320x180.
  constexpr int kWidth = 160, kHeight = 90;
#else
  constexpr int kWidth = 320, kHeight = 180;
#endif
  const Frame scalar = ScalarBackend().render(scene, scene.camera, kWidth, kHeight, params, {});
  // Every instruction set this CPU runs, each with its own tuning and strategies (tuning.hpp).
  for (const std::string& isa : simd::isa_names(true)) {
    const Frame simd =
        SimdBackend({.isa = isa}).render(scene, scene.camera, kWidth, kHeight, params, {});
    const Agreement n = compare(scalar, simd);
    std::cout << "[ figures  ] " << GetParam().scene << " " << to_string(params.method) << " "
              << isa << ": hit equal " << n.hit << "/" << n.pixels << ", steps equal " << n.steps
              << "/" << n.pixels << "\n";
    expect_identical(n, GetParam().scene + " " + to_string(params.method) + " " + isa);
  }
}

std::vector<Case> every_case() {
  std::vector<Case> cases;
  for (const std::string& name : test::gallery_names())
    for (Method m : kKernelMethods) cases.push_back({name, m});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Gallery, SimdAgainstScalar, testing::ValuesIn(every_case()),
                         [](const testing::TestParamInfo<Case>& param) {
                           return param.param.scene + "_" + to_string(param.param.method);
                         });

// Every tile of the grid is handed out once, whichever thread asks and however many parts there
// are (more parts than blocks too), and nothing once the blocks are gone.
TEST(Simd, TileBlocksHandOutEveryTileOnce) {
  for (const auto [rows, cols, parts] :
       {std::array{90, 160, 2}, std::array{90, 160, 16}, std::array{3, 41, 7}, std::array{1, 1, 4},
        std::array{0, 5, 2}, std::array{5, 0, 2}}) {
    simd::TileBlocks blocks(rows, cols, parts);
    std::vector<int> seen(static_cast<size_t>(rows) * static_cast<size_t>(cols), 0);
    int row0 = 0, row1 = 0, col0 = 0, col1 = 0;
    int64_t taken = 0;
    // Parts ask in turn, the last one twice as often, as threads of unequal speed would.
    for (int turn = 0; taken <= rows * cols; ++turn) {
      const int part = turn % (parts + 1) == parts ? parts - 1 : turn % (parts + 1);
      if (!blocks.take(part, row0, row1, col0, col1)) break;
      ++taken;
      ASSERT_TRUE(0 <= row0 && row0 < row1 && row1 <= rows && 0 <= col0 && col0 < col1 &&
                  col1 <= cols);
      for (int r = row0; r < row1; ++r)
        for (int c = col0; c < col1; ++c) ++seen[static_cast<size_t>(r) * cols + c];
    }
    EXPECT_EQ(taken, blocks.taken());
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }))
        << rows << " x " << cols << " tiles, " << parts << " parts";
    for (int part = 0; part < parts; ++part)
      EXPECT_FALSE(blocks.take(part, row0, row1, col0, col1));
  }
}

// Every instruction set this CPU runs (packets of 4, 8 or 16 rays, tiles of 2x2, 4x2 or 4x4)
// gives the scalar backend's frame.
TEST(Simd, EveryInstructionSetAgreesWithScalar) {
  const std::vector<std::string> isas = simd::isa_names(true);
  ASSERT_FALSE(isas.empty());
  for (const char* name : {"l_shape", "double_pentagon", "cube"}) {
    const Scene& scene = test::gallery_scene(name);
    for (Method m : {Method::sphere, Method::analytic}) {
      MarchParams params;
      params.method = m;
      const Frame scalar = ScalarBackend().render(scene, scene.camera, 90, 50, params, {});
      for (const std::string& isa : isas) {
        const SimdBackend simd({.isa = isa});
        ASSERT_TRUE(simd.availability().available) << isa;
        EXPECT_EQ(simd.isa(), isa);
        const Agreement n = compare(scalar, simd.render(scene, scene.camera, 90, 50, params, {}));
        expect_identical(n, std::string(name) + " " + isa);
      }
    }
  }
}

// Rays spread over many rooms: staircases whose edges do not fit in a vector. Drawn apart, a
// pass over several rooms blends their edges by lane (32 and 128 squares: 128 and 512 edges),
// or takes one room a pass (130 squares: 520 edges, over what the blend's tables hold); every
// square drawn in one place, rays take whole passes reading the rooms' common edges by
// broadcast (Walls::same_rooms), and cross by slot on AVX-512 and AVX2 (EdgeTables::glue_by_slot;
// at 130 squares in passes of one room). Every instruction set gives the scalar frame.
TEST(Simd, RaysSpreadOverManyRoomsAgreeWithScalar) {
  for (const auto& [squares, apart] : std::vector<std::pair<int, bool>>{
           {32, false}, {128, false}, {130, false}, {32, true}, {128, true}, {130, true}}) {
    const Scene scene = staircase_surface(squares, apart);
    for (Method m : {Method::sphere, Method::analytic}) {
      MarchParams params;
      params.method = m;
      params.max_distance = 40.0;
      const Frame scalar = ScalarBackend().render(scene, scene.camera, 64, 36, params, {});
      for (const std::string& isa : simd::isa_names(true)) {
        const Agreement n = compare(
            scalar, SimdBackend({.isa = isa}).render(scene, scene.camera, 64, 36, params, {}));
        expect_identical(n, scene.name + " " + to_string(m) + " " + isa);
      }
    }
  }
}

// Rays over several rooms in one pass (Rooms::whole) meeting walls and solids of several rooms:
// the cube with two of its edges made opaque walls and a second solid in another face. Every
// instruction set and method gives the scalar frame.
TEST(Simd, WholePassesOverWallsAndSolidsAgreeWithScalar) {
  nlohmann::json doc = nlohmann::json::parse(
      std::ifstream(std::filesystem::path(FLATMARCH_SOURCE_DIR) / "scenes" / "cube.json"));
  nlohmann::json& gluings = doc["gluings"];
  ASSERT_EQ(gluings.back(), nlohmann::json::parse("[[5, 0], [2, 0]]"));
  gluings.erase(gluings.size() - 1);
  doc["boundaries"] = nlohmann::json::parse(
      R"([{"edge": [5, 0], "boundary": "wall"}, {"edge": [2, 0], "boundary": "wall"}])");
  doc["objects"].push_back(nlohmann::json::parse(
      R"({"type": "sphere", "polygon": 3, "center": [-1, 1, 1], "radius": 0.4})"));
  const Scene scene = parse_scene(doc.dump(), "cube with walls");
  for (Method m : kKernelMethods) {
    MarchParams params;
    params.method = m;
    const Frame scalar = ScalarBackend().render(scene, scene.camera, 96, 54, params, {});
    size_t walls = 0;
    for (float h : scalar.hit) walls += h == kHitWall;
    EXPECT_GT(walls, 100u) << to_string(m) << ": the walls are seen";
    for (const std::string& isa : simd::isa_names(true)) {
      const Agreement n = compare(
          scalar, SimdBackend({.isa = isa}).render(scene, scene.camera, 96, 54, params, {}));
      expect_identical(n, std::string("cube with walls ") + to_string(m) + " " + isa);
    }
  }
}

// A solid of every kind (sphere, box, hollow cube, cylinder) in the torus's one room, seen from
// near and far: the gallery's solids are hollow cubes and spheres, with cylinders only at the
// singularities' corners. On every instruction set and method the frames are the scalar
// backend's bit for bit, and every solid is seen.
TEST(Simd, SolidsOfEveryKindAgreeWithScalar) {
  const Scene scene = parse_scene(R"({
    "polygons": [[[0, 0], [4, 0], [4, 4], [0, 4]]],
    "gluings": [[[0, 0], [0, 2]], [[0, 1], [0, 3]]],
    "objects": [{"type": "sphere", "center": [1.3, 2.4, 1.0], "radius": 0.3},
                {"type": "box", "center": [2.4, 1.3, 0.9], "half": [0.2, 0.3, 0.25]},
                {"type": "hollow_cube", "center": [2.5, 2.5, 1.1], "size": 0.25},
                {"type": "cylinder", "center": [3.3, 3.2, 1.0], "radius": 0.2, "z": [0.5, 1.6]}],
    "camera": {"position": [0.4, 0.4, 1.0], "yaw_deg": 45, "pitch_deg": -3}})",
                                  "four solids");
  for (Method m : kKernelMethods) {
    MarchParams params;
    params.method = m;
    const Frame scalar = ScalarBackend().render(scene, scene.camera, 128, 72, params, {});
    std::array<size_t, 4> seen{};
    for (float h : scalar.hit)
      if (h >= 0.0f && h < 4.0f) ++seen[static_cast<size_t>(h)];
    for (size_t k = 0; k < seen.size(); ++k)
      EXPECT_GT(seen[k], 25u) << to_string(m) << ": solid " << k << " is seen";
    for (const std::string& isa : simd::isa_names(true)) {
      const Agreement n = compare(
          scalar, SimdBackend({.isa = isa}).render(scene, scene.camera, 128, 72, params, {}));
      expect_identical(n, std::string("four solids ") + to_string(m) + " " + isa);
    }
  }
}

// An L-shaped hexagon and a square glued edge to edge, a solid in the square.
Scene hexagon_and_square() {
  return parse_scene(R"({
    "polygons": [[[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]],
                 [[3, 0], [4, 0], [4, 1], [3, 1]]],
    "gluings": [[[0, 1], [1, 3]], [[0, 3], [1, 1]], [[0, 2], [1, 0]], [[0, 4], [1, 2]],
                [[0, 0], [0, 5]]],
    "objects": [{"type": "sphere", "polygon": 1, "center": [3.5, 0.5, 1], "radius": 0.2}],
    "camera": {"polygon": 0, "position": [0.5, 0.5, 1.0], "yaw_deg": 20, "pitch_deg": -5}})",
                     "hexagon and square");
}

// Whole passes whose lanes look their edges up rather than hold them (a room of more than
// kHeldEdges edges).
TEST(Simd, WholePassesLookingEdgesUpAgreeWithScalar) {
  const Scene scene = hexagon_and_square();
  for (Method m : kKernelMethods) {
    MarchParams params;
    params.method = m;
    const Frame scalar = ScalarBackend().render(scene, scene.camera, 96, 54, params, {});
    for (const std::string& isa : simd::isa_names(true)) {
      const Agreement n = compare(
          scalar, SimdBackend({.isa = isa}).render(scene, scene.camera, 96, 54, params, {}));
      expect_identical(n, std::string("hexagon and square ") + to_string(m) + " " + isa);
    }
  }
}

// A frame of `scene` marched by `isa`'s packets on one thread, its exit edges found by the
// nearest line first where `nearest` and the instruction set's tuning takes it
// (simd::PacketJob::exit_by_nearest_line), with the modes of `modes_off` left to their fallbacks
// (simd::PacketJob::modes_off); what the frame took in `taken` where not null.
Frame packet_frame(const Scene& scene, const MarchParams& params, int width, int height,
                   bool nearest, const std::string& isa, uint32_t modes_off = 0,
                   simd::PacketModes* taken = nullptr) {
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
  Frame frame(width, height);
  simd::PacketJob job = simd::frame_job(tables, scene.camera, width, height, frame);
  job.exit_by_nearest_line = nearest;
  job.modes_off = modes_off;
  const simd::PacketCode code = simd::packet_code(simd::isa_target(isa));
  if (taken) *taken = code.modes(job);
  const simd::TileShape tile = simd::tile_shape(code.lanes());
  simd::TileBlocks blocks((height + tile.height - 1) / tile.height,
                          (width + tile.width - 1) / tile.width, 1);
  simd::LaneCounts lanes;
  code.march(job, blocks, 0, &lanes);
  return frame;
}

simd::Isa isa_of(const std::string& name) {
  for (simd::Isa isa : {simd::Isa::avx512, simd::Isa::avx2, simd::Isa::sse4})
    if (name == simd::isa_name(isa)) return isa;
  throw std::invalid_argument("no instruction set " + name);
}

// Each mode of the packet code (simd::Mode, tuning.hpp's table of modes), with a scene and method
// that allow it and the instruction sets that take it there: those whose tuning row takes it and
// whose vectors hold what it reads. On every instruction set this CPU runs, the frame takes the
// mode exactly there, and gives the scalar backend's frame bit for bit both with the mode and with
// it left to its fallback (PacketJob::modes_off): a mode that one target alone takes is tested on
// its fallback on the others.
TEST(Simd, EveryModeAndItsFallbackOnEveryInstructionSet) {
  const Scene& cube = test::gallery_scene("cube");
  const Scene staircase = staircase_surface(32, false);  // every square drawn in one place
  const Scene apart = staircase_surface(32, true);       // 128 edges: looked up in no vectors
  // Whether the cube's 24 edges are looked up in vectors of this instruction set's lanes (in at
  // most Tuning::most_vectors, or most_vectors_analytic): the nearest line's search reads them by
  // lane, and lanes hold them only where the row holds edges that can be looked up.
  const auto cube_edges_fit = [](simd::Isa isa, bool analytic) {
    const int lanes = isa == simd::Isa::avx512 ? 16 : isa == simd::Isa::avx2 ? 8 : 4;
    const simd::Tuning& row = simd::kTunings[static_cast<size_t>(isa)];
    return (24 + lanes - 1) / lanes <= (analytic ? row.most_vectors_analytic : row.most_vectors);
  };
  const auto cube_looked_up = [&](simd::Isa isa) { return cube_edges_fit(isa, true); };
  const auto cube_held = [&](simd::Isa isa) {
    return simd::kTunings[static_cast<size_t>(isa)].held_over_lookup || !cube_edges_fit(isa, false);
  };
  struct ModeCase {
    simd::Mode mode;
    const Scene* scene;
    Method method;
    std::function<bool(simd::Isa)> fits;  // besides its tuning row, where the mode is taken
  };
  const auto everywhere = [](simd::Isa) { return true; };
  const std::vector<ModeCase> cases{
      // Six rooms of four edges (held), their normals alike slot by slot (alike).
      {simd::kModeWhole, &cube, Method::sphere, everywhere},
      {simd::kModeHeld, &apart, Method::sphere, everywhere},
      {simd::kModeHeld, &cube, Method::relaxed, cube_held},
      {simd::kModeAlike, &cube, Method::sphere, everywhere},
      {simd::kModeSameRooms, &staircase, Method::sphere, everywhere},
      // The staircase's ten tints in two vectors: SSE4's hold eight.
      {simd::kModeBySlot, &staircase, Method::analytic,
       [](simd::Isa isa) { return isa != simd::Isa::sse4; }},
      {simd::kModeNearestLine, &cube, Method::analytic, cube_looked_up},
      {simd::kModeOppositePairs, &cube, Method::analytic, cube_looked_up},
  };
  for (const simd::ModeName& m : simd::kModeNames)
    EXPECT_TRUE(std::any_of(cases.begin(), cases.end(),
                            [&](const ModeCase& c) { return c.mode == m.mode; }))
        << "a case for " << m.name;
  for (const ModeCase& c : cases) {
    const std::string name = std::find_if(simd::kModeNames.begin(), simd::kModeNames.end(),
                                          [&](const simd::ModeName& m) { return m.mode == c.mode; })
                                 ->name;
    MarchParams params;
    params.method = c.method;
    if (c.scene == &staircase || c.scene == &apart) params.max_distance = 40.0;
    const bool nearest =
        simd::packet_job(kernel::compile_scene<float>(*c.scene, params)).exit_by_nearest_line;
    const Frame scalar = ScalarBackend().render(*c.scene, c.scene->camera, 64, 36, params, {});
    for (const std::string& isa : simd::isa_names(true)) {
      const simd::Isa which = isa_of(isa);
      const bool expected =
          simd::kTunings[static_cast<size_t>(which)].takes(c.mode) && c.fits(which);
      const std::string what =
          name + " (" + c.scene->name + ", " + to_string(c.method) + ") " + isa;
      simd::PacketModes with, without;
      const Frame on = packet_frame(*c.scene, params, 64, 36, nearest, isa, 0, &with);
      EXPECT_EQ((with.modes & c.mode) != 0u, expected) << what;
      expect_identical(compare(scalar, on), what);
      const Frame off = packet_frame(*c.scene, params, 64, 36, nearest, isa, c.mode, &without);
      EXPECT_EQ(without.modes & c.mode, 0u) << what << ", left to its fallback";
      expect_identical(compare(scalar, off), what + ", left to its fallback");
      std::cout << "[ modes    ] " << what << ": "
                << ((with.modes & c.mode) ? "taken" : "not taken") << ", passes " << with.passes
                << "\n";
    }
  }
}

// The analytic method's exit by the nearest line (nearest-inl.h) takes the scenes of several
// convex rooms not alike, and finds the scalar kernel's exits: there, and forced on the L-shaped
// hexagon, whose rays often meet the nearest line off its edge and take the full loop after it.
TEST(Simd, ExitByTheNearestLineAgreesWithScalar) {
  MarchParams analytic;
  analytic.method = Method::analytic;
  const auto taken = [&](const Scene& scene, const MarchParams& params) {
    const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
    return simd::packet_job(tables).exit_by_nearest_line;
  };
  EXPECT_TRUE(taken(test::gallery_scene("cube"), analytic));
  EXPECT_TRUE(taken(test::gallery_scene("double_pentagon"), analytic));
  EXPECT_FALSE(taken(test::gallery_scene("l_shape"), analytic));  // one room
  EXPECT_FALSE(taken(hexagon_and_square(), analytic));            // not convex
  EXPECT_FALSE(taken(staircase_surface(8, false), analytic));     // rooms alike
  MarchParams sphere;
  sphere.method = Method::sphere;
  EXPECT_FALSE(taken(test::gallery_scene("cube"), sphere));

  // The instruction sets whose tuning takes the nearest line (simd::kModeNearestLine) have a copy
  // of the frame loop that finds the exit this way; the others take the loop without it for the
  // same job, and must give the same frames.
  const Scene hexagon = hexagon_and_square();
  for (const Scene* scene :
       {&hexagon, &test::gallery_scene("cube"), &test::gallery_scene("double_pentagon")}) {
    const Frame scalar = ScalarBackend().render(*scene, scene->camera, 96, 54, analytic, {});
    for (const std::string& isa : simd::isa_names(true)) {
      expect_identical(compare(scalar, packet_frame(*scene, analytic, 96, 54, true, isa)),
                       scene->name + " by the nearest line " + isa);
    }
  }
}

// A trace follows lane 0 of a packet: the same events as the scalar kernel's, in the same
// places, for rays through a few pixels of every scene.
TEST(Simd, TracesMatchScalar) {
  // The gallery, and a staircase of 32 squares drawn in one place, whose crossings read their
  // gluings by slot (EdgeTables::glue_by_slot) on AVX-512 and AVX2.
  std::vector<std::string> names = test::gallery_names();
  names.emplace_back("staircase_32");
  const Scene staircase = staircase_surface(32, false);
  for (const std::string& name : names) {
    const Scene& scene = name == "staircase_32" ? staircase : test::gallery_scene(name);
    const Camera& c = scene.camera;
    const CameraBasis<double> basis = camera_basis<double>(c.yaw_deg, c.pitch_deg, c.fov_deg, 8, 5);
    for (Method m : kKernelMethods) {
      MarchParams params;
      params.method = m;
      for (int i : {1, 4, 6}) {
        const Ray ray{c.polygon, c.position, camera_ray(basis, i, i % 5, 8, 5)};
        const Trace a = ScalarBackend().trace(scene, ray, params, 60);
        const Trace b = SimdBackend().trace(scene, ray, params, 60);
        EXPECT_EQ(b.steps, a.steps) << name << " " << to_string(m) << " pixel " << i;
        ASSERT_EQ(b.events.size(), a.events.size()) << name << " " << to_string(m);
        for (size_t e = 0; e < a.events.size(); ++e) {
          EXPECT_EQ(b.events[e].kind, a.events[e].kind) << name << " event " << e;
          EXPECT_EQ(b.events[e].polygon, a.events[e].polygon) << name << " event " << e;
          EXPECT_EQ(b.events[e].edge, a.events[e].edge) << name << " event " << e;
          EXPECT_EQ(b.events[e].to_polygon, a.events[e].to_polygon) << name << " event " << e;
          EXPECT_EQ(b.events[e].object, a.events[e].object) << name << " event " << e;
          EXPECT_NEAR(b.events[e].t, a.events[e].t, 1e-5 * (1.0 + a.events[e].t));
        }
      }
    }
  }
}

// Every step of every ray is one active lane of one pass, so the active lanes add up to the
// frame's steps; the slots are whole vectors.
TEST(Simd, LaneCountsAddUpToTheSteps) {
  const Scene& scene = test::gallery_scene("l_shape");
  const SimdBackend simd;
  MarchParams params;
  params.method = Method::analytic;
  simd::LaneCounts lanes;
  const Frame frame = simd.render_counted(scene, scene.camera, 77, 33, params, {}, lanes);
  const double steps = std::accumulate(frame.steps.begin(), frame.steps.end(), 0.0);
  EXPECT_EQ(static_cast<double>(lanes.active), steps);
  EXPECT_EQ(lanes.slots % simd.lanes(), 0);
  EXPECT_GT(lanes.slots, lanes.active);  // 77x33 does not fill the edge tiles
}

// The peak's packet (PacketCode::room_steps): the central tile's rays from the camera, each
// repeat one step of every lane; a packet whose rays all end as they start has no step to time.
TEST(Simd, RoomStepsStepEveryLaneOfTheCentralPacket) {
  const Scene& scene = test::gallery_scene("torus");
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, {});
  Frame none;
  const simd::PacketCode code = simd::packet_code(0);
  EXPECT_EQ(code.room_steps(simd::frame_job(tables, scene.camera, 64, 48, none), 5),
            5 * code.lanes());
  EXPECT_GT(SimdBackend().peak_lane_steps(scene, scene.camera, 64, 48, {}, 0.01), 0.0);

  // Above the band, looking up: every ray misses as it starts.
  Camera up = scene.camera;
  up.position.z = 2.0 * tables.params.height + 1.0;
  up.pitch_deg = 80.0;
  const simd::PacketJob job = simd::frame_job(tables, up, 64, 48, none);
  EXPECT_EQ(code.room_steps(job, 5), 0);
  EXPECT_EQ(SimdBackend().peak_lane_steps(scene, up, 64, 48, {}, 0.01), 0.0);
}

// What the packets read of a scene's edges, worked out once a frame (simd::EdgeTables). The
// squares of a staircase drawn in one place are alike in every number; drawn apart (square k at
// [2k, 2k + 2] x [0, 2]) only what does not depend on x is: each edge's y, its direction and
// normal. Edge 1 of square k is glued to square k + 1 (k even), edge 2 to the square above.
TEST(Simd, EdgeTablesFindTheNumbersAlikeInEveryRoom) {
  for (const bool apart : {false, true}) {
    const Scene scene = staircase_surface(8, apart);
    const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, {});
    const simd::EdgeTables t = simd::packet_job(tables).edges;
    SCOPED_TRACE(scene.name);
    EXPECT_EQ(t.most_edges, 4);
    EXPECT_TRUE(t.same_count);
    EXPECT_EQ(t.same_rooms, !apart);
    EXPECT_EQ(t.same_first_edge, 0);
    EXPECT_EQ(t.alike[simd::kAy], 0xfu);
    EXPECT_EQ(t.alike[simd::kNx], 0xfu);
    EXPECT_EQ(t.alike[simd::kAbx], 0xfu);
    EXPECT_EQ(t.alike[simd::kAx], apart ? 0x0u : 0xfu);
    const std::array<float, 4> ay{0.0f, 0.0f, 2.0f, 2.0f}, abx{2.0f, 0.0f, -2.0f, 0.0f};
    for (size_t k = 0; k < 4; ++k) {
      EXPECT_EQ(t.alike_number[simd::kAy][k], ay[k]) << "edge " << k;
      EXPECT_EQ(t.alike_number[simd::kAbx][k], abx[k]) << "edge " << k;
    }
    // Square 2's edges: 8 to 11 in the edge table.
    ASSERT_EQ(tables.polygons[2].x, 8);
    EXPECT_EQ(t.number[simd::kAx][8], apart ? 4.0f : 0.0f);
    EXPECT_EQ(t.to_polygon[9], 3);   // right: square 3
    EXPECT_EQ(t.to_polygon[10], 1);  // top: square 1
    EXPECT_EQ(t.to_polygon[11], 3);  // left: square 3's right edge is glued to it
    EXPECT_EQ(std::count(t.wall.begin(), t.wall.end(), -1), 0);
    // Drawn in one place, every square's right edge is glued by the same translation, (-2, 0)
    // (glue fields 0 and 1: the map's shift): a crossing reads it by slot, and its room and
    // tint's number (the 8 squares' 16 gluings take the palette's 10 colours in turn) by one
    // gather.
    EXPECT_EQ(t.glue_by_slot, !apart);
    if (apart) continue;
    EXPECT_EQ(t.slot_glue[0][1], -2.0f);
    EXPECT_EQ(t.slot_glue[1][1], 0.0f);
    EXPECT_EQ(t.slot_glue[1][2], -2.0f);
    EXPECT_EQ(t.tints.size(), 10u);
    EXPECT_EQ(t.slot_code[9] & 0xffff, 3);  // square 2, edge 1: square 3
    EXPECT_EQ(t.slot_code[10] & 0xffff, 1);
    EXPECT_EQ(t.tints[static_cast<size_t>((t.slot_code[9] >> 16) & 0xff)], tables.edges[9].tint);
    // The seams: what each edge's ends are in its code, where they lie by slot (one place).
    for (size_t e = 0; e < tables.edges.size(); ++e) {
      EXPECT_EQ((t.slot_code[e] >> 24) & 3, static_cast<int>(tables.edges[e].seam.z));
      EXPECT_EQ((t.slot_code[e] >> 26) & 3, static_cast<int>(tables.edges[e].seam.w));
    }
    EXPECT_TRUE(t.seam_by_slot);
    EXPECT_EQ(t.slot_seam[0][1], tables.edges[9].seam.x);
    EXPECT_EQ(t.slot_seam[1][1], tables.edges[9].seam.y);
  }
}

TEST(Simd, AnUnknownInstructionSetIsUnavailableAndSaysWhy) {
  const Scene& scene = test::gallery_scene("torus");
  const SimdBackend unknown({.isa = "avx9000"});
  EXPECT_FALSE(unknown.availability().available);
  EXPECT_NE(unknown.availability().reason.find("unknown"), std::string::npos);
  EXPECT_THROW(unknown.render(scene, scene.camera, 8, 8, {}, {}), std::runtime_error);
}

TEST(Simd, RefusesAFrameOfMorePixelsThanItsLanesCanNumber) {
  const Scene& scene = test::gallery_scene("torus");
  const SimdBackend simd;
  if (!simd.availability().available) GTEST_SKIP() << simd.availability().reason;
  EXPECT_THROW(simd.render(scene, scene.camera, -1, 8, {}, {}), std::invalid_argument);
  // 2^31 pixels: refused before the frame's memory is asked for.
  EXPECT_THROW(simd.render(scene, scene.camera, 65536, 32768, {}, {}), std::invalid_argument);
  EXPECT_EQ(simd.render(scene, scene.camera, 1, 1, {}, {}).hit.size(), 1u);
}

TEST(CliSimd, IsTheDefaultOfRenderAndTakesItsOptions) {
  const std::string scene = FLATMARCH_SOURCE_DIR "/scenes/torus.json";
  const std::string out = test::make_temp_dir() + "/simd_default.png";
  const auto r = test::run_flatmarch({"render", scene, "-o", out, "--size", "16x9"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("simd/analytic"), std::string::npos) << r.err;  // render's default method
  const auto one =
      test::run_flatmarch({"render", scene, "-o", out, "--size", "16x9", "--threads", "1", "--isa",
                           simd::isa_names(true).back(), "--method", "sphere"});
  EXPECT_EQ(one.exit_code, 0) << one.err;
  const auto bad_isa = test::run_flatmarch({"render", scene, "-o", out, "--isa", "avx9000"});
  EXPECT_EQ(bad_isa.exit_code, 2);
  EXPECT_NE(bad_isa.err.find("--isa: unknown instruction set"), std::string::npos) << bad_isa.err;
  const auto f64 = test::run_flatmarch({"render", scene, "-o", out, "--precision", "f64"});
  EXPECT_EQ(f64.exit_code, 2);
  EXPECT_NE(f64.err.find("does not march in f64"), std::string::npos) << f64.err;
  const auto threads = test::run_flatmarch({"render", scene, "-o", out, "--threads", "-2"});
  EXPECT_EQ(threads.exit_code, 2);
  const auto listed = test::run_flatmarch({"backends"});
  EXPECT_NE(listed.out.find("simd instruction sets this CPU runs"), std::string::npos);
}

}  // namespace
}  // namespace flatmarch
