// What a first-person walker's keys change, shared by the viewer (viewer/controls.hpp) and the
// web page (web/page.js, which reads these numbers from the page): its speed and mouse look, and
// the march settings (eps, offset, the render scale) its keys step through.
#pragma once

#include "kernels/march_params.hpp"

namespace flatmarch::motion {

// Camera speed: scene.scale times this per second, kFastFactor times that with Shift held.
inline constexpr double kSpeedPerScale = 0.5;
inline constexpr double kFastFactor = 4.0;
// Mouse look: degrees per pixel of mouse motion.
inline constexpr double kDegreesPerPixel = 0.1;

// eps and offset step by a quarter decade (x or / 10^0.25) within these bounds, and offset is
// kept above eps: a rise of eps carries offset up with it, and offset does not step down to eps
// or below (a ray pushed no further than eps from the edge it came through would cross back).
inline constexpr double kMinEps = 1e-7, kMaxEps = 1e-2;
inline constexpr double kMaxOffset = 0.5;
// The render scale steps by a factor sqrt(2) within these bounds.
inline constexpr double kMinScale = 1.0 / 16.0, kMaxScale = 1.0;

// The march parameters the keys change. Values are derived from integer step counts, so that
// stepping up and back down gives the same parameters exactly (and the same compiled program).
class MarchSettings {
 public:
  // `start` must have offset > eps, eps and offset within the bounds above.
  explicit MarchSettings(const MarchParams& start) : start_(start) {}
  MarchParams params() const;
  void set_method(Method m) { start_.method = m; }
  // Each returns whether anything changed.
  bool step_eps(int steps);
  bool step_offset(int steps);

 private:
  MarchParams start_;
  int eps_steps_ = 0, offset_steps_ = 0;
};

// The render scale, stepping by sqrt(2) from its start within [kMinScale, kMaxScale].
class RenderScale {
 public:
  explicit RenderScale(double start) : start_(start) {}
  double value() const;
  bool step(int steps);  // whether it changed

 private:
  double start_;
  int steps_ = 0;
};

}  // namespace flatmarch::motion
