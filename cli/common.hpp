// What the subcommands share: errors with their exit codes, march options, argument parsing.
#pragma once

#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "backends/backend.hpp"
#include "reports/shard.hpp"

namespace flatmarch::cli {

// A bad argument: printed as `error: ...`, exit code 2 (scene errors are SceneError, also 2).
class UsageError : public std::runtime_error {
 public:
  explicit UsageError(const std::string& what) : std::runtime_error("error: " + what) {}
};

// An unavailable backend: exit code 3.
class UnavailableError : public std::runtime_error {
 public:
  explicit UnavailableError(const std::string& what) : std::runtime_error("error: " + what) {}
};

// Cases of `flatmarch conform` failed their thresholds: exit code 1.
class ConformanceFailure : public std::runtime_error {
 public:
  explicit ConformanceFailure(const std::string& what) : std::runtime_error("error: " + what) {}
};

Vec3 parse_vec3(const std::string& option, const std::string& text);
std::pair<int, int> parse_size(const std::string& option, const std::string& text);

// The command line this process runs (cli::run's), for supervised runs' workers: set_self_command
// records it; worker_command is the same command line, run again by `self`, with `--worker`.
void set_self_command(std::vector<std::string> self, int argc, char** argv);
std::vector<std::string> worker_command();
// The command line as a person would type it again (arguments quoted for a shell where they need
// it), with `extra` added unless it is there: "conform --scene torus --resume".
std::string quoted_command_line(const std::string& extra);

// What one frame holds a pixel (Frame: linear colour, steps, crossings, hit, t and the 8-bit
// sRGB), and about how many frames a piece of work holds at once: a rendered image (the frame
// and the image written from it) and a conformance case (the backend's frame, the oracle's, the
// float64 reference, the error images and their differences).
inline constexpr double kFrameBytesPerPixel = 32.0;
inline constexpr int kRenderFrames = 2;
inline constexpr int kCaseFrames = 8;
// The memory this process may use: the least of the machine's physical memory, its cgroup's
// memory.max and its address-space limit (RLIMIT_AS), with which of them that is.
struct MemoryLimit {
  double bytes = 0.0;
  std::string what;
};
MemoryLimit memory_limit();
// Refuses (UsageError, exit 2) a size whose work would not fit in memory_limit(), before
// anything is allocated, saying how much it would need: `frames` frames of w x h (`work` names
// them: "a conformance case").
void check_frame_memory(const std::string& option, int w, int h, int frames,
                        const std::string& work);

// A folder of flatmarch's installed data (share/flatmarch beside the program's folder,
// dynamic_library.hpp): "scenes" (the gallery), "conformance/scenes"; the same relative to here
// when the program has no data folder beside it.
std::string data_folder(const std::string& sub);
// A scene given as a file, or by its name in the gallery (data_folder("scenes")): `flatmarch
// render torus` from anywhere. A name found nowhere is the file's error, with the gallery named.
Scene load_named_scene(const std::string& file_or_name);
// The file load_named_scene reads.
std::string named_scene_file(const std::string& file_or_name);
// The help text of a SCENE argument that load_named_scene reads.
extern const char* const kSceneArgumentHelp;

// The scenes named by --scene (a file, or a scene's name in one of the --gallery folders) or,
// when none is named, every scene of the folders, each folder's sorted by file name. UsageError
// when a name is found nowhere or the folders hold no scene.
// A scene file of ours, or a geometry of the web app's, converted as import-peer converts it and
// named app_STEM (imported_from says which file).
Scene load_scene_or_app_geometry(const std::filesystem::path& file);
std::vector<Scene> load_scenes(const std::vector<std::string>& names,
                               const std::vector<std::string>& galleries);

// Words joined by ", " (lists in help texts and errors).
std::string joined(const std::vector<std::string>& words);
// The kernel's methods, named in order and joined (help texts and errors).
std::string kernel_method_names();

// The kernel methods named by --method options (UsageError for another name); all three when
// none is named.
std::vector<Method> parse_methods(const std::vector<std::string>& names);

// A JSON file named by `option` (UsageError if it cannot be read or is not JSON), and writing
// one (its folder made; runtime_error if it cannot be written).
nlohmann::json read_json(const std::string& option, const std::filesystem::path& file);
void write_json(const std::filesystem::path& file, const nlohmann::json& doc);

// --- What `flatmarch report` and `flatmarch merge` share (cli/report.cpp).

// The page of results files in `out`, one file's page or several machines compared; `previous`:
// an earlier run's results, compared case by case. Its tables are worked out here
// (reports/page.hpp) into `out`/page.json, its charts and HTML drawn by reports/make_report.py
// (matplotlib, Jinja) run by `python`. runtime_error when it cannot be made.
void make_report_page(const std::string& python, const std::vector<std::string>& results,
                      const std::filesystem::path& out, const std::string& previous);
// A word for the shell (sh -c, std::system), quoted.
std::string shell_quoted(const std::string& word);
// python3 with matplotlib and jinja2: $FLATMARCH_PYTHON, else /usr/bin/python3.
std::string default_python();
// The results' regression section: checked against `baseline` (a file; "" for the committed
// reports/baseline.json when it was measured alike), else "checked" false and why not.
nlohmann::json regression_section(const nlohmann::json& results, const std::string& baseline);
// The gate (--baseline): writes OUT/gate.json, prints the findings, and throws
// ConformanceFailure (exit 1) when a figure regressed; UsageError when the baseline cannot judge.
void gate(const nlohmann::json& results, const std::string& baseline,
          const std::filesystem::path& out);
// A --shard value, I/N (UsageError otherwise).
reports::Shard parse_shard_option(const std::string& text);

// The precision --precision names: f32 or f64 (UsageError for another).
Precision parse_precision(const std::string& text);

// The kernel backend --backend names, made with `options`: UsageError for an unknown name, or a
// backend that does not run the kernel (the oracle, which the others are measured against).
std::unique_ptr<Backend> make_kernel_backend(const std::string& name,
                                             const BackendOptions& options);

// --external NAME=MANIFEST (repeat): renderers we did not write, judged beside the backends
// (docs/external.md). register_externals adds each to the backend registry (before anything
// lists the backends) and returns their names; UsageError for a manifest it cannot use.
void add_external_option(CLI::App& app, std::vector<std::string>& specs);
std::vector<std::string> register_externals(const std::vector<std::string>& specs);

// The march parameters' options (--eps, --offset, --max-steps, --max-distance, --omega), each
// declared here once with one help text; check_march_params holds each to one range. A command
// takes those `which` names (all: the five).
struct MarchParamOptions {
  bool eps = true, offset = true, max_steps = true, max_distance = true, omega = true;
};
void add_march_param_options(CLI::App& app, MarchParams& params, MarchParamOptions which = {});

// The backends' own options (--isa, --threads, --device, --vk-staging), declared once;
// check_backend_options checks them.
void add_backend_options(CLI::App& app, BackendOptions& options);
void check_backend_options(const BackendOptions& options);

// Throws UsageError for parameters out of range; warns (stderr) when offset <= eps.
void check_march_params(const MarchParams& params);

// Warns (stderr) when params.eps lies below float32's resolution at the scene's scale, where
// sphere tracing cannot get within eps of a wall but by landing on it.
void warn_about_resolution(const Scene& scene, const MarchParams& params);

// Why the image module (OpenImageIO) cannot be loaded here, or "" where it can: the commands whose
// results are figures then measure without it, and say once what they left out.
std::string image_module_missing();
// The one line they say it in, on stderr: "COMMAND: left out, WHAT: no image library here (WHY).
// HOW".
void say_left_out(const std::string& command, const std::string& what, const std::string& how);
// The note on Yee's metric, which the conformance checks leave out without the module.
extern const char* const kPerceptualLeftOut;

// UsageError (--max-distance) when rays from `camera` would leave the reach to which an unbounded
// scene is modelled (kernel::check_reach).
void check_reach(const Scene& scene, const Camera& camera, const MarchParams& params);

// The backend and march parameters of render and trace (DESIGN.md section 3).
struct MarchOptions {
  std::string backend;  // empty: default_backend
  std::string default_backend = "oracle";
  std::string method;  // empty: default_method where the backend runs it, else its first
  std::string default_method;
  MarchParams params;
  std::string precision = "f32";
  BackendOptions backend_options;

  // `fallback`: the backend when default_backend is unavailable here.
  void add_to(CLI::App& app, const std::string& default_name = "oracle",
              const std::string& fallback = "oracle");
  // Makes the backend (UsageError if unknown, UnavailableError if unavailable here) and checks
  // the parameters against it.
  const Backend& resolve();

 private:
  std::string fallback_;
  std::unique_ptr<Backend> made_;
};

// Camera overrides of render (DESIGN.md section 5).
struct CameraOptions {
  std::optional<int> polygon;
  std::string position;
  std::optional<double> yaw_deg, pitch_deg, fov_deg;

  void add_to(CLI::App& app);
  Camera apply(const Scene& scene) const;  // validated against the scene
};

// Progress on stderr for long work: a live line on a terminal, a line every few seconds otherwise.
class ProgressReporter {
 public:
  explicit ProgressReporter(std::string label, bool quiet = false);
  void operator()(double fraction);
  void done();

 private:
  std::string label_;
  bool quiet_, tty_;
  double started_, last_ = -1.0;
};

}  // namespace flatmarch::cli
