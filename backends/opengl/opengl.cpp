#include "backends/opengl/opengl.hpp"

#include <chrono>
#include <mutex>
#include <stdexcept>

#include "backends/bands.hpp"
#include "backends/lru_cache.hpp"
#include "backends/opengl/context.hpp"
#include "backends/opengl/gl_api.hpp"
#include "backends/opengl/gl_kernel.hpp"
#include "backends/process_exit.hpp"
#include "backends/readback.hpp"
#include "kernels/scene_shader.hpp"

namespace flatmarch {

namespace {

// Compiled programs kept per context (a program is a scene, its march parameters and a variant).
constexpr size_t kProgramCache = 16;

}  // namespace

struct OpenGlBackend::Context {
  std::unique_ptr<gl::Context> gl_context;
  GLint max_size = 0;            // of a render target's side
  GLint max_groups[2] = {0, 0};  // compute workgroups in x and y
  GLint64 max_storage = 0;       // bytes of a shader storage block
  KernelShape shape = KernelShape::software;
  std::mutex mutex;  // one frame or trace at a time; the context is current only during one
  std::unique_ptr<gl::RenderTargets> targets;  // the last frame's, kept for the next one
  // The software shape's read-back (a pixel pack buffer); the gpu shape's pixels, written by
  // the compute shader, and the copy of them that the host maps.
  std::unique_ptr<gl::Buffer> readback, pixels;
  std::unique_ptr<gl::DeviceClock> clock;
  DeviceTiming timing;  // of the last frame
  // Programs by their source and the table buffer they bind (kernels/scene_shader.hpp).
  LruCache<std::string, std::unique_ptr<gl::KernelProgram>> programs{kProgramCache};
  LruCache<std::string, std::unique_ptr<gl::ComputeProgram>> kernels{kProgramCache};

  const gl::Api& gl() const { return gl_context->api(); }

  // A program by its source and the tables it owns; a trace shared by scenes owns none (its
  // tables come with each trace: kernel::shared_trace).
  gl::KernelProgram& program(const kernel::SceneTables<float>& tables,
                             const kernel::ShaderVariant& variant) {
    const bool shared = variant.trace && kernel::shared_trace(tables);
    return *programs.get(
        kernel::scene_fragment_shader(tables, variant) +
            (shared ? std::string() : kernel::table_buffer(tables)),
        [&] { return std::make_unique<gl::KernelProgram>(gl(), tables, variant); });
  }

  gl::ComputeProgram& compute(const kernel::SceneTables<float>& tables,
                              const kernel::ShaderVariant& variant) {
    return *kernels.get(
        kernel::scene_compute_shader(tables, variant, kernel::ComputeApi::opengl) +
            kernel::table_buffer(tables),
        [&] { return std::make_unique<gl::ComputeProgram>(gl(), tables, variant); });
  }

  ~Context() {
    if (!gl_context) return;
    try {
      const gl::Context::Current current(*gl_context);
      programs.clear();
      kernels.clear();
      targets.reset();
      readback.reset();
      pixels.reset();
      clock.reset();
    } catch (const std::exception&) {
      // The context cannot be made current: its objects go with it.
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
    const std::optional<KernelShape> shape =
        parse_kernel_shape(options_.kernel_shape, c->gl_context->device().software);
    if (!shape) throw std::invalid_argument(kernel_shape_error(options_.kernel_shape));
    c->shape = *shape;
    const gl::Context::Current current(*c->gl_context);
    const gl::Api& gl = c->gl();
    gl.GetIntegerv(GL_MAX_TEXTURE_SIZE, &c->max_size);
    for (GLuint k = 0; k < 2; ++k)
      gl.GetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, k, &c->max_groups[k]);
    gl.GetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &c->max_storage);
    c->readback = std::make_unique<gl::Buffer>(gl);
    c->pixels = std::make_unique<gl::Buffer>(gl);
    c->clock = std::make_unique<gl::DeviceClock>(gl);
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
  return std::string("the kernel as an OpenGL ") +
         (context_->shape == KernelShape::gpu ? "compute" : "fragment") +
         " shader, specialised per scene, headless (" + d.renderer + ", " + d.version + ", " +
         d.platform + (d.software ? ", software" : "") + "; the " + to_string(context_->shape) +
         " shape); f32";
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
                    .software = d.software,
                    .kernel_shape = to_string(context_->shape)};
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
  return draw(scene, camera, width, height, params, progress, false);
}

Frame OpenGlBackend::render_colour(const Scene& scene, const Camera& camera, int width, int height,
                                   const MarchParams& params, const Progress& progress) const {
  return draw(scene, camera, width, height, params, progress, true);
}

bool OpenGlBackend::colour_program_apart() const {
  return context() && context_->shape == KernelShape::software;
}

std::optional<DeviceTiming> OpenGlBackend::last_device_timing() const {
  if (!context()) return std::nullopt;
  const std::lock_guard<std::mutex> lock(context_->mutex);
  return context_->timing;
}

namespace {

// The rows of a frame's bands, drawn or dispatched by `band(row, rows)`: waited for after each
// where their pace is measured (every Banding but none), the device's clock around each.
template <typename F>
double draw_bands(const gl::Api& gl, gl::DeviceClock& clock, double pace, int width, int height,
                  int granule, Banding why, const Progress& progress, F&& band) {
  BandPacer bands(pace, width, height, granule, why);
  for (int row = 0, rows = 0; row < height; row += rows) {
    rows = bands.rows(row);
    const auto start = std::chrono::steady_clock::now();
    clock.begin(gl::DeviceClock::march);
    band(row, rows);
    clock.end(gl::DeviceClock::march);
    if (why != Banding::none) gl.Finish();
    bands.done(rows,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (progress) progress(static_cast<double>(row + rows) / height);
  }
  return bands.pace();
}

}  // namespace

Frame OpenGlBackend::draw(const Scene& scene, const Camera& camera, int width, int height,
                          const MarchParams& params, const Progress& progress,
                          bool colour_only) const {
  check_precision(params);
  if (!context()) unavailable(unavailable_);
  Context& c = *context_;
  if (width <= 0 || height <= 0) throw std::invalid_argument("the image has no pixels");
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  const size_t bytes = pixels * (colour_only ? kColourReadbackBytes : kWholeReadbackBytes);
  const bool compute = c.shape == KernelShape::gpu;
  const GLint groups_x = (width + kernel::kComputeTile - 1) / kernel::kComputeTile;
  if (compute ? static_cast<GLint64>(bytes) > c.max_storage || groups_x > c.max_groups[0] ||
                    (height + kernel::kComputeTile - 1) / kernel::kComputeTile > c.max_groups[1]
              : width > c.max_size || height > c.max_size)
    throw std::invalid_argument(
        compute ? "the opengl backend's compute shader renders at most " +
                      std::to_string(c.max_storage / static_cast<GLint64>(bytes / pixels)) +
                      " pixels" + (colour_only ? "" : " with their AOVs") + " and " +
                      std::to_string(static_cast<int64_t>(c.max_groups[0]) * kernel::kComputeTile) +
                      " a row here"
                : "the opengl backend renders at most " + std::to_string(c.max_size) +
                      " pixels a side here");
  const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
  const std::lock_guard<std::mutex> lock(c.mutex);
  const gl::Context::Current current(*c.gl_context);
  const gl::Api& gl = c.gl();
  gl.GetError();  // a clean slate for the check below
  const kernel::ShaderVariant variant{
      .from_band = kernel::within_band(tables, camera.position),
      .shape = c.shape,
      .readback = colour_only ? kernel::Readback::colour : kernel::Readback::all};
  const CameraBasis<float> basis = camera_basis<float>(
      float(camera.yaw_deg), float(camera.pitch_deg), float(camera.fov_deg), width, height);
  const Banding why = banding(static_cast<bool>(progress), c.gl_context->device().software);
  gl::DeviceClock& clock = *c.clock;
  clock.read();  // nothing left over from an earlier frame that failed
  gl::Buffer& readback = *c.readback;

  if (compute) {
    const gl::ComputeProgram& program = c.compute(tables, variant);
    c.pixels->bind(GL_SHADER_STORAGE_BUFFER, bytes, GL_DYNAMIC_COPY);
    gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, c.pixels->id());
    kernel::ComputeConstants constants{
        .from = glm::vec4(glm::vec3(camera.position), 0.0f),
        .forward = glm::vec4(basis.forward, 0.0f),
        .right = glm::vec4(basis.right, 0.0f),
        .up = glm::vec4(basis.up, 0.0f),
        .scale = glm::vec4(basis.aspect * basis.tan_half_fov, basis.tan_half_fov, 0.0f, 0.0f),
        .frame = glm::ivec4(width, height, 0, camera.polygon),
        .order = glm::ivec4(1, colour_only ? 1 : 0, 0, 0)};
    program.set_seconds_per_pixel(
        draw_bands(gl, clock, program.seconds_per_pixel(), width, height, kernel::kComputeTile, why,
                   progress, [&](int row, int rows) {
                     const int tile_rows = (rows + kernel::kComputeTile - 1) / kernel::kComputeTile;
                     constants.frame.z = row;
                     constants.order.x = kernel::row_stride(tile_rows);
                     program.dispatch(constants, static_cast<GLuint>(groups_x),
                                      static_cast<GLuint>(tile_rows));
                   }));
    // The pixels copied where the host maps them, as a discrete GPU's must be.
    gl.MemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    clock.begin(gl::DeviceClock::readback);
    gl.BindBuffer(GL_COPY_READ_BUFFER, c.pixels->id());
    readback.bind(GL_COPY_WRITE_BUFFER, bytes, GL_STREAM_READ);
    gl.CopyBufferSubData(GL_COPY_READ_BUFFER, GL_COPY_WRITE_BUFFER, 0, 0,
                         static_cast<GLsizeiptr>(bytes));
    clock.end(gl::DeviceClock::readback);
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, readback.id());
  } else {
    const gl::KernelProgram& program = c.program(tables, variant);
    if (!c.targets || c.targets->width() != width || c.targets->height() != height ||
        c.targets->readback() != variant.readback) {
      c.targets.reset();
      c.targets = std::make_unique<gl::RenderTargets>(gl, width, height, variant.readback);
    }
    c.targets->bind();
    gl.Viewport(0, 0, width, height);
    gl.Enable(GL_SCISSOR_TEST);
    // The image's row j is drawn at OpenGL's row j, so that the read-back is in the frame's
    // order.
    program.set_seconds_per_pixel(
        draw_bands(gl, clock, program.seconds_per_pixel(), width, height, 1, why, progress,
                   [&](int row, int rows) {
                     gl.Scissor(0, row, width, rows);
                     program.draw(basis, camera.polygon, glm::vec3(camera.position), width, height,
                                  gl::KernelProgram::Rows::top_first);
                   }));
    gl.Disable(GL_SCISSOR_TEST);
    // Into a pixel pack buffer: the device copies, and the host maps it once that is done.
    clock.begin(gl::DeviceClock::readback);
    readback.bind(GL_PIXEL_PACK_BUFFER, bytes, GL_STREAM_READ);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    if (colour_only) {
      gl.ReadPixels(0, 0, width, height, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    } else {
      gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, nullptr);
      gl.ReadBuffer(GL_COLOR_ATTACHMENT1);
      gl.ReadPixels(0, 0, width, height, GL_RGBA_INTEGER, GL_UNSIGNED_INT,
                    reinterpret_cast<void*>(pixels * 16));
    }
    clock.end(gl::DeviceClock::readback);
  }
  const void* mapped =
      gl.MapBufferRange(GL_PIXEL_PACK_BUFFER, 0, static_cast<GLsizeiptr>(bytes), GL_MAP_READ_BIT);
  if (!mapped) {
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    throw std::runtime_error("the opengl backend cannot map its read-back: " + gl::errors(gl));
  }
  Frame frame =
      colour_only ? colour_frame(mapped, width, height) : whole_frame(mapped, width, height);
  gl.UnmapBuffer(GL_PIXEL_PACK_BUFFER);
  gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  c.timing = clock.read();
  if (const std::string e = gl::errors(gl); !e.empty())
    throw std::runtime_error("the opengl backend failed to render: " + e);
  return frame;
}

void OpenGlBackend::compile(const std::string& source, bool compute) const {
  if (!context()) unavailable(unavailable_);
  const std::lock_guard<std::mutex> lock(context_->mutex);
  const gl::Context::Current current(*context_->gl_context);
  const gl::Api& gl = context_->gl();
  gl.DeleteProgram(compute ? gl::link_compute(gl, source)
                           : gl::link_program(gl, kernel::kFullScreenVertexShader, source));
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
  gl::KernelProgram& program = c.program(tables, {.trace = true, .shape = c.shape});
  c.targets.reset();  // bound while it lives; a trace draws to one pixel
  const gl::RenderTargets targets(gl, 1, 1);
  Trace trace = program.trace(ray, max_events, tables);
  if (const std::string e = gl::errors(gl); !e.empty())
    throw std::runtime_error("the opengl backend failed to trace: " + e);
  return trace;
}

}  // namespace flatmarch
