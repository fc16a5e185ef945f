// Reading, validating and deriving scenes (DESIGN.md section 1). Every rule is checked; a
// violation is reported as `error: FILE: /json/path: what is wrong` through SceneError.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include "scene/scene.hpp"

namespace flatmarch {

class SceneError : public std::runtime_error {
 public:
  SceneError(std::string file, std::string pointer, std::string what_is_wrong);
  const std::string& file() const { return file_; }
  const std::string& pointer() const { return pointer_; }  // JSON pointer, "/" for the document
  const std::string& problem() const { return problem_; }

 private:
  std::string file_, pointer_, problem_;
};

// Limits that keep every input bounded in time and memory.
struct SceneLimits {
  static constexpr size_t max_file_bytes = 64u << 20;
  static constexpr int max_depth = 64;
  static constexpr int max_polygons = 10000;
  static constexpr int max_vertices_per_polygon = 10000;
  static constexpr int max_objects = 10000;
};

Scene load_scene(const std::filesystem::path& path);
// `file` names the source in errors; the scene's default name is its stem.
Scene parse_scene(std::string_view text, const std::string& file);
Scene scene_from_json(const nlohmann::json& doc, const std::string& file);

// The JSON reading under the scene's limits (size, nesting depth), for other JSON inputs too
// (import-peer): every problem is a SceneError at "/".
nlohmann::json parse_json(std::string_view text, const std::string& file);
nlohmann::json read_json_file(const std::filesystem::path& path);

}  // namespace flatmarch
