// What the OpenGL and Vulkan test programs hold both GPU backends to, written once.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "backends/bands.hpp"
#include "backends/scalar/scalar.hpp"
#include "kernels/scene_shader.hpp"
#include "tests/gallery.hpp"

namespace flatmarch::test {

// A frame is drawn in bands (BandPacer): the first frame of a program starts with
// kFirstBandRows, a later one goes by the first one's pace; progress rises to 1 either way.
inline void expect_progress_in_bands(const Backend& backend) {
  const Scene& scene = gallery_scene("torus");
  // March parameters of this test's own: a program's first frame.
  MarchParams params;
  params.eps = 1.25e-4;
  std::vector<double> seen;
  backend.render(scene, scene.camera, 32, 200, params, [&](double f) { seen.push_back(f); });
  ASSERT_GE(seen.size(), 2u);
  EXPECT_DOUBLE_EQ(seen.front(), BandPacer::kFirstBandRows / 200.0);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);
  seen.clear();  // the next frame: bands by the first frame's pace, to the end
  backend.render(scene, scene.camera, 32, 200, params, [&](double f) { seen.push_back(f); });
  ASSERT_GE(seen.size(), 1u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);
}

// Frames from cameras within and outside the band [0, height]: the shader of a camera within it
// leaves out the entry into the band (kernel::scene_fragment_shader's `from_band`), and one
// outside keeps it. Both must see what the scalar kernel sees.
inline void expect_band_views_as_scalar(const Backend& backend) {
  for (const char* name : {"l_shape", "cube"}) {
    const Scene& scene = gallery_scene(name);
    Camera above = scene.camera;
    above.position.z = scene.height + 3.0;  // looking down into the rooms from above
    above.pitch_deg = -50.0;
    Camera below = scene.camera;
    below.position.z = -2.0;  // and up from below
    below.pitch_deg = 40.0;
    for (const Camera& camera : {scene.camera, above, below}) {
      constexpr int kWidth = 64, kHeight = 36;
      const Frame want = ScalarBackend().render(scene, camera, kWidth, kHeight, {}, {});
      const Frame got = backend.render(scene, camera, kWidth, kHeight, {}, {});
      size_t differ = 0, entered = 0;
      for (size_t px = 0; px < want.hit.size(); ++px) {
        differ += got.hit[px] != want.hit[px] || got.crossings[px] != want.crossings[px];
        entered += want.hit[px] != -1.0f;  // not a miss of every room
      }
      // A ray along an edge or through a vertex may go either way in another float unit.
      EXPECT_LE(differ, want.hit.size() / 100)
          << name << " from z = " << camera.position.z << ": " << differ << " pixels differ";
      EXPECT_GT(entered, want.hit.size() / 8) << name << ": the view must see the rooms";
    }
  }
}

// A scene of several rooms reads its tables from a buffer (kernel::tables_in_buffer), so two such
// scenes that differ in their tables alone have one shader: the cube, the cube with its solid
// moved and grown, and the cube again, drawn one after the other, must each see what the scalar
// kernel sees, whichever program a backend keeps.
inline void expect_each_scene_its_own_tables(const Backend& backend) {
  const Scene& cube = gallery_scene("cube");
  Scene moved = cube;
  moved.objects.at(0).center = Vec3(0.6, 1.3, 1.0);
  moved.objects.at(0).size = 0.4;
  const kernel::SceneTables<float> a = kernel::compile_scene<float>(cube, {}),
                                   b = kernel::compile_scene<float>(moved, {});
  ASSERT_TRUE(kernel::tables_in_buffer(a));
  ASSERT_NE(kernel::table_buffer(a), kernel::table_buffer(b));
  ASSERT_EQ(kernel::scene_compute_shader(a), kernel::scene_compute_shader(b));
  ASSERT_EQ(kernel::scene_fragment_shader(a), kernel::scene_fragment_shader(b));
  constexpr int kWidth = 64, kHeight = 36;
  std::vector<Frame> scalar;
  for (const Scene* scene : {&cube, static_cast<const Scene*>(&moved), &cube}) {
    const Frame want = ScalarBackend().render(*scene, scene->camera, kWidth, kHeight, {}, {});
    const Frame got = backend.render(*scene, scene->camera, kWidth, kHeight, {}, {});
    size_t differ = 0;
    for (size_t px = 0; px < want.hit.size(); ++px)
      differ += got.hit[px] != want.hit[px] || got.crossings[px] != want.crossings[px];
    EXPECT_LE(differ, want.hit.size() / 100)
        << scene->objects[0].size << ": " << differ << " pixels differ from the scalar kernel's";
    scalar.push_back(want);
    // A probe ray towards where the solid is in the moved scene: its events as the scalar's.
    const Ray probe{scene->camera.polygon, scene->camera.position,
                    glm::normalize(Vec3(0.6, 1.3, 1.0) - scene->camera.position)};
    const Trace want_trace = ScalarBackend().trace(*scene, probe, {}, 16);
    const Trace got_trace = backend.trace(*scene, probe, {}, 16);
    ASSERT_EQ(got_trace.events.size(), want_trace.events.size()) << scene->objects[0].size;
    for (size_t k = 0; k < want_trace.events.size(); ++k) {
      EXPECT_EQ(got_trace.events[k].kind, want_trace.events[k].kind) << k;
      EXPECT_EQ(got_trace.events[k].polygon, want_trace.events[k].polygon) << k;
    }
  }
  // The two scenes look different where the solid moved.
  size_t moved_pixels = 0;
  for (size_t px = 0; px < scalar[0].hit.size(); ++px)
    moved_pixels += scalar[0].hit[px] != scalar[1].hit[px];
  EXPECT_GT(moved_pixels, scalar[0].hit.size() / 50);
}

// A frame of the colour alone (Backend::render_colour) holds the whole frame's colour as a PNG
// holds it: tone-mapped linear colour sRGB-encoded in 8 bits (within a unit: the shader encodes
// in float32), alpha 255, and nothing else; and both kinds of frame are timed on the device.
inline void expect_colour_frames_as_whole_frames(const Backend& backend) {
  const Scene& scene = gallery_scene("cube");
  MarchParams params;
  params.method = Method::analytic;
  const Frame whole = backend.render(scene, scene.camera, 64, 36, params, {});
  const std::optional<DeviceTiming> whole_time = backend.last_device_timing();
  const Frame colour = backend.render_colour(scene, scene.camera, 64, 36, params, {});
  const std::optional<DeviceTiming> colour_time = backend.last_device_timing();
  ASSERT_EQ(colour.srgb.size(), 4 * whole.hit.size());
  EXPECT_TRUE(colour.rgb.empty());
  EXPECT_TRUE(colour.hit.empty() && colour.steps.empty() && colour.t.empty());
  size_t off = 0;
  for (size_t px = 0; px < whole.hit.size(); ++px) {
    for (size_t k = 0; k < 3; ++k) {
      const double c = std::clamp(static_cast<double>(whole.rgb[3 * px + k]), 0.0, 1.0);
      const double encoded = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
      off += std::abs(colour.srgb[4 * px + k] - 255.0 * encoded) > 1.0;
    }
    off += colour.srgb[4 * px + 3] != 255;
  }
  EXPECT_EQ(off, 0u) << "channels more than a unit from the whole frame's colour";
  for (const auto& t : {whole_time, colour_time}) {
    ASSERT_TRUE(t.has_value()) << "a GPU backend says how its device timed the frame";
    ASSERT_TRUE(t->measured) << t->why;  // llvmpipe and lavapipe have the queries
    EXPECT_GT(t->seconds(), 0.0);
    EXPECT_GE(t->march_s, 0.0);
    EXPECT_GE(t->readback_s, 0.0);
  }
}

}  // namespace flatmarch::test
