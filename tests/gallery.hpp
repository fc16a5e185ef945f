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
