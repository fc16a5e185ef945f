#include "viewer/controls.hpp"

#include <algorithm>
#include <cmath>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace flatmarch::viewer {

Command command_for_key(int key) {
  switch (key) {
    case GLFW_KEY_1:
      return Command::method_sphere;
    case GLFW_KEY_2:
      return Command::method_relaxed;
    case GLFW_KEY_3:
      return Command::method_analytic;
    case GLFW_KEY_LEFT_BRACKET:
      return Command::eps_down;
    case GLFW_KEY_RIGHT_BRACKET:
      return Command::eps_up;
    case GLFW_KEY_SEMICOLON:
      return Command::offset_down;
    case GLFW_KEY_APOSTROPHE:
      return Command::offset_up;
    case GLFW_KEY_MINUS:
      return Command::scale_down;
    case GLFW_KEY_EQUAL:
      return Command::scale_up;
    case GLFW_KEY_TAB:
      return Command::next_scene;
    case GLFW_KEY_F12:
      return Command::screenshot;
    case GLFW_KEY_ESCAPE:
      return Command::escape;
    default:
      return Command::none;
  }
}

Vec3 HeldKeys::direction() const {
  const auto axis = [&](int plus, int minus) {
    return (held(plus) ? 1.0 : 0.0) - (held(minus) ? 1.0 : 0.0);
  };
  Vec2 horizontal(axis(GLFW_KEY_W, GLFW_KEY_S), axis(GLFW_KEY_D, GLFW_KEY_A));
  if (horizontal.x != 0.0 && horizontal.y != 0.0) horizontal /= std::sqrt(2.0);
  return {horizontal.x, horizontal.y, axis(GLFW_KEY_E, GLFW_KEY_Q)};
}

bool HeldKeys::fast() const {
  return held(GLFW_KEY_LEFT_SHIFT) || held(GLFW_KEY_RIGHT_SHIFT);
}

}  // namespace flatmarch::viewer
