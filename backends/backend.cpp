#include "backends/backend.hpp"

#include <array>
#include <utility>

#include "backends/oracle/oracle.hpp"
#include "backends/scalar/scalar.hpp"

namespace flatmarch {

namespace {

constexpr std::array<std::pair<Method, const char*>, 4> kMethods{{{Method::sphere, "sphere"},
                                                                  {Method::relaxed, "relaxed"},
                                                                  {Method::analytic, "analytic"},
                                                                  {Method::oracle, "oracle"}}};

constexpr std::array<std::pair<EventKind, const char*>, 11> kEventKinds{
    {{EventKind::gluing, "gluing"},
     {EventKind::mirror, "mirror"},
     {EventKind::enter, "enter"},
     {EventKind::object, "object"},
     {EventKind::wall, "wall"},
     {EventKind::floor, "floor"},
     {EventKind::escape, "escape"},
     {EventKind::vertex, "vertex"},
     {EventKind::max_steps, "max_steps"},
     {EventKind::max_distance, "max_distance"},
     {EventKind::miss, "miss"}}};

template <typename E, size_t N>
const char* name_of(const std::array<std::pair<E, const char*>, N>& table, E value) {
  for (const auto& [v, name] : table)
    if (v == value) return name;
  return "?";
}

template <typename E, size_t N>
std::optional<E> value_of(const std::array<std::pair<E, const char*>, N>& table,
                          const std::string& name) {
  for (const auto& [v, n] : table)
    if (name == n) return v;
  return std::nullopt;
}

}  // namespace

const char* to_string(Method m) {
  return name_of(kMethods, m);
}
std::optional<Method> parse_method(const std::string& name) {
  return value_of(kMethods, name);
}
const char* to_string(EventKind k) {
  return name_of(kEventKinds, k);
}

Frame::Frame(int w, int h)
    : width(w),
      height(h),
      rgb(3 * static_cast<size_t>(w) * static_cast<size_t>(h)),
      steps(static_cast<size_t>(w) * static_cast<size_t>(h)),
      crossings(steps.size()),
      hit(steps.size()),
      t(steps.size()) {}

const std::vector<std::unique_ptr<Backend>>& backends() {
  static const std::vector<std::unique_ptr<Backend>> all = [] {
    std::vector<std::unique_ptr<Backend>> v;
    v.push_back(std::make_unique<OracleBackend>());
    v.push_back(std::make_unique<ScalarBackend>());
    return v;
  }();
  return all;
}

const Backend* find_backend(const std::string& name) {
  for (const auto& b : backends())
    if (b->name() == name) return b.get();
  return nullptr;
}

}  // namespace flatmarch
