// A GPU backend's frames from cameras within and outside the band [0, height]: the shader of a
// camera within it leaves out the entry into the band (kernel::scene_fragment_shader's
// `from_band`), and one outside keeps it. Both must see what the scalar kernel sees.
#pragma once

#include <gtest/gtest.h>

#include "backends/scalar/scalar.hpp"
#include "tests/gallery.hpp"

namespace flatmarch::test {

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

}  // namespace flatmarch::test
