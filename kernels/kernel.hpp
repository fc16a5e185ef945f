// The kernel (kernels/march.glsl) compiled as C++: Kernel<real, FEATURES> holds pointers to a
// compiled scene's tables and the frame's parameters, and has the kernel's functions as members
// (`march`, `shade`, ...). with_kernel picks, at run time, the instance specialised on the
// feature set a scene uses.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "kernels/constants.hpp"

namespace flatmarch::kernel {

// The table records and parameters of kernels/tables.glsl in one precision.
template <typename real>
struct Tables {
  using vec2 = typename Types<real>::vec2;
  using vec3 = typename Types<real>::vec3;
  using vec4 = typename Types<real>::vec4;
#include "kernels/tables.glsl"
};

// The parameters as a std140 uniform block: 12 scalars, then 16-byte aligned vec4s.
static_assert(offsetof(Tables<float>::KernelParams, convex) == 12 &&
              offsetof(Tables<float>::KernelParams, fog) == 48 &&
              sizeof(Tables<float>::KernelParams) == 192);
static_assert(sizeof(Tables<float>::EdgeRecord) == 112 &&
              sizeof(Tables<float>::ObjectRecord) == 64);

// A transport event as the kernel reports it (EventKind numbering, kEvent*).
struct KernelEvent {
  int kind, polygon, edge, to_polygon, to_edge, object;
  double t;
  glm::dvec3 at;
};

template <typename real, uint kFeatures>
struct Kernel {
  using vec2 = typename Types<real>::vec2;
  using vec3 = typename Types<real>::vec3;
  using vec4 = typename Types<real>::vec4;
  using EdgeRecord = typename Tables<real>::EdgeRecord;
  using ObjectRecord = typename Tables<real>::ObjectRecord;
  using KernelParams = typename Tables<real>::KernelParams;

  static constexpr uint FEATURES = kFeatures;

  const ivec4* polygons = nullptr;
  const EdgeRecord* edges = nullptr;
  const ObjectRecord* objects = nullptr;
  KernelParams params{};
  // Where events go when a trace is wanted, and how many to keep.
  std::vector<KernelEvent>* events = nullptr;
  int max_events = 0;

  void record_event(int kind, int polygon, int edge, int to_polygon, int to_edge, int object,
                    real t, vec3 at) const {
    if (events && static_cast<int>(events->size()) < max_events)
      events->push_back({kind, polygon, edge, to_polygon, to_edge, object, static_cast<double>(t),
                         glm::dvec3(at)});
  }

#include "kernels/march.glsl"
#include "kernels/maths.glsl"
};

// The kernel specialised on kFeatures, bound to the tables (a kernel::SceneTables<real>) of a
// scene of that feature set: for code that knows its scene's set and would not compile the
// kFeatureCount specialisations with_kernel does (a test's scene).
template <typename real, uint kFeatures, typename Tables>
Kernel<real, kFeatures> bind_kernel(const Tables& tables) {
  if (tables.features != kFeatures)
    throw std::invalid_argument("bind_kernel: the tables are of feature set " +
                                std::to_string(tables.features) + ", not " +
                                std::to_string(kFeatures));
  Kernel<real, kFeatures> k;
  k.polygons = tables.polygons.data();
  k.edges = tables.edges.data();
  k.objects = tables.objects.data();
  k.params = tables.params;
  return k;
}

namespace detail {
template <typename real, typename Tables, typename F, uint... N>
void dispatch(const Tables& tables, F&& f, std::integer_sequence<uint, N...>) {
  const auto run = [&]<uint M>() {
    Kernel<real, M> k = bind_kernel<real, M>(tables);
    f(k);
  };
  static_cast<void>(((tables.features == N ? (run.template operator()<N>(), true) : false) || ...));
}
}  // namespace detail

// Calls f(kernel) with the kernel specialised on tables.features and bound to the tables
// (a kernel::SceneTables<real>, kernels/compile.hpp).
template <typename real, typename Tables, typename F>
void with_kernel(const Tables& tables, F&& f) {
  detail::dispatch<real>(tables, f, std::make_integer_sequence<uint, kFeatureCount>{});
}

}  // namespace flatmarch::kernel
