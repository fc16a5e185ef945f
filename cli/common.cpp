#include "cli/common.hpp"

#include "output/dynamic_library.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include "backends/oracle/oracle.hpp"
#include "conformance/external.hpp"
#include "interop/peer_import.hpp"
#include "kernels/compile.hpp"
#include "output/image_library.hpp"
#include "scene/load.hpp"

namespace flatmarch::cli {

namespace {

double now_seconds() {
  using clock = std::chrono::steady_clock;
  return std::chrono::duration<double>(clock::now().time_since_epoch()).count();
}

double parse_number(const std::string& option, const std::string& text) {
  size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !std::isfinite(v))
    throw UsageError(option + ": \"" + text + "\" is not a finite number");
  return v;
}

}  // namespace

Vec3 parse_vec3(const std::string& option, const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, ',');) parts.push_back(part);
  if (parts.size() != 3 || text.back() == ',')
    throw UsageError(option + ": expected X,Y,Z, got \"" + text + "\"");
  return {parse_number(option, parts[0]), parse_number(option, parts[1]),
          parse_number(option, parts[2])};
}

std::pair<int, int> parse_size(const std::string& option, const std::string& text) {
  const size_t x = text.find('x');
  constexpr int kMax = 16384;
  int w = 0, h = 0;
  try {
    size_t uw = 0, uh = 0;
    if (x != std::string::npos) {
      w = std::stoi(text.substr(0, x), &uw);
      h = std::stoi(text.substr(x + 1), &uh);
    }
    if (x == std::string::npos || uw != x || uh != text.size() - x - 1) w = h = 0;
  } catch (const std::exception&) {
    w = h = 0;
  }
  if (w < 1 || h < 1 || w > kMax || h > kMax)
    throw UsageError(option + ": expected WxH with 1 <= W, H <= " + std::to_string(kMax) +
                     ", got \"" + text + "\"");
  return {w, h};
}

namespace {
std::vector<std::string> g_self, g_args;
}  // namespace

void set_self_command(std::vector<std::string> self, int argc, char** argv) {
  g_self = std::move(self);
  g_args.assign(argv + std::min(argc, 1), argv + argc);
}

std::vector<std::string> worker_command() {
  std::vector<std::string> command = g_self;
  command.insert(command.end(), g_args.begin(), g_args.end());
  command.emplace_back("--worker");
  return command;
}

std::string shell_quoted(const std::string& word) {
  std::string q = "'";
  for (const char ch : word) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return q + "'";
}

std::string quoted_command_line(const std::string& extra) {
  std::vector<std::string> args = g_args;
  if (!extra.empty() && std::find(args.begin(), args.end(), extra) == args.end())
    args.push_back(extra);
  std::string line;
  for (const std::string& a : args) {
    const bool plain = !a.empty() && std::all_of(a.begin(), a.end(), [](char ch) {
      return std::isalnum(static_cast<unsigned char>(ch)) || std::strchr("-_./=:,+@%", ch);
    });
    line += (line.empty() ? "" : " ") + (plain ? a : shell_quoted(a));
  }
  return line;
}

std::string this_program(const char* argv0) {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::string(argv0) : self.string();
}

MemoryLimit memory_limit() {
  MemoryLimit m;
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && page > 0)
    m = {static_cast<double>(pages) * static_cast<double>(page), "this machine's physical memory"};
  const auto lower = [&m](double bytes, const char* what) {
    if (bytes > 0.0 && (m.bytes == 0.0 || bytes < m.bytes)) m = {bytes, what};
  };
  // cgroup v2 (a container's or a Slurm job's limit): a number of bytes, or "max".
  if (std::ifstream in("/sys/fs/cgroup/memory.max"); in) {
    std::string text;
    in >> text;
    if (!text.empty() && std::all_of(text.begin(), text.end(), ::isdigit))
      lower(std::stod(text), "its cgroup's memory.max");
  }
  if (rlimit as{}; getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY)
    lower(static_cast<double>(as.rlim_cur), "its address-space limit (RLIMIT_AS)");
  return m;
}

void check_frame_memory(const std::string& option, int w, int h, int frames,
                        const std::string& work) {
  const MemoryLimit limit = memory_limit();
  const double need = kFrameBytesPerPixel * w * h * frames;
  if (limit.bytes == 0.0 || need <= limit.bytes) return;
  const auto gib = [](double bytes) {
    std::ostringstream s;
    s.precision(3);
    s << bytes / (1024.0 * 1024.0 * 1024.0) << " GiB";
    return s.str();
  };
  throw UsageError(option + " " + std::to_string(w) + "x" + std::to_string(h) + ": " + work +
                   " at this size holds about " + std::to_string(frames) + " frames of " +
                   std::to_string(static_cast<int>(kFrameBytesPerPixel)) + " bytes a pixel, " +
                   gib(need) + ", more than the " + gib(limit.bytes) + " of " + limit.what +
                   "; choose a smaller size");
}

void MarchOptions::add_to(CLI::App& app, const std::string& default_name,
                          const std::string& fallback) {
  default_backend = default_name;
  fallback_ = fallback;
  // The backends by their default instances (backends()), as `flatmarch backends` lists them.
  // Making them all here, the SIMD backend among them, also keeps the sanitizer build's
  // LeakSanitizer from crashing at exit ("Tracer caught signal 11") after `render --backend
  // opengl` on OSMesa: measured, reproducible, cause not found.
  std::vector<std::string> names;
  for (const auto& b : backends()) names.push_back(b->name());
  app.add_option("--backend", backend,
                 "Backend: " + joined(names) +
                     " (see `flatmarch backends`); default: " + default_name +
                     (fallback != default_name ? " where available, else " + fallback : ""));
  app.add_option(
      "--method", method,
      "Method: " + method_names() + " (default: " +
          (default_method.empty() ? std::string()
                                  : default_method + " where the backend runs it, else ") +
          "the backend's first)");
  add_march_param_options(app, params);
  app.add_option("--precision", precision, "f32 or f64 (f64 on the oracle and scalar backends)")
      ->capture_default_str();
  add_backend_options(app, backend_options);
}

void add_march_param_options(CLI::App& app, MarchParams& params, MarchParamOptions which) {
  const auto add = [&app](bool wanted, const char* name, auto& value, const char* help) {
    if (wanted) app.add_option(name, value, help)->capture_default_str();
  };
  add(which.eps, "--eps", params.eps, "Hit threshold, > 0");
  add(which.offset, "--offset", params.offset, "Re-entry push after a gluing, > 0");
  add(which.max_steps, "--max-steps", params.max_steps,
      "Kernel iterations before a ray gives up, in [1, 1e8]");
  add(which.max_distance, "--max-distance", params.max_distance,
      "Path length before a ray gives up, > 0");
  add(which.omega, "--omega", params.omega,
      "Over-relaxation factor of the relaxed method, in [1, 2)");
}

void add_backend_options(CLI::App& app, BackendOptions& options) {
  // Each flag once, in the registry's order, with the help of every backend that adds it.
  std::vector<const BackendOption*> flags;
  std::vector<std::string> helps;
  for (const BackendEntry& e : backend_registry())
    for (const BackendOption& o : e.options) {
      const auto same = [&](const BackendOption* f) { return f->flag == o.flag; };
      const auto at = std::find_if(flags.begin(), flags.end(), same);
      if (at == flags.end()) {
        flags.push_back(&o);
        helps.push_back(e.name + ": " + o.help);
      } else {
        helps[static_cast<size_t>(at - flags.begin())] += "; " + e.name + ": " + o.help;
      }
    }
  for (size_t k = 0; k < flags.size(); ++k)
    std::visit(
        [&](auto field) {
          auto& value = options.*field;
          if constexpr (std::is_same_v<std::decay_t<decltype(value)>, bool>)
            app.add_flag(flags[k]->flag, value, helps[k]);
          else
            app.add_option(flags[k]->flag, value, helps[k])->capture_default_str();
        },
        flags[k]->field);
}

void check_backend_options(const BackendOptions& options) {
  if (options.threads < 0) throw UsageError("--threads: must be 0 (all cores) or more");
  if (const std::string e = kernel_shape_error(options.kernel_shape); !e.empty())
    throw UsageError(e);
  for (const BackendEntry& e : backend_registry())
    if (e.check_options)
      if (const std::string error = e.check_options(options); !error.empty())
        throw UsageError(error);
}

Precision parse_precision(const std::string& text) {
  if (text == "f32") return Precision::f32;
  if (text == "f64") return Precision::f64;
  throw UsageError("--precision: expected f32 or f64, got \"" + text + "\"");
}

std::unique_ptr<Backend> make_kernel_backend(const std::string& name,
                                             const BackendOptions& options) {
  const std::vector<std::string> kernel = kernel_backend_names();
  std::unique_ptr<Backend> backend = make_backend(name, options);
  if (!backend)
    throw UsageError("--backend: unknown backend \"" + name + "\" (see `flatmarch backends`)");
  if (std::find(kernel.begin(), kernel.end(), name) == kernel.end())
    throw UsageError("--backend: the " + name + " is what the others are measured against");
  return backend;
}

void add_external_option(CLI::App& app, std::vector<std::string>& specs) {
  app.add_option("--external", specs,
                 "NAME=MANIFEST: a renderer we did not write, called as a command and judged "
                 "beside the backends (repeat; docs/external.md has the protocol; its cases are "
                 "BACKEND/METHOD/SCENE with NAME as the backend, its time its command's)");
}

std::vector<std::string> register_externals(const std::vector<std::string>& specs) {
  std::vector<std::string> names;
  for (const std::string& spec : specs) {
    BackendEntry entry;
    try {
      entry = conformance::external_entry(spec);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--external: ") + e.what());
    }
    if (find_backend_entry(entry.name))
      throw UsageError("--external " + spec + ": a backend named " + entry.name +
                       " exists; name it otherwise (NAME=MANIFEST)");
    names.push_back(entry.name);
    register_backend(std::move(entry));
  }
  return names;
}

void check_march_params(const MarchParams& params) {
  if (!(params.eps > 0.0) || !std::isfinite(params.eps))
    throw UsageError("--eps: must be a positive number");
  if (!(params.offset > 0.0) || !std::isfinite(params.offset))
    throw UsageError("--offset: must be a positive number");
  if (params.max_steps < 1 || params.max_steps > 100'000'000)
    throw UsageError("--max-steps: must lie in [1, 1e8]");
  if (!(params.max_distance > 0.0) || !std::isfinite(params.max_distance))
    throw UsageError("--max-distance: must be a positive number");
  if (!(params.omega >= 1.0 && params.omega < 2.0)) throw UsageError("--omega: must lie in [1, 2)");
  if ((params.method == Method::sphere || params.method == Method::relaxed) &&
      params.offset <= params.eps)
    std::cerr << "warning: --offset " << params.offset << " is not above --eps " << params.eps
              << ": a ray placed that close to the edge it came through crosses back, so every "
                 "ray that reaches a gluing ends with max_steps\n";
}

void warn_about_resolution(const Scene& scene, const MarchParams& params) {
  // In an unbounded room the coordinates grow with the path: a ray along a cylinder meets its
  // walls max_distance out (measured: at eps 1e-6 in float32, 0.4% of the cylinders' pixels run
  // out of steps, none of the torus's).
  const double extent = scene.topology.infinite ? scene.scale + params.max_distance : scene.scale;
  const double resolution = 0x1p-23 * extent;
  if (params.precision == Precision::f32 && params.method != Method::analytic &&
      params.eps < resolution)
    std::cerr << "warning: " << scene.name << ": --eps " << params.eps
              << " is below float32's resolution at this scene's "
              << (scene.topology.infinite ? "reach (its scale plus max_distance, " : "scale (")
              << resolution
              << "): sphere tracing gets that close to a wall only by landing on it, and many "
                 "rays run out of steps; use --precision f64 or a larger eps\n";
}

void check_reach(const Scene& scene, const Camera& camera, const MarchParams& params) {
  try {
    kernel::check_reach(scene, params.max_distance, Vec2(camera.position));
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--max-distance: ") + e.what());
  }
}

const Backend& MarchOptions::resolve() {
  if (backend.empty()) {
    const Backend* preferred = find_backend(default_backend);
    backend = preferred && preferred->availability().available ? default_backend : fallback_;
  }
  check_backend_options(backend_options);
  made_ = make_backend(backend, backend_options);
  if (!made_)
    throw UsageError("--backend: unknown backend \"" + backend + "\" (see `flatmarch backends`)");
  const Backend* b = made_.get();
  const Availability a = b->availability();
  if (!a.available)
    throw UnavailableError("backend " + backend + " is unavailable here: " + a.reason);
  const std::vector<Method> methods = b->methods();
  const auto preferred = parse_method(default_method);
  if (method.empty() && preferred &&
      std::find(methods.begin(), methods.end(), *preferred) != methods.end()) {
    params.method = *preferred;
  } else if (method.empty()) {
    params.method = methods.front();
  } else {
    const auto m = parse_method(method);
    if (!m)
      throw UsageError("--method: unknown method \"" + method + "\" (" + method_names() + ")");
    if (std::find(methods.begin(), methods.end(), *m) == methods.end())
      throw UsageError("--method: backend " + backend + " does not run method " + method);
    params.method = *m;
  }
  params.precision = parse_precision(precision);
  const std::vector<Precision> precisions = b->precisions();
  if (std::find(precisions.begin(), precisions.end(), params.precision) == precisions.end())
    throw UsageError("--precision: backend " + backend + " does not march in " + precision);
  check_march_params(params);
  return *b;
}

void CameraOptions::add_to(CLI::App& app) {
  app.add_option("--camera-polygon", polygon, "Polygon of the camera position");
  app.add_option("--position", position, "Camera position X,Y,Z in that polygon's coordinates");
  app.add_option("--yaw", yaw_deg, "Camera yaw in degrees (0 looks along +x)");
  app.add_option("--pitch", pitch_deg, "Camera pitch in degrees, in [-90, 90]");
  app.add_option("--fov", fov_deg, "Vertical field of view in degrees, in (0, 180)");
}

Camera CameraOptions::apply(const Scene& scene) const {
  Camera c = scene.camera;
  if (polygon) c.polygon = *polygon;
  if (!position.empty()) c.position = parse_vec3("--position", position);
  if (yaw_deg) c.yaw_deg = *yaw_deg;
  if (pitch_deg) c.pitch_deg = *pitch_deg;
  if (fov_deg) c.fov_deg = *fov_deg;
  if (!std::isfinite(c.yaw_deg)) throw UsageError("--yaw: must be finite");
  if (!(std::abs(c.pitch_deg) <= 90.0)) throw UsageError("--pitch: must lie in [-90, 90]");
  if (!(c.fov_deg > 0.0 && c.fov_deg < 180.0)) throw UsageError("--fov: must lie in (0, 180)");
  if (auto problem = ray_problem(scene, Ray{c.polygon, c.position, Vec3(1.0, 0.0, 0.0)}))
    throw UsageError("camera: " + *problem);
  return c;
}

std::string data_folder(const std::string& sub) {
  const std::string dir = install_folder(kDataFolder);
  return dir.empty() ? sub : (std::filesystem::path(dir) / sub).string();
}

const char* const kSceneArgumentHelp = "Scene file (JSON), or a gallery scene's name (torus)";

std::string named_scene_file(const std::string& file_or_name) {
  namespace fs = std::filesystem;
  const bool name = file_or_name.find('/') == std::string::npos &&
                    fs::path(file_or_name).extension() != ".json" && !fs::exists(file_or_name);
  if (!name) return file_or_name;
  const fs::path in = fs::path(data_folder("scenes")) / (file_or_name + ".json");
  if (fs::exists(in)) return in.string();
  throw UsageError("SCENE: no scene file \"" + file_or_name + "\", nor a scene of that name in " +
                   "the gallery (" + data_folder("scenes") + ")");
}

Scene load_named_scene(const std::string& file_or_name) {
  return load_scene_or_app_geometry(named_scene_file(file_or_name));
}

namespace {

// A scene named by a file, or by its name in one of the gallery folders.
std::filesystem::path scene_file(const std::string& name,
                                 const std::vector<std::string>& galleries) {
  if (std::filesystem::exists(name)) return name;
  for (const std::string& folder : galleries)
    if (const std::filesystem::path in = std::filesystem::path(folder) / (name + ".json");
        std::filesystem::exists(in))
      return in;
  throw UsageError("--scene: no scene file \"" + name + "\", nor " + name + ".json in " +
                   (galleries.empty() ? std::string("any --gallery folder") : galleries.front()) +
                   (galleries.size() > 1 ? " or the other --gallery folders" : ""));
}

}  // namespace

Scene load_scene_or_app_geometry(const std::filesystem::path& file) {
  const nlohmann::json doc = read_json_file(file);
  if (!is_peer_geometry(doc)) {
    Scene scene = scene_from_json(doc, file.string());
    scene.source_file = file.string();
    return scene;
  }
  PeerImport imported = import_peer_file(file);
  imported.scene["name"] = "app_" + file.stem().string();
  return scene_from_json(imported.scene, file.string());
}

std::vector<Scene> load_scenes(const std::vector<std::string>& names,
                               const std::vector<std::string>& galleries) {
  namespace fs = std::filesystem;
  std::vector<fs::path> files;
  for (const std::string& s : names) files.push_back(scene_file(s, galleries));
  if (files.empty()) {
    for (const std::string& folder : galleries) {
      if (!fs::is_directory(folder)) continue;
      std::vector<fs::path> in_folder;
      for (const auto& entry : fs::directory_iterator(folder))
        if (entry.path().extension() == ".json") in_folder.push_back(entry.path());
      std::sort(in_folder.begin(), in_folder.end());
      files.insert(files.end(), in_folder.begin(), in_folder.end());
    }
    if (files.empty())
      throw UsageError("--gallery: no scene files in " + galleries.front() +
                       (galleries.size() > 1 ? " or the other folders" : "") +
                       " (run from the source folder, or give --scene or --gallery)");
  }
  std::vector<Scene> scenes;
  for (const fs::path& f : files) scenes.push_back(load_scene_or_app_geometry(f));
  return scenes;
}

std::string image_module_missing() {
  std::string why;
  return image_library_if_loadable(&why) ? std::string() : why;
}

void say_left_out(const std::string& command, const std::string& what, const std::string& how) {
  // The reason on one line: its "\n  " breaks as spaces.
  std::string why;
  for (const char c : image_module_missing())
    if (c == '\n')
      why += ' ';
    else if (c != ' ' || why.empty() || why.back() != ' ')
      why += c;
  std::fflush(stdout);  // after what the command printed, not amid it
  std::fprintf(stderr, "%s: left out, %s: no image library here (%s). %s\n", command.c_str(),
               what.c_str(), why.c_str(), how.c_str());
}

const char* const kPerceptualLeftOut =
    "Every other figure is measured, and the verdicts are the other checks'";

std::string joined(const std::vector<std::string>& words) {
  std::string text;
  for (const std::string& w : words) text += (text.empty() ? "" : ", ") + w;
  return text;
}

std::string kernel_method_names() {
  std::vector<std::string> names;
  for (Method m : kKernelMethods) names.push_back(to_string(m));
  return joined(names);
}

std::vector<Method> parse_methods(const std::vector<std::string>& names) {
  std::vector<Method> methods;
  for (const std::string& name : names) {
    const auto m = parse_method(name);
    if (!m || *m == Method::oracle)
      throw UsageError("--method: expected one of " + kernel_method_names() + ", got \"" + name +
                       "\"");
    methods.push_back(*m);
  }
  if (methods.empty()) methods.assign(kKernelMethods.begin(), kKernelMethods.end());
  return methods;
}

ProgressReporter::ProgressReporter(std::string label, bool quiet)
    : label_(std::move(label)),
      quiet_(quiet),
      tty_(isatty(fileno(stderr)) != 0),
      started_(now_seconds()) {}

void ProgressReporter::operator()(double fraction) {
  if (quiet_) return;
  const double t = now_seconds();
  const double since = t - started_;
  // Short work stays silent; a terminal gets a live line, a log a line every 5 seconds.
  if (since < 1.0 || (!tty_ && t - last_ < 5.0) || (tty_ && t - last_ < 0.1)) return;
  last_ = t;
  const double eta = fraction > 0.0 ? since * (1.0 - fraction) / fraction : 0.0;
  std::fprintf(stderr, "%s%s: %3.0f%%, %.0f s left%s", tty_ ? "\r" : "", label_.c_str(),
               100.0 * fraction, eta, tty_ ? "   " : "\n");
  std::fflush(stderr);
}

void ProgressReporter::done() {
  if (!quiet_ && tty_ && last_ >= 0.0)
    std::fprintf(stderr, "\r%*s\r", static_cast<int>(label_.size()) + 30, "");
}

nlohmann::json read_json(const std::string& option, const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw UsageError(option + ": cannot read " + file.string());
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw UsageError(option + ": " + file.string() + " is not JSON: " + e.what());
  }
}

void write_json(const std::filesystem::path& file, const nlohmann::json& doc) {
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  // Whole or not at all: written beside it, then renamed over it, so that a run stopped while
  // writing leaves the file it had (or none), never half of one.
  const std::filesystem::path partial = file.string() + ".partial";
  {
    std::ofstream out(partial);
    out << doc.dump(1) << "\n";
    out.flush();
    if (!out) throw std::runtime_error("cannot write " + partial.string());
  }
  std::error_code error;
  std::filesystem::rename(partial, file, error);
  if (error) throw std::runtime_error("cannot write " + file.string() + ": " + error.message());
}

}  // namespace flatmarch::cli
