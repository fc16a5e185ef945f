// What the packet code reads of a scene's edges, worked out once a frame (packet_job) rather than
// by the marcher of each of the frame's chunks (as it was): the edges' numbers by field, which of
// them are alike in every room or slot by slot, and what a gluing does at each edge. The per-target
// Walls (walls-inl.h) copies what it reads into its own arrays. Built per chunk, this took 4% of a
// 128-square staircase's analytic samples on one thread (the checks for numbers alike go over every
// room) and halved its `peak_steps_per_s`, whose timed loop builds a marcher too. Plain data, the
// same for every instruction set.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "kernels/compile.hpp"

namespace flatmarch::simd {

// The numbers of an edge the packet code reads, by name.
enum Field { kAx, kAy, kAbx, kAby, kAyAby, kNx, kNy, kNa, kInvLength2, kTolerance, kFields };

// Number `f` of edge `e`, whose edge_extra (packet.hpp) is `extra`.
inline float edge_number(Field f, const kernel::Tables<float>::EdgeRecord& e, glm::vec4 extra) {
  switch (f) {
    case kAx:
      return e.segment.x;
    case kAy:
      return e.segment.y;
    case kAbx:
      return extra.x;
    case kAby:
      return extra.y;
    case kAyAby:
      return extra.w;
    case kNx:
      return e.line.x;
    case kNy:
      return e.line.y;
    case kNa:
      return e.line.z;
    case kInvLength2:
      return e.line.w;
    case kTolerance:
      return extra.z;
    case kFields:
      break;
  }
  return 0.0f;
}

// Slots (edge k of every room) whose numbers are checked for being alike in every room.
constexpr int kAlikeSlots = 16;
// The numbers of a gluing a crossing reads: its map's shift (2) and linear part (4), the
// destination edge's line (3), its own line's normal (2) and its tint (4).
constexpr size_t kGlueFields = 15;
// The first kSlotGlueFields of them, all but the tint.
constexpr size_t kSlotGlueFields = 11;

struct EdgeTables {
  std::array<std::vector<float>, kFields> number;  // [field][edge]
  int most_edges = 0;                              // of any room
  bool same_count = false;                         // every room has most_edges edges
  // Rooms alike in every number, edge by edge (the squares of a square-tiled surface drawn in
  // one place): then room 0's edges, from same_first_edge, stand for every room's.
  bool same_rooms = false;
  int same_first_edge = 0;
  // Where number f of edge k is alike in every room that has an edge k: bit k of alike[f], and
  // the number.
  std::array<uint32_t, kFields> alike{};
  std::array<std::array<float, kAlikeSlots>, kFields> alike_number{};
  std::array<std::vector<float>, kGlueFields> glue;  // [field][edge]; 0 where not glued
  // Bit f: number f of glue alike at every glued edge, glue_number[f].
  uint32_t glue_alike = 0;
  std::array<float, kGlueFields> glue_number{};
  std::array<std::vector<float>, 4> seam;  // [field][edge]: EdgeRecord::seam, for crossings
  std::vector<int32_t> to_polygon;         // of each edge: the room it is glued to, else 0
  std::vector<int32_t> wall;               // of each edge: -1 an opaque wall, else 0
  bool same_tint = true;                   // every edge, glued or not, has the same tint
  // Gluings alike slot by slot: every room has most_edges edges (at most kAlikeSlots), all
  // glued, and edge k of every room is glued by the same numbers (glue fields below
  // kSlotGlueFields: the map, the destination edge's line, the edge's normal), as on a
  // square-tiled surface drawn in one place; the scene has at most kAlikeSlots tints. A crossing
  // then reads those numbers by the lane's slot, and its destination room and tint by one gather
  // of slot_code.
  bool glue_by_slot = false;
  std::array<std::array<float, kAlikeSlots>, kSlotGlueFields> slot_glue{};  // [field][slot]
  // [room * most_edges + slot]: destination room | tint << 16 | what the edge's ends are for the
  // seams (EdgeRecord::seam's z and w, 0 to 2) << 24 and << 26.
  std::vector<int32_t> slot_code;
  // Where each slot's ends lie along it (EdgeRecord::seam's x and y) alike in every room (rooms
  // drawn in one place): by slot, so that a crossing reads its seam with no gather.
  bool seam_by_slot = false;
  std::array<std::array<float, kAlikeSlots>, 2> slot_seam{};
  std::vector<glm::vec4> tints;  // the tints slot_code numbers
};

// The edge tables of `tables`, whose edges' edge_extra is `extra`.
EdgeTables edge_tables(const kernel::SceneTables<float>& tables,
                       const std::vector<glm::vec4>& extra);

}  // namespace flatmarch::simd
