// The march parameters of DESIGN.md section 3, as every backend and the scene compiler take them.
#pragma once

namespace flatmarch {

// A ray passing within this distance of a vertex meets it (DESIGN.md section 3).
inline constexpr double kVertexTolerance = 1e-12;

enum class Method { sphere, relaxed, analytic, oracle };
enum class Precision { f32, f64 };

struct MarchParams {
  Method method = Method::sphere;
  double eps = 1e-4;
  double offset = 2e-4;
  int max_steps = 1024;
  double max_distance = 100.0;
  double omega = 1.6;
  Precision precision = Precision::f32;
};

}  // namespace flatmarch
