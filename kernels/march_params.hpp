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

// How a GPU backend shapes the kernel and its launch (--kernel-shape). A software rasteriser
// (llvmpipe, lavapipe) runs every branch's code for every lane, taken or not, and a loop's body
// at least once, so the `software` shape keeps rare work out of branches, tests loops at their
// end, reads a one-room scene's edges at constant indices and draws a fragment shader; the `gpu`
// shape is the plain kernel, its loops testing first, run as a compute shader on every backend
// (a datacenter GPU runs fragment shaders on a few of its units only: docs/gpu.md). Both
// give the same steps, crossings and hits to the bit (device_paths_test).
enum class KernelShape { software, gpu };
const char* to_string(KernelShape s);
// "auto" (or empty): the software shape on a software device, else the gpu shape; "software",
// "gpu": that shape. Nothing for any other text.
std::optional<KernelShape> parse_kernel_shape(const std::string& text, bool software_device);
// What is wrong with --kernel-shape `text`, or "" when parse_kernel_shape takes it.
std::string kernel_shape_error(const std::string& text);

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
