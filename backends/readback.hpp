// A GPU backend's frame as it comes back from the device (kernels/scene_shader.hpp's Readback),
// unpacked into a Frame: the OpenGL and Vulkan backends lay their read-backs out alike.
#pragma once

#include <cstddef>

#include "backends/backend.hpp"

namespace flatmarch {

// Bytes a pixel: a frame of the colour alone (one packed sRGB uint), a whole frame (two uvec4).
inline constexpr size_t kColourReadbackBytes = 4, kWholeReadbackBytes = 32;

// A frame of the colour alone from width x height packUnorm4x8 words (r in the low byte).
Frame colour_frame(const void* words, int width, int height);

// A whole frame from, for every pixel, the float bits of its linear colour (r, g, b, 1), then
// for every pixel its AOVs as integers (steps, crossings, hit in two's complement) and t's float
// bits: 4 words a pixel each.
Frame whole_frame(const void* words, int width, int height);

}  // namespace flatmarch
