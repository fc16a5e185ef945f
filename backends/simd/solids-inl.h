// The solids of a pass's rooms for packets of rays (march.glsl's "Solids"): their distances,
// where rays reach their bounding spheres, and their normals. One broadcast record per solid.

// Per-target include guard: this file is included once per instruction set (hwy/foreach_target.h
// re-includes packet.cpp for each), so the guard toggles with HWY_TARGET_TOGGLE.
#if defined(FLATMARCH_BACKENDS_SIMD_SOLIDS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef FLATMARCH_BACKENDS_SIMD_SOLIDS_INL_H_
#undef FLATMARCH_BACKENDS_SIMD_SOLIDS_INL_H_
#else
#define FLATMARCH_BACKENDS_SIMD_SOLIDS_INL_H_
#endif

#include <hwy/highway.h>

#include "backends/simd/lanes-inl.h"
#include "backends/simd/maths-inl.h"

HWY_BEFORE_NAMESPACE();
namespace flatmarch::simd {
namespace HWY_NAMESPACE {

class Solids {
 public:
  explicit Solids(const kernel::SceneTables<float>& tables)
      : polygons_(tables.polygons.data()),
        objects_(tables.objects.data()),
        params_(tables.params),
        features_(tables.features),
        count_(static_cast<int>(tables.objects.size())) {
    if (tables.objects.size() > room_of_.size()) return;
    for (size_t p = 0; p < tables.polygons.size(); ++p)
      for (int k = tables.polygons[p].z; k < tables.polygons[p].z + tables.polygons[p].w; ++k)
        room_of_[static_cast<size_t>(k)] = static_cast<int>(p);
  }

  // Whether a whole pass may read the solids by lane (few enough in the scene).
  bool by_lane() const { return count_ <= static_cast<int>(room_of_.size()); }

  // Signed distance from p to solid k of the object table.
  FLATMARCH_PACKET_INLINE V solid_distance(int k, V px, V py, V pz) const {
    const ObjectRecord& o = objects_[k];
    return lane::solid_sdf(o.info.x, lane::vec3(lane::Broadcast(o.center)),
                           lane::Broadcast(o.shape), lane::vec3(px, py, pz))
        .v;
  }

  FLATMARCH_PACKET_INLINE SolidDistance nearest_solid(const Rooms& rooms, V px, V py, V pz) const {
    SolidDistance best;
    best.d = Splat(kFar);
    best.object = SplatI(-1);
    if (!has(kFeatureObjects)) return best;
    if (rooms.whole) {  // every solid of the scene, for the lanes in its room
      for (int k = 0; k < count_; ++k) {
        const M in = hn::And(rooms.all, Equal(rooms.polygons, room_of_[static_cast<size_t>(k)]));
        if (!Any(in)) continue;
        const V dk = solid_distance(k, px, py, pz);
        const M nearer = hn::And(in, dk < best.d);
        best.d = Select(nearer, dk, best.d);
        best.object = Select(nearer, SplatI(k), best.object);
      }
      return best;
    }
    for (size_t i = 0; i < static_cast<size_t>(rooms.count); ++i) {
      const ivec4 poly = polygons_[rooms.polygon[i]];
      for (int k = poly.z; k < poly.z + poly.w; ++k) {
        const V dk = solid_distance(k, px, py, pz);
        const M nearer = hn::And(rooms.lanes[i], dk < best.d);
        best.d = Select(nearer, dk, best.d);
        best.object = Select(nearer, SplatI(k), best.object);
      }
    }
    return best;
  }

  // Where a ray first comes within eps of a solid's bounding sphere in its room, or kFar.
  FLATMARCH_PACKET_INLINE V solid_entry(const Rooms& rooms, const Packet& r) const {
    V first = Splat(kFar);
    const lane::vec3 o(r.ox, r.oy, r.oz), d(r.dx, r.dy, r.dz);
    if (rooms.whole) {  // every solid of the scene, for the lanes in its room
      for (int k = 0; k < count_; ++k) {
        const M in = hn::And(rooms.all, Equal(rooms.polygons, room_of_[static_cast<size_t>(k)]));
        if (!Any(in)) continue;
        const glm::vec4 c = objects_[k].center;
        const V entry =
            lane::sphere_entry(o - lane::vec3(lane::Broadcast(c)), d, c.w + params_.eps).v;
        first = Select(in, hn::Min(first, entry), first);
      }
      return first;
    }
    for (size_t i = 0; i < static_cast<size_t>(rooms.count); ++i) {
      const ivec4 poly = polygons_[rooms.polygon[i]];
      for (int k = poly.z; k < poly.z + poly.w; ++k) {
        const glm::vec4 c = objects_[k].center;
        const V entry =
            lane::sphere_entry(o - lane::vec3(lane::Broadcast(c)), d, c.w + params_.eps).v;
        first = Select(rooms.lanes[i], hn::Min(first, entry), first);
      }
    }
    return first;
  }

  // The unit normal of solid k of the object table at p (maths.glsl's solid_normal_at).
  FLATMARCH_PACKET_INLINE lane::vec3 solid_normal(int k, V px, V py, V pz) const {
    const ObjectRecord& o = objects_[k];
    return lane::solid_normal_at(o.info.x, lane::vec3(lane::Broadcast(o.center)),
                                 lane::Broadcast(o.shape), lane::vec3(px, py, pz));
  }

 private:
  bool has(uint feature) const { return (features_ & feature) != 0u; }

  const ivec4* polygons_;
  const ObjectRecord* objects_;
  KernelParams params_;
  uint features_;
  int count_;  // solids in the scene
  // The room of each solid, where by_lane(): a whole pass computes every solid's distance for
  // the lanes in its room, a loop over the scene's solids, so only where they are few (the
  // gallery's scenes of several rooms have one or two).
  static constexpr size_t kMostByLane = 8;
  std::array<int, kMostByLane> room_of_ = {};
};

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace flatmarch::simd
HWY_AFTER_NAMESPACE();
#endif  // FLATMARCH_BACKENDS_SIMD_SOLIDS_INL_H_
