#include "scene/json_reader.hpp"

#include <algorithm>
#include <limits>

namespace flatmarch {

namespace {

std::string escape_token(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~')
      out += "~0";
    else if (c == '/')
      out += "~1";
    else
      out += c;
  }
  return out;
}

}  // namespace

std::string json_type_name(const nlohmann::json& v) {
  switch (v.type()) {
    case nlohmann::json::value_t::null:
      return "null";
    case nlohmann::json::value_t::object:
      return "an object";
    case nlohmann::json::value_t::array:
      return "an array";
    case nlohmann::json::value_t::string:
      return "a string";
    case nlohmann::json::value_t::boolean:
      return "a boolean";
    case nlohmann::json::value_t::number_integer:
    case nlohmann::json::value_t::number_unsigned:
    case nlohmann::json::value_t::number_float:
      return "a number";
    default:
      return "an unsupported value";
  }
}

JsonNode JsonNode::operator[](std::string_view key) const {
  object();
  const auto it = value_->find(key);
  if (it == value_->end()) fail("missing required key \"" + std::string(key) + "\"");
  return {*it, pointer_ + "/" + escape_token(std::string(key)), *file_};
}

JsonNode JsonNode::operator[](size_t index) const {
  return {value_->at(index), pointer_ + "/" + std::to_string(index), *file_};
}

JsonNode JsonNode::object() const {
  if (!value_->is_object()) fail("expected an object, found " + json_type_name(*value_));
  return *this;
}

size_t JsonNode::array_size(size_t min_size, size_t max_size) const {
  if (!value_->is_array()) fail("expected an array, found " + json_type_name(*value_));
  const size_t n = value_->size();
  if (n < min_size)
    fail("expected at least " + std::to_string(min_size) + " elements, found " + std::to_string(n));
  if (n > max_size)
    fail("expected at most " + std::to_string(max_size) + " elements, found " + std::to_string(n));
  return n;
}

void JsonNode::allow_keys(std::initializer_list<const char*> keys) const {
  object();
  for (const auto& item : value_->items()) {
    const std::string& key = item.key();
    const bool known =
        std::any_of(keys.begin(), keys.end(), [&](const char* k) { return key == k; });
    if (!known) {
      std::string list;
      for (const char* k : keys) list += std::string(list.empty() ? "" : ", ") + k;
      JsonNode{item.value(), pointer_ + "/" + escape_token(key), *file_}.fail(
          "unknown key \"" + key + "\" (expected one of: " + list + ")");
    }
  }
}

double JsonNode::number() const {
  if (!value_->is_number()) fail("expected a number, found " + json_type_name(*value_));
  const double v = value_->get<double>();
  if (!std::isfinite(v)) fail("expected a finite number");
  return v;
}

double JsonNode::positive() const {
  const double v = number();
  if (!(v > 0.0)) fail("expected a positive number, found " + value_->dump());
  return v;
}

bool JsonNode::boolean() const {
  if (!value_->is_boolean()) fail("expected true or false, found " + json_type_name(*value_));
  return value_->get<bool>();
}

std::string JsonNode::string() const {
  if (!value_->is_string()) fail("expected a string, found " + json_type_name(*value_));
  return value_->get<std::string>();
}

int JsonNode::index(int limit, const char* what) const {
  if (!value_->is_number())
    fail(std::string("expected ") + what + " index, found " + json_type_name(*value_));
  const double v = value_->get<double>();
  if (!(v == std::floor(v)))
    fail(std::string("expected an integer ") + what + " index, found " + value_->dump());
  if (v < 0.0 || v >= static_cast<double>(limit))
    fail(std::string(what) + " index " + value_->dump() + " out of range (there " +
         (limit == 1 ? "is 1 " : "are " + std::to_string(limit) + " ") + what +
         (limit == 1 ? ")" : "s)"));
  return static_cast<int>(v);
}

Vec2 JsonNode::vec2() const {
  array_size(2, 2);
  return {(*this)[0].number(), (*this)[1].number()};
}

Vec3 JsonNode::vec3() const {
  array_size(3, 3);
  return {(*this)[0].number(), (*this)[1].number(), (*this)[2].number()};
}

Vec3 JsonNode::color() const {
  const Vec3 c = vec3();
  for (int i = 0; i < 3; ++i)
    if (c[i] < 0.0 || c[i] > 1.0)
      (*this)[static_cast<size_t>(i)].fail("colour components lie in [0, 1]");
  return c;
}

}  // namespace flatmarch
