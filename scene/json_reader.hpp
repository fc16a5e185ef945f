// Typed, path-aware access to a JSON document: every accessor either returns a valid value or
// throws SceneError naming the JSON pointer of the offending value.
#pragma once

#include <cmath>
#include <initializer_list>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "scene/geometry.hpp"
#include "scene/load.hpp"

namespace flatmarch {

class JsonNode {
 public:
  JsonNode(const nlohmann::json& value, std::string pointer, const std::string& file)
      : value_(&value), pointer_(std::move(pointer)), file_(&file) {}

  const nlohmann::json& json() const { return *value_; }
  const std::string& pointer() const { return pointer_.empty() ? root_ : pointer_; }
  const std::string& file() const { return *file_; }

  [[noreturn]] void fail(const std::string& what_is_wrong) const {
    throw SceneError(*file_, pointer(), what_is_wrong);
  }

  bool has(std::string_view key) const { return value_->is_object() && value_->contains(key); }
  JsonNode operator[](std::string_view key) const;
  JsonNode operator[](size_t index) const;

  JsonNode object() const;  // checks the value is an object
  size_t array_size(size_t min_size = 0, size_t max_size = SIZE_MAX) const;
  void allow_keys(std::initializer_list<const char*> keys) const;

  double number() const;
  double positive() const;
  bool boolean() const;
  std::string string() const;
  int index(int limit, const char* what) const;  // an integer in [0, limit)
  Vec2 vec2() const;
  Vec3 vec3() const;
  Vec3 color() const;  // three numbers in [0, 1]

 private:
  static inline const std::string root_ = "/";
  const nlohmann::json* value_;
  std::string pointer_;
  const std::string* file_;
};

// A short description of a JSON value's type, for error messages.
std::string json_type_name(const nlohmann::json& v);

}  // namespace flatmarch
