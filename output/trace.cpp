#include "output/trace.hpp"

#include <array>
#include <utility>

namespace flatmarch {

namespace {

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

}  // namespace

const char* to_string(EventKind k) {
  return name_of(kEventKinds, k);
}

}  // namespace flatmarch
