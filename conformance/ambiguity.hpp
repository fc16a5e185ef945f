// The oracle's truth for a frame, with the pixels that finite precision cannot decide.
//
// A marching kernel does not follow the exact ray. Sphere tracing (and its relaxed form) stops
// within `eps` of an edge and places the point `offset` inside the destination room, which moves
// the ray (eps + offset) sin(a) sideways, a the angle between the ray and the edge's normal; the
// analytic method crosses at the exit point it computed, with no push. Both round every position
// to about u = 2^-24 (f32) or 2^-53 (f64) of the scene's scale, and their direction turns by about
// u, so the ray drifts a few u a unit of length. So the kernel's ray may lie up to
//
//     delta_n = delta + sum over the crossings so far of (push sin(a) + 16 u scale)
//               + 4 u (length so far)
//     delta   = eps + offset + 16 u scale      (sphere, relaxed; push = eps + offset)
//             = 32 u scale                     (analytic: rounding and its vertex tolerance;
//                                               push = 0)
//
// from the exact one: the drifts add up, as they may in the worst case.
//
// A pixel whose exact path passes within delta_n of a vertex (a cone point or any corner), runs
// within delta_n of an edge it does not cross, meets an edge within delta_n of the top or bottom
// of the wall band (or leaves the band within delta_n of an edge), grazes an object's silhouette
// (a line shifted delta_n + eps sideways, eps because every method stops that near a solid, meets
// the object where the exact one does not, or the other way round), or ends near max_distance
// (within delta_n plus the push's shortening of the path, t's rounding and 10 eps, as solids are
// hit within eps of them, on either side) can go
// either way; one that hits a solid near an edge of it, where the normal jumps (a line shifted by
// the kernel's normal step meets the solid with a normal that differs on one side only), has a
// colour that can go either way. Such pixels are reported apart instead of being counted as
// failures, in the spirit of VK-GL-CTS's position-deviation compares.
#pragma once

#include <cstdint>
#include <vector>

#include "backends/backend.hpp"
#include "backends/oracle/oracle.hpp"

namespace flatmarch::conformance {

// Why a ray is ambiguous: a bit each.
enum Ambiguity : uint8_t {
  kNearVertex = 1,     // passes within delta_n of a vertex
  kNearEdge = 2,       // runs within delta_n of an edge it does not cross
  kBandEdge = 4,       // meets an edge near the band's top or bottom, or leaves the band near one
  kSilhouette = 8,     // grazes an object: a shifted line decides the object otherwise
  kNearDistance = 16,  // ends within delta_n of max_distance, on either side
  kCrease = 32         // hits a solid within the kernel's normal step of an edge of it
};
inline constexpr int kAmbiguityReasons = 6;
// The bits that leave a ray's path undecided (its hit, crossings and t); a crease alone puts only
// its colour in doubt: the path is decided and judged.
inline constexpr uint8_t kPathAmbiguity =
    kNearVertex | kNearEdge | kBandEdge | kSilhouette | kNearDistance;

// delta for these parameters in this scene (above).
double ambiguity_delta(const Scene& scene, const MarchParams& params);

struct RayTruth {
  RayEnd end;
  uint8_t ambiguity = 0;  // Ambiguity bits; none of kPathAmbiguity: the ray's path is decided
  // How much shorter (or longer) the kernel's path length t may come out, rounding aside: at
  // each crossing sphere tracing stops up to eps / cos(incidence) short of the edge and the push
  // moves the point up to eps + offset along the ray; a solid (every method) or a wall (sphere,
  // relaxed) is hit up to eps / cos(incidence) early.
  double t_slack = 0.0;
};

// The oracle's answer for one ray, with its ambiguity at `delta` (max_distance from `params`).
RayTruth ray_truth(const Scene& scene, const Ray& ray, const MarchParams& params, double delta);

// The oracle's frame and each pixel's ambiguity.
struct FrameTruth {
  Frame frame;
  std::vector<uint8_t> ambiguity;  // a pixel's Ambiguity bits, row-major as the frame
  std::vector<float> t_slack;      // a pixel's RayTruth::t_slack
  double delta = 0.0;
  double unit_roundoff = 0.0;  // of the precision the frame is compared in
  size_t ambiguous() const;    // pixels whose path is undecided
};

FrameTruth frame_truth(const Scene& scene, const Camera& camera, int width, int height,
                       const MarchParams& params);

}  // namespace flatmarch::conformance
