// The interface every backend implements (oracle first; the kernels' backends later), the march
// parameters of DESIGN.md section 3 and the outputs of section 4.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "kernels/constants.hpp"
#include "kernels/march_params.hpp"
#include "output/frame.hpp"
#include "output/trace.hpp"
#include "scene/scene.hpp"

namespace flatmarch {

// The device a GPU backend runs on, named beside every figure it produces.
struct DeviceInfo {
  std::string name;       // "llvmpipe (LLVM 15.0.6, 256 bits)", "NVIDIA H100 80GB HBM3"
  std::string type;       // "GPU" or "CPU" (OpenGL); Vulkan's device type ("discrete GPU", ...)
  std::string api;        // "OpenGL 4.5 (Core Profile) Mesa 22.3.6", "Vulkan 1.3.230"
  std::string driver;     // "Mesa 22.3.6", "NVIDIA 550.54.15", "llvmpipe Mesa 22.3.6 (LLVM 15.0.6)"
  std::string platform;   // how the backend reached it: "EGL device", "OSMesa", "Vulkan"
  bool software = false;  // a rasteriser running on the CPU (llvmpipe, lavapipe, SwiftShader)
  // The kernel's shape the backend runs on it (BackendOptions::kernel_shape, resolved):
  // "software" or "gpu".
  std::string kernel_shape;
};

// A frame's time on its device, by the device's own clock (OpenGL timer queries, Vulkan timestamp
// queries), where a GPU backend could measure it: what the hardware did, apart from the
// submission, the waits and the host's work, which the clock around render() counts too.
struct DeviceTiming {
  bool measured = false;
  std::string why;          // why not, when not measured (the device has no timer, ...)
  double march_s = 0.0;     // the draws or dispatches that march the frame's rays
  double readback_s = 0.0;  // the copies that bring it where the host reads it
  double seconds() const { return march_s + readback_s; }
};

struct Availability {
  bool available = true;
  std::string reason;  // why not, when unavailable
};

// How a backend runs, where it has a choice (command-line options --isa, --threads, --device).
struct BackendOptions {
  std::string isa{};  // simd: the instruction set (see `flatmarch backends`); empty: the best here
  int threads = 0;    // simd: worker threads; 0: all cores
  // opengl and vulkan: the device, by its index or a part of its name (see `flatmarch
  // backends`); empty: a GPU if there is one (vulkan: discrete, integrated, virtual), else the CPU
  // (llvmpipe through EGL, then OSMesa; lavapipe).
  std::string device{};
  // opengl, vulkan, webgl: the kernel's shape (KernelShape): "auto" (or empty), "software" or
  // "gpu".
  std::string kernel_shape{};
  // vulkan: read frames back through a staging buffer even where the device's memory is
  // host-visible, as on a discrete GPU (so that the path is tested on any device).
  bool vk_staging = false;
  // vulkan: run under the Khronos validation layer, and fail a frame or trace on any message it
  // sends. Also on when the environment sets FLATMARCH_VULKAN_VALIDATION=1.
  bool validation = false;
};

// What a backend that marches rays in vector lanes measures of them for a case (the SIMD
// backend): its lanes per packet; of the lanes a packet step could have used, how many did work
// (summed over a frame's passes); the most lane-steps a second it makes on the case (one room's
// step on full packets on all its threads; 0: no step to time); and its rays a second on one
// thread, its instruction set the same (the median of three frames of the colour after one
// untimed; 0 where it runs one thread already): the numerator of its lane efficiency.
struct LaneFigures {
  int lanes = 0;
  int64_t active = 0, slots = 0;
  double peak_steps_per_s = 0.0;
  double one_thread_rays_per_s = 0.0;
};

// What a renderer we did not write, called as a command (conformance/external.hpp,
// docs/external.md), gives and how it is judged: the channels it writes, its look, the march
// parameters it has built in.
struct ExternalInfo {
  std::string manifest;  // its manifest file
  std::string version, description;
  bool colour = true, hit = true, crossings = true, steps = true, t = true;
  // The look its colour is judged in: "flatmarch" (DESIGN.md's), "peer-app" (the web app's) or
  // "none" (not judged).
  std::string look = "flatmarch";
  // The march parameters it has built in, whatever it is asked (eps, offset, max_steps,
  // max_distance, omega).
  std::vector<std::pair<std::string, double>> fixed;
  // The scene files it reads: "flatmarch" (ours), "peer-app" (the web app's geometries).
  std::vector<std::string> scene_formats = {"flatmarch"};
  std::string expectations;  // its expectation file (conformance/expectations.hpp), if any
  // The parameters it marches with when asked for `asked`: `fixed` over them.
  MarchParams marches_with(MarchParams asked) const;
  // Why it cannot be given `scene` (it reads only the app's format, and the scene was not
  // converted from it), or empty.
  std::string cannot_read(const Scene& scene) const;
};

// A case a renderer cannot render (a scene it cannot express, a format it cannot read): skipped,
// saying why, neither a failure nor an error.
struct CaseSkipped : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Called now and then during long work with the fraction done, in [0, 1].
using Progress = std::function<void(double)>;

class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string name() const = 0;
  virtual std::string description() const = 0;
  virtual Availability availability() const = 0;
  // Methods this backend runs; `oracle` runs only Method::oracle.
  virtual std::vector<Method> methods() const = 0;
  // Precisions it marches in.
  virtual std::vector<Precision> precisions() const { return {Precision::f32, Precision::f64}; }
  // The device it runs on (GPU backends, when available); CPU backends: none.
  virtual std::optional<DeviceInfo> device() const { return std::nullopt; }
  // Whether its first frame of a scene compiles a program of its own (the kernel specialised on
  // the scene and the parameters) that the driver's disk cache keeps for the next process: a
  // report compiles them ahead, several at once (opengl, vulkan; webgl's browser keeps its cache
  // in a profile that lives as long as its page).
  virtual bool compiles_per_scene() const { return false; }

  virtual Frame render(const Scene& scene, const Camera& camera, int width, int height,
                       const MarchParams& params, const Progress& progress) const = 0;
  // A frame for the eye or the clock: at least its colour. The GPU backends read back the 8-bit
  // sRGB colour alone (Frame::srgb, an eighth of render()'s read-back); the others give render()'s
  // frame. Timed runs draw these; whatever compares frames draws render()'s.
  virtual Frame render_colour(const Scene& scene, const Camera& camera, int width, int height,
                              const MarchParams& params, const Progress& progress) const {
    return render(scene, camera, width, height, params, progress);
  }
  // Whether render_colour() gives render()'s whole frame (false where it reads back less).
  virtual bool colour_frames_whole() const { return true; }
  // Whether a frame of the colour alone runs a program of its own, compiled on its first frame
  // (OpenGL's fragment shader: one a set of targets), not the whole frame's (a compute shader
  // writes either read-back).
  virtual bool colour_program_apart() const { return false; }
  // The last render() or render_colour() on the device's own clock (GPU backends; measured, or
  // why not). Nothing from a backend that runs on no device of its own (the CPU backends).
  virtual std::optional<DeviceTiming> last_device_timing() const { return std::nullopt; }
  // The time the last render() took as the backend measured it itself, where a clock around
  // render() would count more than the frame (webgl: the browser's round trip); unset where the
  // clock around render() is the measure. The benchmarks time frames by it when set.
  virtual std::optional<double> last_frame_seconds() const { return std::nullopt; }
  // Follows one ray, recording at most `max_events` events.
  virtual Trace trace(const Scene& scene, const Ray& ray, const MarchParams& params,
                      int max_events) const = 0;
  // A run of cases between two of them: lets go of what it keeps working for the last scene
  // (webgl: its page, whose browser went on spending both cores of a 2-core machine on
  // SwiftShader's threads after the case, slowing the next cases of the other backends). The
  // next frame opens what it needs again.
  virtual void rest() const {}
  // Whether its cases are best run one after another, resting only when another backend's case
  // comes: what rest() lets go of is dear to start again (webgl: its browser, a second or more a
  // case on a 2-core machine).
  virtual bool runs_back_to_back() const { return false; }
  // What it is where it is a renderer we did not write, called as a command; null for ours.
  virtual const ExternalInfo* external() const { return nullptr; }
  // Its lanes' figures for a case (LaneFigures; the peak timed for about `peak_seconds`); none
  // from a backend without lanes.
  virtual std::optional<LaneFigures> lane_figures(const Scene& scene, const Camera& camera,
                                                  int width, int height, const MarchParams& params,
                                                  double peak_seconds) const {
    (void)scene, (void)camera, (void)width, (void)height, (void)params, (void)peak_seconds;
    return std::nullopt;
  }
};

// ---- The registry -----------------------------------------------------------------------------
// Every list of backends in the project (the CLI's, the conformance suite's and its tests', the
// report's and the benchmarks') is read from here: adding a backend is adding an entry.

// A command-line option a backend adds, the field of BackendOptions it sets, and its help (the
// CLI declares each flag once, with the help of every backend that adds it).
struct BackendOption {
  std::string flag;  // "--isa"
  std::variant<std::string BackendOptions::*, int BackendOptions::*, bool BackendOptions::*> field;
  std::string help;
};

// What a case of a backend costs, as the shard planner and the time-left estimate price it
// before any case has run (reports/shard.hpp): seconds on a 2-core Zen 5.
struct BackendCost {
  double frame_seconds = 0.01;   // a 160x90 frame of sphere tracing (a tenth of it analytic)
  double startup_seconds = 0.0;  // a conformance case's start beyond its frames (a browser's page)
  // What a timed case adds beyond its frames (the SIMD backend's lane figures), from a frame's
  // seconds and the minimum time a benchmark runs; none if null.
  std::function<double(double frame_seconds, double min_time)> extra_timed_seconds{};
};

// `flatmarch shader`'s request of a backend that runs a GLSL shader of its own: the trace variant
// or the whole frame's, in the kernel's software or GPU shape.
struct ShaderRequest {
  bool trace = false;
  KernelShape shape = KernelShape::software;
};

// The help of --kernel-shape, which the GPU backends' entries share.
extern const char* const kKernelShapeHelp;

// A backend as the project's lists know it: what the command line, the report, the shard planner,
// the fingerprint and the tests ask of it, so that none of them names a backend.
struct BackendEntry {
  std::string name;
  // Runs the march kernel: the conformance suite, the report and the benchmarks measure it
  // against the oracle. (The oracle is the one backend that does not.)
  bool kernel = true;
  // What its results are the reference for, where they are one (`flatmarch backends` says).
  std::string reference_for{};
  std::function<std::unique_ptr<Backend>(const BackendOptions&)> make;
  // The variants the contract tests hold to the contract besides the default one: a name and the
  // options that make it (simd: each instruction set compiled in). None if null.
  std::function<std::vector<std::pair<std::string, BackendOptions>>()> variants{};
  // The options it takes beyond the march parameters.
  std::vector<BackendOption> options{};
  // Why its results are wrong on purpose, if they are (the test programs' `faulty` backend):
  // conformance must fail it on every case; the contract and stability tests skip it, saying so.
  std::string wrong_on_purpose{};
  // The methods the gallery's conformance test runs it on, where its every case costs much
  // (webgl: a browser's page; `flatmarch conform` measures the rest); empty: every method.
  std::vector<Method> gallery_test_methods{};
  // Its cost, for the shard planner (BackendCost).
  BackendCost cost{};
  // The conformance tests run its cases in one process with the other backends of this batch
  // (tests/CMakeLists.txt's BATCH, made from each backend's flatmarch_add_backend): "kernels",
  // whose cases share each scene's truth, or one of its own (a backend that starts a browser).
  std::string test_batch = "kernels";
  // A CPU backend that runs the kernel, by speed (0: not one): the fastest built and available is
  // `render`'s default and the report's quick sweep's; the slowest, the reference, its fallback.
  int cpu_rank = 0;
  // Why the default report measures it on a sample of its cases where its device draws in
  // software ("its WebGL draws in software here"); empty: on every case wherever it runs.
  std::string software_sample_why{};
  // Checks the options it takes (BackendOptions); an error to show, or empty.
  std::function<std::string(const BackendOptions&)> check_options{};
  // Adds what the machine's fingerprint says of it (its devices, instruction sets, libraries).
  std::function<void(nlohmann::json& fingerprint)> fingerprint{};
  // Its rows of the report's machine table (a label and a text), and its part of the machine's
  // one-line description ("; Vulkan: NAME"), from a fingerprint.
  std::function<std::vector<std::pair<std::string, std::string>>(const nlohmann::json&)>
      fingerprint_rows{};
  std::function<std::string(const nlohmann::json&)> describe_machine{};
  // `flatmarch backends`: adds to its JSON entry (its devices, its instruction sets), and the
  // text printed after the table from that entry.
  std::function<void(const Backend&, nlohmann::json& listing)> list{};
  std::function<std::string(const nlohmann::json& listing)> list_text{};
  // `flatmarch shader`: the GLSL it runs for a scene's whole frames (its kernel specialised on the
  // scene, with the tables baked in), and its compiler, which returns what compiled it (a
  // renderer's name) or throws kernel::ShaderError. None if null: it runs no shader of its own.
  std::function<std::string(const Scene&, const MarchParams&, const ShaderRequest&)> shader{};
  std::function<std::string(const Backend&, const std::string& source, const ShaderRequest&)>
      compile_shader{};
};

// The entries a build has, in order (backends/registered.cpp, made by CMake from the backends'
// folders the build's options keep: oracle, scalar, then simd, opengl, vulkan, webgl).
std::vector<BackendEntry> built_in_backends();

// The registered backends: the built-in ones, then any a program added.
const std::vector<BackendEntry>& backend_registry();
// Adds a backend after the built-in ones (a test's own backend, registered by a static
// initialiser; an external renderer, from the command line). Throws std::logic_error on a name
// already taken.
bool register_backend(BackendEntry entry);
// The names of the registered backends, and of those that run the kernel.
std::vector<std::string> backend_names();
std::vector<std::string> kernel_backend_names();
// The registry's entry of that name; null if there is none.
const BackendEntry* find_backend_entry(const std::string& name);
// The CPU backends that run the kernel, fastest first (BackendEntry::cpu_rank); the fastest of
// them that runs here with `options`; and the reference one (the slowest: scalar).
std::vector<std::string> cpu_backend_names();
std::string fastest_cpu_backend(const BackendOptions& options);
std::string reference_cpu_backend();

// All registered backends, available here or not, with default options.
const std::vector<std::unique_ptr<Backend>>& backends();
const Backend* find_backend(const std::string& name);
// A backend by name with the given options; null if there is none of that name.
std::unique_ptr<Backend> make_backend(const std::string& name, const BackendOptions& options);

}  // namespace flatmarch
