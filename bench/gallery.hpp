// What the benchmark programs share: the gallery scenes and the counters of a rendered frame.
#pragma once

#include <benchmark/benchmark.h>
#include <malloc.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "backends/backend.hpp"
#include "reports/matrix.hpp"
#include "scene/load.hpp"

namespace flatmarch::bench {

using reports::frame_counters;  // the counters every benchmark program reports

// Frames are renders' largest allocations (7 MB at 640x360). By default glibc gives memory that
// big back to the system when it is freed and maps it afresh for the next frame, whose pages
// then fault in one by one (about 4 ms a frame here, mostly serialised in the kernel). A renderer
// that draws frame after frame keeps the memory; so do the benchmarks, for every backend alike.
inline void keep_freed_frames() {
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

// Takes a program's own flags, --NAME=VALUE with NAME one of `names`, out of argv before Google
// Benchmark reads it (it reports flags it does not know); returns their values by name.
inline std::map<std::string, std::string> take_flags(int& argc, char** argv,
                                                     const std::vector<std::string>& names) {
  std::map<std::string, std::string> values;
  for (int k = 1; k < argc;) {
    const std::string arg = argv[k];
    const auto name = std::find_if(names.begin(), names.end(), [&](const std::string& n) {
      return arg.rfind("--" + n + "=", 0) == 0;
    });
    if (name == names.end()) {
      ++k;
      continue;
    }
    values[*name] = arg.substr(name->size() + 3);
    std::copy(argv + k + 1, argv + argc + 1, argv + k);
    --argc;
  }
  return values;
}

// A --size value, WxH with each 1 to 8192, into width and height; false if it is not one.
inline bool parse_size(const std::string& text, int& width, int& height) {
  return std::sscanf(text.c_str(), "%dx%d", &width, &height) == 2 && width >= 1 && height >= 1 &&
         width <= 8192 && height <= 8192;
}

// What a benchmark program does first: keep freed frames and take Google Benchmark's flags.
// False when a flag is unknown (it has been reported; exit with 2).
inline bool begin(int& argc, char** argv) {
  keep_freed_frames();
  benchmark::Initialize(&argc, argv);
  return !benchmark::ReportUnrecognizedArguments(argc, argv);
}

// The gallery scenes (scenes/*.json), sorted by file name; pointers stay valid for benchmarks.
inline std::vector<std::unique_ptr<Scene>> load_gallery() {
  std::vector<std::filesystem::path> files;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(FLATMARCH_SOURCE_DIR) / "scenes"))
    if (entry.path().extension() == ".json") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  std::vector<std::unique_ptr<Scene>> scenes;
  for (const auto& f : files) scenes.push_back(std::make_unique<Scene>(load_scene(f)));
  return scenes;
}

}  // namespace flatmarch::bench
