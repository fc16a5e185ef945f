#include "backends/opengl/opengl.hpp"

#include <mutex>
#include <stdexcept>

#include "backends/lru_cache.hpp"
#include "backends/opengl/context.hpp"
#include "backends/opengl/gl_api.hpp"
#include "backends/opengl/gl_kernel.hpp"
#include "backends/process_exit.hpp"
#include "kernels/scene_shader.hpp"

namespace flatmarch {

namespace {

// Compiled programs kept per context (a program is a scene, its march parameters and a variant).
constexpr size_t kProgramCache = 16;

}  // namespace

struct OpenGlBackend::Context {
  std::unique_ptr<gl::Context> gl_context;
  GLint max_size = 0;
  std::mutex mutex;  // one frame or trace at a time; the context is current only during one
  std::unique_ptr<gl::RenderTargets> targets;  // the last frame's, kept for the next one
  std::vector<float> aovs;                     // read-back of the AOV target, reused
  // Programs by their fragment source.
  LruCache<std::string, std::unique_ptr<gl::KernelProgram>> programs{kProgramCache};

  const gl::Api& gl() const { return gl_context->api(); }

  gl::KernelProgram& program(const kernel::SceneTables<float>& tables, bool trace,
                             bool from_band = false) {
    return *programs.get(kernel::scene_fragment_shader(tables, trace, from_band), [&] {
      return std::make_unique<gl::KernelProgram>(gl(), tables, trace, from_band);
    });
  }

  ~Context() {
    if (!gl_context) return;
    try {
      const gl::Context::Current current(*gl_context);
      programs.clear();
      targets.reset();
    } catch (const std::exception&) {
      // The context cannot be made current: its programs go with it.
    }
  }
};

OpenGlBackend::OpenGlBackend(const BackendOptions& options) : options_(options) {}

// The context is made on first use, not when the backend is listed: every command builds the
// backend registry, and few draw.
OpenGlBackend::Context* OpenGlBackend::context() const {
  std::call_once(made_, [this] { make_context(); });
  return context_.get();
}

void OpenGlBackend::make_context() const {
  auto c = std::make_unique<Context>();
  try {
    c->gl_context = gl::make_context(options_.device);
    const gl::Context::Current current(*c->gl_context);
    c->gl().GetIntegerv(GL_MAX_TEXTURE_SIZE, &c->max_size);
  } catch (const std::exception& e) {
    unavailable_ = e.what();
    return;
  }
  context_ = std::move(c);
  driver_loaded();  // after the driver has made its context, threads and exit handlers
}

OpenGlBackend::~OpenGlBackend() {
  release_context(context_);
}

namespace {
[[noreturn]] void unavailable(const std::string& why) {
  throw std::runtime_error("the opengl backend is unavailable: " + why);
}
}  // namespace

std::string OpenGlBackend::description() const {
  if (!context())
    return "the kernel as an OpenGL fragment shader, specialised per scene (unavailable)";
  const gl::Device& d = context_->gl_context->device();
  return "the kernel as an OpenGL fragment shader, specialised per scene, headless (" + d.renderer +
         ", " + d.version + ", " + d.platform + (d.software ? ", software" : "") + "); f32";
}

Availability OpenGlBackend::availability() const {
  if (!context()) return {false, unavailable_};
  return {};
}

std::optional<DeviceInfo> OpenGlBackend::device() const {
  if (!context()) return std::nullopt;
  const gl::Device& d = context_->gl_context->device();
  return DeviceInfo{.name = d.renderer,
                    .type = d.software ? "CPU" : "GPU",
                    .api = "OpenGL " + d.version,
                    .driver = d.driver(),
                    .platform = d.platform,
                    .software = d.software};
}

std::string OpenGlBackend::renderer() const {
  if (!context()) return "";
  const gl::Device& d = context_->gl_context->device();
  return d.renderer + ", " + d.version;
}

int OpenGlBackend::device_index() const {
  return context() ? context_->gl_context->device().index : -1;
}

namespace {

void check_precision(const MarchParams& params) {
  if (params.precision != Precision::f32)
    throw std::invalid_argument(
        "the opengl backend marches in f32 only (the scalar backend runs f64)");
}

}  // namespace

Frame OpenGlBackend::render(const Scene& scene, const Camera& camera, int width, int height,
                            const MarchParams& params, const Progress& progress) const {
  check_precision(params);
  if (!context()) unavailable(unavailable_);
  Context& c = *context_;
  if (width > c.max_size || height > c.max_size)
    throw std::invalid_argument("the opengl backend renders at most " + std::to_string(c.max_size) +
                                " pixels a side here");
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
  const std::lock_guard<std::mutex> lock(c.mutex);
  const gl::Context::Current current(*c.gl_context);
  const gl::Api& gl = c.gl();
  gl.GetError();  // a clean slate for the check below
  gl::KernelProgram& program =
      c.program(tables, false, kernel::within_band(tables, camera.position));
  if (!c.targets || c.targets->width() != width || c.targets->height() != height) {
    c.targets.reset();
    c.targets = std::make_unique<gl::RenderTargets>(gl, width, height);
  }
  c.targets->bind();
  const CameraBasis<float> basis = camera_basis<float>(
      float(camera.yaw_deg), float(camera.pitch_deg), float(camera.fov_deg), width, height);
  Frame frame(width, height);
  gl::draw_frame(gl, program, basis, camera.polygon, glm::vec3(camera.position), progress, frame,
                 &c.aovs);
  if (const std::string e = gl::errors(gl); !e.empty())
    throw std::runtime_error("the opengl backend failed to render: " + e);
  return frame;
}

void OpenGlBackend::compile(const std::string& fragment) const {
  if (!context()) unavailable(unavailable_);
  const std::lock_guard<std::mutex> lock(context_->mutex);
  const gl::Context::Current current(*context_->gl_context);
  const gl::Api& gl = context_->gl();
  gl.DeleteProgram(gl::link_program(gl, kernel::kFullScreenVertexShader, fragment));
}

Trace OpenGlBackend::trace(const Scene& scene, const Ray& ray, const MarchParams& params,
                           int max_events) const {
  check_precision(params);
  if (!context()) unavailable(unavailable_);
  Context& c = *context_;
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
  const std::lock_guard<std::mutex> lock(c.mutex);
  const gl::Context::Current current(*c.gl_context);
  const gl::Api& gl = c.gl();
  gl.GetError();
  gl::KernelProgram& program = c.program(tables, true);
  c.targets.reset();  // bound while it lives; a trace draws to one pixel
  const gl::RenderTargets targets(gl, 1, 1);
  Trace trace = program.trace(ray, max_events);
  if (const std::string e = gl::errors(gl); !e.empty())
    throw std::runtime_error("the opengl backend failed to trace: " + e);
  return trace;
}

}  // namespace flatmarch
