// The oracle's truth for a frame, with the pixels that finite precision cannot decide.
//
// A marching kernel does not follow the exact ray. Sphere tracing (and its relaxed form) stops
// s in [0, eps] short of an edge, maps the point into the next room and places it `offset` inside
// the edge it is now behind: the ray moves (s + offset) along that edge's inward normal, sideways
// by the part of it across the new direction. The analytic method crosses at the exit point it
// computed, with no push. Both round every position to about u = 2^-24 (f32) or 2^-53 (f64) of
// the scene's scale, and their direction turns by about u, so the ray drifts a few u a unit of
// length. Per ray, along its exact path (ray_truth), the kernel's ray lies within
//
//     delta_n = delta + |the expected shift across the ray| + spread
//     delta   = eps + offset + 16 u scale      (sphere, relaxed)
//             = 32 u scale                     (analytic: rounding and its vertex tolerance)
//
// of the exact one: the expected shift adds each crossing's push, s = eps / 2, as a vector with
// its sign, carried through each gluing's linear part and reflected by mirrors (in an L-shaped
// room the pushes of edges on either side of the ray cancel in part); the spread adds, whatever
// their signs, eps / 2 of each push, 16 u scale a crossing and 4 u a unit of length, and is
// stretched and shrunk with the gluings' linear parts.
//
// A pixel whose exact path passes within delta_n of a vertex (a cone point or any corner), runs
// within delta_n of an edge it does not cross, meets an edge within delta_n of the top or bottom
// of the wall band (or leaves the band within delta_n of an edge), grazes an object's silhouette
// (a line shifted delta_n + eps sideways, eps because every method stops where a solid's distance
// reads eps, which near a solid's edge is up to a few eps away, meets the object where the exact
// one does not, or the other way round, or meets it much nearer or farther), or ends, or makes its
// last crossing, near max_distance (within delta_n plus the pushes' change of the path length,
// t's rounding and 10 eps, on either side) can go either way: its path is undecided
// (kPathAmbiguity). One that hits a solid near an edge of it, where the normal jumps (a line
// shifted as far as the kernel's normal stencil reaches meets the solid with a normal that
// differs on one side only: a crease), has a colour that can go either way; its path is decided.
// Such pixels are reported apart instead of being counted as failures (creases only by the colour
// checks), in the spirit of VK-GL-CTS's position-deviation compares.
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
  kCrease = 32         // hits a solid within eps (and rounding) of an edge of it
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
