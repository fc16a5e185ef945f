// OpenImageIO, as a separately loaded module (flatmarch_image.so, built from image_module.cpp):
// Debian's libOpenImageIO brings about 250 shared libraries (codecs, OpenCV, GDAL, ...) whose
// loading takes about 0.2 s, so only the commands that read, write or compare images load it,
// when they first do. The module's functions take and return plain frames; they throw
// std::runtime_error with OpenImageIO's message.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "backends/backend.hpp"

namespace flatmarch {

// OpenImageIO's comparison of two colour images (ImageBufAlgo::compare, as idiff) and the
// number of pixels Yee's perceptual metric tells apart (ImageBufAlgo::compare_Yee).
struct ColourComparison {
  double mean_error = 0.0, rms_error = 0.0, psnr = 0.0, max_error = 0.0;
  int max_x = 0, max_y = 0;
  size_t warn = 0, fail = 0, perceptual = 0;
};

struct ImageLibrary {
  int abi = 0;  // kImageLibraryAbi of the module's build: a stale module is refused
  const char* (*version)() = nullptr;  // OpenImageIO's version, as loaded
  // The colour as an 8-bit sRGB PNG (clamped); every channel as a float EXR.
  void (*write_png)(const Frame& frame, const std::string& path) = nullptr;
  void (*write_aov_exr)(const Frame& frame, const std::string& path) = nullptr;
  // An EXR written by write_aov_exr, into `frame` (resized).
  void (*read_aov_exr)(const std::string& path, Frame& frame) = nullptr;
  // A PNG's colour as written, 8-bit sRGB, 3 bytes a pixel (rows from the top).
  void (*read_png)(const std::string& path, std::vector<uint8_t>& rgb, int& width,
                   int& height) = nullptr;
  ColourComparison (*compare)(const Frame& a, const Frame& b, float fail, float warn) = nullptr;
};

// Changes whenever ImageLibrary or a type it passes changes.
constexpr int kImageLibraryAbi = 2;

// The module, loaded on first call from FLATMARCH_MODULE_DIR (environment), the build's module
// folder, or ../lib beside the program; throws std::runtime_error saying where it looked and why
// it could not load.
const ImageLibrary& image_library();

}  // namespace flatmarch

// The module's one entry point.
extern "C" const flatmarch::ImageLibrary* flatmarch_image_library();
