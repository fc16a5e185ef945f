// The viewer's controls: what each key does, the movement keys held down, and the march
// settings the keys step through. Pure state, no window: real input and scripted input
// (viewer/script.hpp) drive the same handlers. Keys are GLFW key codes.
#pragma once

#include <set>

#include "kernels/march_params.hpp"
#include "scene/geometry.hpp"

namespace flatmarch::viewer {

// What a key press does besides moving (movement keys are read from HeldKeys each frame).
enum class Command {
  none,
  method_sphere,    // 1
  method_relaxed,   // 2
  method_analytic,  // 3
  eps_down,         // [
  eps_up,           // ]
  offset_down,      // ;
  offset_up,        // '
  scale_down,       // -
  scale_up,         // =
  next_scene,       // Tab (Shift+Tab: the previous one)
  screenshot,       // F12
  escape,           // Esc: release the cursor, or quit when it is released
};

Command command_for_key(int key);

// The movement keys held down: W/S forward and back, D/A right and left, E/Q up and down, Shift
// faster.
class HeldKeys {
 public:
  void press(int key) { held_.insert(key); }
  void release(int key) { held_.erase(key); }
  void clear() { held_.clear(); }
  bool held(int key) const { return held_.count(key) > 0; }
  // (forward, right, up) for one unit of travel: the horizontal part of length 0 or 1 (W and D
  // together go diagonally at the same speed), up -1, 0 or 1.
  Vec3 direction() const;
  bool fast() const;  // Shift held

 private:
  std::set<int> held_;
};

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

}  // namespace flatmarch::viewer
