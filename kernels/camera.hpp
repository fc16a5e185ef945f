// The camera of DESIGN.md section 2. Every backend builds its primary rays from this, so that
// images are comparable pixel by pixel.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "kernels/constants.hpp"

namespace flatmarch {

namespace kernel {
// kernels/maths.glsl for plain C++ outside the kernel, in precision `real` (camera_ray here).
template <typename real>
struct Maths {
  using vec2 = typename Types<real>::vec2;
  using vec3 = typename Types<real>::vec3;
  using vec4 = typename Types<real>::vec4;
#include "kernels/maths.glsl"
};
}  // namespace kernel

template <typename T>
struct CameraBasis {
  glm::vec<3, T> forward, right, up;
  T tan_half_fov;  // of the vertical field of view
  T aspect;        // width / height
};

template <typename T>
CameraBasis<T> camera_basis(T yaw_deg, T pitch_deg, T fov_deg, int width, int height) {
  const T a = glm::radians(yaw_deg), b = glm::radians(pitch_deg);
  CameraBasis<T> c;
  c.forward = {std::cos(b) * std::cos(a), std::cos(b) * std::sin(a), std::sin(b)};
  c.right = {std::sin(a), -std::cos(a), T(0)};
  c.up = glm::cross(c.right, c.forward);
  c.tan_half_fov = std::tan(glm::radians(fov_deg) / T(2));
  c.aspect = T(width) / T(height);
  return c;
}

// Unit direction through the image point (x, y), in pixels from the top left corner.
template <typename T>
glm::vec<3, T> camera_ray_at(const CameraBasis<T>& c, T x, T y, int width, int height) {
  return kernel::Maths<T>().camera_ray(c.forward, c.right, c.up, c.tan_half_fov, c.aspect,
                                       glm::vec<2, T>(x, y), glm::vec<2, T>(T(width), T(height)));
}

// Unit direction of pixel (i, j), row j = 0 at the top: through its centre.
template <typename T>
glm::vec<3, T> camera_ray(const CameraBasis<T>& c, int i, int j, int width, int height) {
  return camera_ray_at(c, T(i) + T(0.5), T(j) + T(0.5), width, height);
}

}  // namespace flatmarch
