#include "backends/simd/edge_tables.hpp"

#include <algorithm>
#include <cstring>
#include <optional>
#include <utility>

namespace flatmarch::simd {
namespace {

using kernel::ivec4;
using EdgeRecord = kernel::Tables<float>::EdgeRecord;

// The number every number `each` offers holds, bit for bit (each(take) calls take(x) for each
// x); none if they differ or there is none.
template <typename Each>
std::optional<float> alike(const Each& each) {
  std::optional<float> number;
  bool same = true;
  each([&](float x) {
    same = same && (!number || std::memcmp(&x, &*number, sizeof(float)) == 0);
    if (!number) number = x;
  });
  return same ? number : std::nullopt;
}

// EdgeTables::glue_by_slot and what it reads, where the scene allows.
void slot_gluings(const kernel::SceneTables<float>& tables, EdgeTables& t) {
  const auto glued = [](const EdgeRecord& e) { return e.link.x == kEdgeGlued; };
  if (tables.polygons.empty() || !t.same_count || t.most_edges > kAlikeSlots ||
      tables.polygons.size() >= (size_t{1} << 16) ||
      !std::all_of(tables.edges.begin(), tables.edges.end(), glued))
    return;
  for (size_t f = 0; f < kSlotGlueFields; ++f)
    for (int k = 0; k < t.most_edges; ++k) {
      const std::optional<float> number = alike([&](const auto& take) {
        for (const ivec4& p : tables.polygons) take(t.glue[f][static_cast<size_t>(p.x + k)]);
      });
      if (!number) return;
      t.slot_glue[f][static_cast<size_t>(k)] = *number;
    }
  std::vector<glm::vec4> tints;
  std::vector<int32_t> code;
  for (const ivec4& p : tables.polygons)
    for (int k = 0; k < p.y; ++k) {
      const EdgeRecord& e = tables.edges[static_cast<size_t>(p.x + k)];
      const auto same = [&](const glm::vec4& c) {
        return std::memcmp(&c, &e.tint, sizeof(c)) == 0;
      };
      auto tint = std::find_if(tints.begin(), tints.end(), same);
      if (tint == tints.end()) {
        if (tints.size() == kAlikeSlots) return;
        tint = tints.insert(tints.end(), e.tint);
      }
      code.push_back(e.link.y | static_cast<int32_t>(tint - tints.begin()) << 16 |
                     static_cast<int32_t>(e.seam.z) << 24 | static_cast<int32_t>(e.seam.w) << 26);
    }
  t.glue_by_slot = true;
  t.slot_code = std::move(code);
  t.tints = std::move(tints);
}

}  // namespace

EdgeTables edge_tables(const kernel::SceneTables<float>& tables,
                       const std::vector<glm::vec4>& extra) {
  EdgeTables t;
  const size_t edges = tables.edges.size();
  for (size_t f = 0; f < kFields; ++f) {
    t.number[f].resize(edges);
    for (size_t e = 0; e < edges; ++e)
      t.number[f][e] = edge_number(static_cast<Field>(f), tables.edges[e], extra[e]);
  }
  for (const ivec4& p : tables.polygons) t.most_edges = std::max(t.most_edges, p.y);
  // Number f of edge k, where every room that has an edge k holds the same.
  const auto alike_in_rooms = [&](size_t f, int k) {
    return alike([&](const auto& take) {
      for (const ivec4& p : tables.polygons)
        if (k < p.y) take(t.number[f][static_cast<size_t>(p.x + k)]);
    });
  };
  if (!tables.polygons.empty()) {
    const ivec4 first = tables.polygons.front();
    t.same_first_edge = first.x;
    t.same_count = std::all_of(tables.polygons.begin(), tables.polygons.end(),
                               [&](const ivec4& p) { return p.y == t.most_edges; });
    t.same_rooms = tables.polygons.size() > 1 && t.same_count;
    for (size_t f = 0; f < kFields && t.same_rooms; ++f)
      for (int k = 0; k < first.y && t.same_rooms; ++k)
        t.same_rooms = alike_in_rooms(f, k).has_value();
  }
  for (size_t f = 0; f < kFields; ++f)
    for (int k = 0; k < std::min(t.most_edges, kAlikeSlots); ++k)
      if (const std::optional<float> number = alike_in_rooms(f, k)) {
        t.alike[f] |= 1u << k;
        t.alike_number[f][static_cast<size_t>(k)] = *number;
      }
  for (auto& g : t.glue) g.assign(edges, 0.0f);
  t.to_polygon.assign(edges, 0);
  t.wall.assign(edges, 0);
  for (size_t e = 0; e < edges; ++e) {
    const EdgeRecord& edge = tables.edges[e];
    const ivec4 link = edge.link;
    const bool glued = link.x == kEdgeGlued;
    glm::vec4 to(0.0f);  // the line of the edge it is glued to: edge link.z of room link.y
    if (glued) {
      const int to_edge = tables.polygons[static_cast<size_t>(link.y)].x + link.z;
      to = tables.edges[static_cast<size_t>(to_edge)].line;
    }
    const std::array<float, kGlueFields> glue{edge.map_shift.x,
                                              edge.map_shift.y,
                                              edge.map_linear.x,
                                              edge.map_linear.y,
                                              edge.map_linear.z,
                                              edge.map_linear.w,
                                              to.x,
                                              to.y,
                                              to.z,
                                              edge.line.x,
                                              edge.line.y,
                                              edge.tint.x,
                                              edge.tint.y,
                                              edge.tint.z,
                                              edge.tint.w};
    for (size_t f = 0; f < kGlueFields; ++f) t.glue[f][e] = glue[f];
    for (size_t f = 0; f < 4; ++f) t.seam[f].push_back(edge.seam[static_cast<int>(f)]);
    t.to_polygon[e] = glued ? link.y : 0;
    t.wall[e] = link.x == kEdgeWall ? -1 : 0;
    t.same_tint =
        t.same_tint && std::memcmp(&edge.tint, &tables.edges.front().tint, sizeof(edge.tint)) == 0;
  }
  // A gluing's numbers alike at every glued edge (the tint, usually) are read by broadcast.
  for (size_t f = 0; f < kGlueFields; ++f) {
    const std::optional<float> number = alike([&](const auto& take) {
      for (size_t e = 0; e < edges; ++e)
        if (tables.edges[e].link.x == kEdgeGlued) take(t.glue[f][e]);
    });
    if (!number) continue;
    t.glue_alike |= 1u << f;
    t.glue_number[f] = *number;
  }
  // Where the seams' ends lie, alike slot by slot (rooms drawn in one place, of as many edges).
  t.seam_by_slot = t.same_count && t.most_edges <= kAlikeSlots && !tables.polygons.empty();
  for (size_t f = 0; f < 2 && t.seam_by_slot; ++f)
    for (int k = 0; k < t.most_edges && t.seam_by_slot; ++k) {
      const std::optional<float> number = alike([&](const auto& take) {
        for (const ivec4& p : tables.polygons) take(t.seam[f][static_cast<size_t>(p.x + k)]);
      });
      t.seam_by_slot = number.has_value();
      if (number) t.slot_seam[f][static_cast<size_t>(k)] = *number;
    }
  slot_gluings(tables, t);
  return t;
}

}  // namespace flatmarch::simd
