// A scene's own shader: the kernel specialised on the scene's features with its compiled tables
// baked in as constants (kernels/shader_source.hpp), and a main() that marches one pixel (or one
// probe ray). The OpenGL backend, the viewer and `flatmarch shader` use it.
#pragma once

#include <string>

#include "kernels/compile.hpp"

namespace flatmarch::kernel {

// The tables as GLSL constant arrays and the parameters as a constant, with exactly the values
// of `tables` (printed so that they read back as the same floats). Baked in, they let the
// compiler drop what this scene and these parameters never run (the other methods' code above
// all): GPU compilers and llvmpipe run both sides of a branch that is not known to be uniform.
// A change of parameters is a new program.
std::string baked_tables(const SceneTables<float>& tables);

// Uniforms of the fragment shader (scene_fragment_shader):
//   u_polygon, u_from         the camera's polygon and position
//   u_forward, u_right, u_up  its basis (kernels/camera.hpp)
//   u_scale                   (aspect * tan(fov / 2), tan(fov / 2))
//   u_size                    the image's width and height in pixels
// Outputs: location 0 the linear colour (rgb, 1), location 1 the AOVs (steps, crossings, hit, t).
// With `trace` it marches one probe ray instead (u_polygon, u_from and the direction u_forward)
// and writes its events to the event buffer (binding 4, see kernels/shader_prelude.glsl).
std::string scene_fragment_shader(const SceneTables<float>& tables, bool trace = false);

// A full-screen triangle, the vertex shader that goes with it.
extern const char* const kFullScreenVertexShader;

}  // namespace flatmarch::kernel
