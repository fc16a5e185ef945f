// The march parameters of DESIGN.md section 3, as every backend and the scene compiler take them.
#pragma once

#include <array>
#include <optional>
#include <string>

namespace flatmarch {

// A ray passing within this distance of a vertex meets it (DESIGN.md section 3).
inline constexpr double kVertexTolerance = 1e-12;

enum class Method { sphere, relaxed, analytic, oracle };
enum class Precision { f32, f64 };

// The methods the march kernel runs, in the order every list shows them (the oracle backend runs
// Method::oracle alone). Every list of methods in the project is read from here.
inline constexpr std::array<Method, 3> kKernelMethods{Method::sphere, Method::relaxed,
                                                      Method::analytic};

const char* to_string(Method m);
std::optional<Method> parse_method(const std::string& name);
// Every method's name, in order, joined by ", " (for help texts and errors).
std::string method_names();

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
