// peer_adapter: the original web app of Lander & Taha (RayMarchingFlatSurfaces) as a renderer
// under the external renderer protocol (docs/external.md), so that the conformance suite judges
// its images and AOVs against the oracle.
//
//   peer_adapter [--app=DIR] [--device=NAME] REQUEST_JSON
//
// DIR (default $FLATMARCH_PEER_APP) is a checkout of the app; its files are not ours to ship.
// The app renders only its own geometry files, so the request must name the one its scene was
// imported from. The app's own generator (run in Node by peer_adapter/generate.mjs) makes the
// shader, which is drawn twice on OpenGL (bench/peer_app.hpp): as generated, for the colour,
// and with a few marked edits that write the march's state instead, for the AOVs. Every edit is
// an exact replacement of a line of the app's template that fails when the line is not there,
// so that a changed app is noticed rather than misjudged.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/peer_app.hpp"
#include "kernels/camera.hpp"
#include "kernels/compile.hpp"
#include "output/image_io.hpp"
#include "scene/load.hpp"

extern char** environ;

namespace flatmarch::bench {

namespace {

using Json = nlohmann::json;

// Exit code of a case the app cannot render (docs/external.md).
constexpr int kCannotRender = 77;

struct CannotRender : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Options {
  std::filesystem::path app;
  std::string device;  // as --device: empty for the first GPU, else a software rasteriser
  std::string request;
};

Options parse_options(int argc, char** argv) {
  Options o;
  if (const char* app = std::getenv("FLATMARCH_PEER_APP")) o.app = app;
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg.starts_with("--app="))
      o.app = arg.substr(6);
    else if (arg.starts_with("--device="))
      o.device = arg.substr(9);
    else if (k == argc - 1 && !arg.starts_with("--"))
      o.request = arg;
    else
      throw std::invalid_argument("unknown argument " + arg);
  }
  if (o.request.empty())
    throw std::invalid_argument("usage: peer_adapter [--app=DIR] [--device=NAME] REQUEST_JSON");
  if (o.app.empty())
    throw std::invalid_argument(
        "no app: give --app=DIR or FLATMARCH_PEER_APP, a checkout of RayMarchingFlatSurfaces");
  for (const char* file : {"public/shader/template.frag", "src/core/ShaderGenerator.js"})
    if (!std::filesystem::exists(o.app / file))
      throw std::invalid_argument(o.app.string() + " is not a checkout of the app: it has no " +
                                  file);
  return o;
}

// A fresh folder under the system's temporary one, removed with its files at the end.
class TemporaryFolder {
 public:
  TemporaryFolder() {
    std::string name = (std::filesystem::temp_directory_path() / "peer-adapter-XXXXXX").string();
    if (mkdtemp(name.data()) == nullptr)
      throw std::runtime_error("cannot make a temporary folder: " + std::string(strerror(errno)));
    path_ = name;
  }
  ~TemporaryFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TemporaryFolder(const TemporaryFolder&) = delete;
  TemporaryFolder& operator=(const TemporaryFolder&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// The last line of a program's error output that says something: generate.mjs ends with its
// reason, after whatever the app's generator warned of.
std::string last_line(const std::string& text) {
  std::istringstream lines(text);
  std::string line, last;
  while (std::getline(lines, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  return last;
}

// The app's shader for `geometry`, from its generator run in Node (generate.mjs).
std::string generate(const std::filesystem::path& app, const std::filesystem::path& geometry) {
  const TemporaryFolder folder;
  const std::string out = (folder.path() / "stdout").string();
  const std::string err = (folder.path() / "stderr").string();
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  const std::string script = FLATMARCH_PEER_GENERATOR;
  std::vector<std::string> args{"node", script, app.string(), geometry.string()};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, "node", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0)
    throw std::runtime_error("cannot run node (" + std::string(strerror(spawned)) +
                             "): the app's shader generator (src/core/ShaderGenerator.js) runs "
                             "in Node 18 or later, which must be on the PATH");
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw std::runtime_error("cannot wait for node");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const std::string why = last_line(read_text(err));
    throw std::runtime_error(why.empty() ? "the app's shader generator failed (node exited with " +
                                               std::to_string(WEXITSTATUS(status)) + ")"
                                         : why);
  }
  return Json::parse(read_text(out)).at("shader").get<std::string>();
}

// Replaces the one occurrence of `line` in the app's shader: an edit of ours, which must say so
// in a `// flatmarch edit:` comment.
void edit(std::string& source, const std::string& line, const std::string& replacement) {
  const size_t at = source.find(line);
  if (at == std::string::npos)
    throw std::runtime_error("the app's shader has changed: cannot find \"" + line + "\"");
  if (source.find(line, at + 1) != std::string::npos)
    throw std::runtime_error("the app's shader has changed: \"" + line +
                             "\" is there more than once");
  source.replace(at, line.size(), replacement);
}

// The app divides its pixel coordinates by the shorter side and scales them by tan(fov / 2), so
// our vertical field of view f over `height` rows is its tan(fov / 2) = 2 tan(f / 2) min / height.
void use_our_fov(std::string& source, double fov_deg, int width, int height) {
  const double tan_half = 2.0 * std::tan(0.5 * glm::radians(fov_deg)) *
                          static_cast<double>(std::min(width, height)) / height;
  std::ostringstream value;
  value << std::fixed << std::setprecision(9) << tan_half;
  std::ostringstream fov;
  fov << fov_deg;
  edit(source, "float fov = radians(75.0);",
       "float fov = 2.0 * atan(" + value.str() +
           "); // flatmarch edit: our vertical field of view, " + fov.str() + " degrees over " +
           std::to_string(height) + " rows");
}

// How the app's loop ended, as the state pass writes it.
constexpr int kEndedOnDecoration = 0, kEndedPastMaxDistance = 1, kEndedOutOfIterations = 2;

// Edits that leave the march and the colour as they are but write, instead of the colour, the
// loop's iterations, the crossings, how the loop ended (kEnded*) to the first target and the
// final position to the second. The loop leaves on a decoration (finalHitID 1000) before it
// adds the step to t, and past tMax just after, so t and finalHitID tell the three endings apart.
void write_march_state(std::string& source) {
  edit(source, "float collision_count = 0.0;",
       "float collision_count = 0.0;\n"
       "    float flatmarch_steps = 0.0; // flatmarch edit: the loop's iterations");
  edit(source, "float sceneDist = sdf(pos);",
       "flatmarch_steps += 1.0; // flatmarch edit: one more iteration\n"
       "        float sceneDist = sdf(pos);");
  edit(source, "gl_FragColor = vec4(color, 1.0) - collision_count * vec4(fog_effect_strength);",
       "// flatmarch edit: the march's state instead of the colour\n"
       "    float flatmarch_end = finalHitID >= 1000.0 ? " +
           std::to_string(kEndedOnDecoration) + ".0 : (t > tMax ? " +
           std::to_string(kEndedPastMaxDistance) + ".0 : " + std::to_string(kEndedOutOfIterations) +
           ".0);\n"
           "    gl_FragData[0] = vec4(flatmarch_steps, collision_count, flatmarch_end, 0.0);\n"
           "    gl_FragData[1] = vec4(pos, 1.0);");
}

// The app's coordinates are y-up: its (x, y, z) is our (x, z, y + wall height) in the scene's
// one polygon, whose band is twice the app's wall height.
glm::vec3 to_app(Vec3 v) {
  return glm::vec3(v.x, v.z, v.y);
}

// Our camera (DESIGN.md section 2) as the app's uniforms. Mapping our frame into the app's
// swaps two axes, which mirrors cross products: the app's right, cross(front, up), is our -R. So
// the app's column x is our column width - 1 - x, for the same rays (run flips them back).
AppView app_view(const Json& camera, double wall_height, int width, int height) {
  const auto p = camera.at("position").get<std::vector<double>>();
  if (p.size() != 3) throw std::runtime_error("the request's camera position is not 3 numbers");
  const CameraBasis<double> basis =
      camera_basis(camera.value("yaw_deg", 0.0), camera.value("pitch_deg", 0.0),
                   camera.value("fov_deg", 75.0), width, height);
  return {to_app(Vec3(p[0], p[1], p[2] - wall_height)), to_app(basis.forward), to_app(basis.up)};
}

// A framebuffer of new textures of one format, `count` colour attachments, all drawn into.
class Target {
 public:
  Target(const gl::Api& gl, GLenum format, int count, int width, int height)
      : gl_(gl), width_(width), height_(height), textures_(static_cast<size_t>(count)) {
    gl.GenFramebuffers(1, &framebuffer_);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
    gl.GenTextures(count, textures_.data());
    std::vector<GLenum> buffers;
    for (int k = 0; k < count; ++k) {
      gl.BindTexture(GL_TEXTURE_2D, textures_[static_cast<size_t>(k)]);
      gl.TexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(format), width, height, 0, GL_RGBA,
                    format == GL_RGBA8 ? GL_UNSIGNED_BYTE : GL_FLOAT, nullptr);
      buffers.push_back(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(k));
      gl.FramebufferTexture2D(GL_FRAMEBUFFER, buffers.back(), GL_TEXTURE_2D,
                              textures_[static_cast<size_t>(k)], 0);
    }
    gl.DrawBuffers(count, buffers.data());
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("the app's framebuffer is incomplete");
  }
  ~Target() {
    gl_.DeleteFramebuffers(1, &framebuffer_);
    gl_.DeleteTextures(static_cast<GLsizei>(textures_.size()), textures_.data());
  }
  Target(const Target&) = delete;
  Target& operator=(const Target&) = delete;

  void bind() const { gl_.BindFramebuffer(GL_FRAMEBUFFER, framebuffer_); }

  // Attachment k's pixels, 4 values a pixel, rows from the bottom (GL's order).
  template <typename T>
  std::vector<T> read(int k) const {
    bind();
    gl_.ReadBuffer(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(k));
    std::vector<T> pixels(4 * static_cast<size_t>(width_) * static_cast<size_t>(height_));
    gl_.ReadPixels(0, 0, width_, height_, GL_RGBA,
                   std::is_same_v<T, float> ? GL_FLOAT : GL_UNSIGNED_BYTE, pixels.data());
    return pixels;
  }

 private:
  const gl::Api& gl_;
  int width_, height_;
  GLuint framebuffer_ = 0;
  std::vector<GLuint> textures_;
};

// What the app draws: its colour (8-bit, as the page shows it) and its march's state, each 4
// values a pixel in GL's order.
struct AppFrame {
  std::vector<unsigned char> colour;
  std::vector<float> state, position;
};

AppFrame draw(const std::string& colour_shader, const std::string& state_shader,
              const AppView& view, int width, int height, const std::string& device) {
  const std::unique_ptr<gl::Context> context = gl::make_context(device, gl::Profile::compatibility);
  const gl::Context::Current current(*context);
  const gl::Api& gl = context->api();
  const AppTriangle triangle(gl);
  AppFrame frame;
  {
    const AppProgram program(gl, colour_shader);
    const Target target(gl, GL_RGBA8, 1, width, height);
    program.draw(triangle, view, width, height);
    frame.colour = target.read<unsigned char>(0);
  }
  {
    const AppProgram program(gl, state_shader);
    const Target target(gl, GL_RGBA32F, 2, width, height);
    program.draw(triangle, view, width, height);
    frame.state = target.read<float>(0);
    frame.position = target.read<float>(1);
  }
  if (const std::string e = gl::errors(gl); !e.empty())
    throw std::runtime_error("the app's frame failed: " + e);
  return frame;
}

// The solids of the scene's one room (its objects and markers) with their hit indices, from the
// kernel's tables, to tell which one the app's "decoration" is.
class Solids {
 public:
  explicit Solids(const Scene& scene) : tables_(kernel::compile_scene<double>(scene, {})) {}

  // The index of the solid nearest to `p` (our coordinates), or kHitMiss where there is none.
  int nearest(Vec3 p) const {
    kernel::Maths<double> maths;  // its functions are not const
    const glm::ivec4 room = tables_.polygons.at(0);
    int best = kHitMiss;
    double best_distance = std::numeric_limits<double>::infinity();
    for (int k = room.z; k < room.z + room.w; ++k) {
      const auto& o = tables_.objects[static_cast<size_t>(k)];
      const double d = maths.solid_sdf(o.info.x, Vec3(o.center), o.shape, p);
      if (d < best_distance) best = o.info.y, best_distance = d;
    }
    return best;
  }

 private:
  kernel::SceneTables<double> tables_;
};

// How a pixel's ray ended in our hit codes (DESIGN.md section 4). Past tMax a ray has escaped
// when it ends above or below the band (never in a translation prism, whose heights wrap), and
// run out of distance inside it.
int hit_code(int ended, Vec3 end, const Scene& scene, const Solids& solids) {
  switch (ended) {
    case kEndedOnDecoration:
      return solids.nearest(end);
    case kEndedPastMaxDistance:
      return scene.in_band(end.z) ? kHitMaxDistance : kHitEscape;
    case kEndedOutOfIterations:
      return kHitMaxSteps;
  }
  throw std::runtime_error("the state pass wrote an unknown ending " + std::to_string(ended));
}

const Json& member(const Json& j, const char* key, const char* what) {
  if (!j.is_object() || !j.contains(key))
    throw std::runtime_error(std::string(what) + " has no \"" + key + "\"");
  return j.at(key);
}

void run(const Options& options) {
  const Json request = Json::parse(options.request);
  const Json from = request.contains("imported_from") ? request["imported_from"] : Json();
  if (!from.is_object() || from.value("format", std::string()) != "peer-app" ||
      !from.contains("file"))
    throw CannotRender(
        "the app reads only its own geometry files: this scene was not imported from one "
        "(the request has no imported_from of format peer-app)");
  if (const std::string method = request.value("method", std::string("sphere")); method != "sphere")
    throw CannotRender("the app marches by sphere tracing only, not by " + method);
  const Scene scene = scene_from_json(member(request, "scene", "the request"),
                                      request.value("scene_file", std::string("request")));
  const int width = member(request, "width", "the request").get<int>();
  const int height = member(request, "height", "the request").get<int>();
  if (width <= 0 || height <= 0) throw std::runtime_error("the request's frame has no pixels");
  const Json& camera = member(request, "camera", "the request");
  const std::filesystem::path exr =
      member(member(request, "output", "the request"), "exr", "the request's output")
          .get<std::string>();

  std::string colour_shader = generate(options.app, from.at("file").get<std::string>());
  use_our_fov(colour_shader, camera.value("fov_deg", 75.0), width, height);
  std::string state_shader = colour_shader;
  write_march_state(state_shader);
  const double wall_height = 0.5 * scene.height;
  const AppFrame app =
      draw(colour_shader, state_shader, app_view(camera, wall_height, width, height), width, height,
           options.device);

  // GL's rows run from the bottom and the app's columns are ours mirrored (app_view): flipping
  // both reverses the order of the pixels.
  const Solids solids(scene);
  const size_t last = static_cast<size_t>(width) * static_cast<size_t>(height) - 1;
  Frame frame(width, height);
  for (size_t px = 0; px <= last; ++px) {
    const size_t g = 4 * (last - px);
    // The app writes display values, which the 8-bit target keeps as they are.
    const auto linear = [&](int c) {
      return static_cast<float>(decode_srgb(app.colour[g + static_cast<size_t>(c)] / 255.0));
    };
    const Vec3 end(app.position[g], app.position[g + 2], app.position[g + 1] + wall_height);
    const int hit = hit_code(static_cast<int>(app.state[g + 2]), end, scene, solids);
    frame.set(px, linear(0), linear(1), linear(2), app.state[g], app.state[g + 1],
              static_cast<float>(hit), 0.0f);
  }
  write_aov_exr(frame, exr);
}

// Error messages on one line: the suite shows a skipped case's first line.
std::string one_line(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '\n' || c == '\r') {
      if (!out.empty() && out.back() != ' ') out += "; ";
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

}  // namespace flatmarch::bench

int main(int argc, char** argv) {
  using namespace flatmarch::bench;
  try {
    run(parse_options(argc, argv));
    return 0;
  } catch (const CannotRender& e) {
    std::cerr << one_line(e.what()) << "\n";
    return kCannotRender;
  } catch (const std::exception& e) {
    std::cerr << "peer_adapter: " << one_line(e.what()) << "\n";
    return 1;
  }
}
