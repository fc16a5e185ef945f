// The viewer's controls: what each key does and the movement keys held down (the speeds and the
// march settings the keys step through are motion/settings.hpp's, which the web page shares).
// Pure state, no window: real input and scripted input (viewer/script.hpp) drive the same
// handlers. Keys are GLFW key codes.
#pragma once

#include <set>

#include "motion/settings.hpp"
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

}  // namespace flatmarch::viewer
