// Writing frames (DESIGN.md section 4): the colour as an 8-bit sRGB PNG and every AOV in one
// multi-channel float EXR beside it (out.png -> out.exr), both through OpenImageIO (loaded on
// first use: image_library.hpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "output/frame.hpp"

namespace flatmarch {

// The EXR written beside a PNG.
std::filesystem::path aov_path(const std::filesystem::path& png);

// Throws std::runtime_error with OpenImageIO's message when a file cannot be written.
void write_png(const Frame& frame, const std::filesystem::path& png);
void write_aov_exr(const Frame& frame, const std::filesystem::path& exr);

// Reads an EXR written by write_aov_exr back into a frame.
Frame read_aov_exr(const std::filesystem::path& exr);
// Reads any EXR's channels of those names (another program's): a channel it lacks is NaN, and
// bit k of `present` says whether channel k (R, G, B, steps, crossings, hit, t) was there.
Frame read_exr_channels(const std::filesystem::path& exr, unsigned& present);

// A PNG's colour as written: 8-bit sRGB, 3 bytes a pixel, rows from the top.
struct Png {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
};
Png read_png(const std::filesystem::path& png);

}  // namespace flatmarch
