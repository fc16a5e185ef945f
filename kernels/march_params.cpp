#include "kernels/march_params.hpp"

#include <utility>

namespace flatmarch {

namespace {

constexpr std::array<std::pair<Method, const char*>, 4> kMethods{{{Method::sphere, "sphere"},
                                                                  {Method::relaxed, "relaxed"},
                                                                  {Method::analytic, "analytic"},
                                                                  {Method::oracle, "oracle"}}};

}  // namespace

const char* to_string(Method m) {
  for (const auto& [v, name] : kMethods)
    if (v == m) return name;
  return "?";
}

std::optional<Method> parse_method(const std::string& name) {
  for (const auto& [v, n] : kMethods)
    if (name == n) return v;
  return std::nullopt;
}

std::string method_names() {
  std::string names;
  for (const auto& [m, name] : kMethods) names += (names.empty() ? "" : ", ") + std::string(name);
  return names;
}

const char* to_string(KernelShape s) {
  return s == KernelShape::software ? "software" : "gpu";
}

std::optional<KernelShape> parse_kernel_shape(const std::string& text, bool software_device) {
  if (text.empty() || text == "auto")
    return software_device ? KernelShape::software : KernelShape::gpu;
  if (text == "software") return KernelShape::software;
  if (text == "gpu") return KernelShape::gpu;
  return std::nullopt;
}

std::string kernel_shape_error(const std::string& text) {
  return parse_kernel_shape(text, false)
             ? ""
             : "--kernel-shape: expected auto, software or gpu, got \"" + text + "\"";
}

}  // namespace flatmarch
