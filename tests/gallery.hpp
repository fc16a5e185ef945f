// The gallery scenes (scenes/*.json) as the tests find them. Needs FLATMARCH_SOURCE_DIR.
#pragma once

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "scene/load.hpp"

namespace flatmarch::test {

// The gallery's scene files, sorted.
inline std::vector<std::filesystem::path> gallery_files() {
  std::vector<std::filesystem::path> files;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(FLATMARCH_SOURCE_DIR) / "scenes"))
    if (entry.path().extension() == ".json") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

// Of the per-scene cases that render a whole frame through the command line (a process that
// loads OpenImageIO: CliScalar's 56 processes took 34 s under the sanitizers), a sanitizer build
// runs those of every kSanitizedStride-th gallery scene: the same code on fewer scenes. The
// -Werror build runs all.
#ifdef FLATMARCH_SANITIZE_BUILD
inline constexpr size_t kSanitizedStride = 4;
#else
inline constexpr size_t kSanitizedStride = 1;
#endif

// Whether such a case runs on the gallery scene of this file here.
inline bool in_sanitized_sample(const std::filesystem::path& file) {
  const std::vector<std::filesystem::path> files = gallery_files();
  const auto at = std::find(files.begin(), files.end(), file);
  return at == files.end() || static_cast<size_t>(at - files.begin()) % kSanitizedStride == 0;
}

// Their names (file stems), sorted.
inline std::vector<std::string> gallery_names() {
  std::vector<std::string> names;
  for (const auto& file : gallery_files()) names.push_back(file.stem().string());
  return names;
}

// A gallery scene by name, loaded once.
inline const Scene& gallery_scene(const std::string& name) {
  static std::map<std::string, Scene> cache;
  auto it = cache.find(name);
  if (it == cache.end())
    it = cache
             .emplace(name, load_scene(std::filesystem::path(FLATMARCH_SOURCE_DIR) / "scenes" /
                                       (name + ".json")))
             .first;
  return it->second;
}

}  // namespace flatmarch::test
