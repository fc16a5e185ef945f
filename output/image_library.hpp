// OpenImageIO, as a separately loaded module (flatmarch_image.so, built from image_module.cpp):
// Debian's libOpenImageIO brings about 250 shared libraries (codecs, OpenCV, GDAL, ...) whose
// loading takes about 0.2 s, so only the commands that read, write or compare images load it,
// when they first do. The module's functions take and return plain frames; they throw
// std::runtime_error with OpenImageIO's message. A machine may lack the library (a GPU machine
// lent for minutes, say): the report, the conformance suite, the sweep and the benchmarks
// measure there without it, and leave out only the images and Yee's perceptual metric.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "output/frame.hpp"

namespace flatmarch {

struct ImageLibrary {
  int abi = 0;  // kImageLibraryAbi of the module's build: a stale module is refused
  const char* (*version)() = nullptr;  // OpenImageIO's version, as loaded
  // The colour as an 8-bit sRGB PNG (clamped); every channel as a float EXR.
  void (*write_png)(const Frame& frame, const std::string& path) = nullptr;
  void (*write_aov_exr)(const Frame& frame, const std::string& path) = nullptr;
  // An EXR written by write_aov_exr, into `frame` (resized). With `present` null every channel
  // must be there; else a channel the file lacks is NaN and bit k of *present says whether
  // channel k (R, G, B, steps, crossings, hit, t) was there (another program's EXR).
  void (*read_aov_exr)(const std::string& path, Frame& frame, unsigned* present) = nullptr;
  // A PNG's colour as written, 8-bit sRGB, 3 bytes a pixel (rows from the top).
  void (*read_png)(const std::string& path, std::vector<uint8_t>& rgb, int& width,
                   int& height) = nullptr;
  // The number of pixels of two colour images (linear, frame.rgb) that Yee's perceptual metric
  // tells apart (ImageBufAlgo::compare_Yee).
  size_t (*perceptual)(const Frame& a, const Frame& b) = nullptr;
};

// Changes whenever ImageLibrary or a type it passes changes.
constexpr int kImageLibraryAbi = 4;

// The module, loaded on first call from $FLATMARCH_MODULE_DIR (there alone, where it is set),
// else lib/flatmarch beside the program's folder (dynamic_library.hpp's kModuleFolder); throws
// std::runtime_error saying where it looked and why it could not load.
const ImageLibrary& image_library();
// The same, or null where it cannot be loaded, with the reason in `why` (when given): for work
// whose results are figures, which it goes on without (images left out, said once).
const ImageLibrary* image_library_if_loadable(std::string* why = nullptr);

}  // namespace flatmarch

// The module's one entry point.
extern "C" const flatmarch::ImageLibrary* flatmarch_image_library();
