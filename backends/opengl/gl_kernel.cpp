#include "backends/opengl/gl_kernel.hpp"

#include <algorithm>
#include <chrono>
#include <initializer_list>

#include "backends/bands.hpp"

#include "backends/kernel_trace.hpp"
#include "kernels/scene_shader.hpp"

namespace flatmarch::gl {

namespace {

GLuint compile(const Api& gl, GLenum stage, const std::string& source) {
  const GLuint shader = gl.CreateShader(stage);
  const char* text = source.c_str();
  gl.ShaderSource(shader, 1, &text, nullptr);
  gl.CompileShader(shader);
  GLint ok = GL_FALSE, length = 0;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok == GL_TRUE) return shader;
  gl.GetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
  gl.GetShaderInfoLog(shader, length, nullptr, log.data());
  gl.DeleteShader(shader);
  log.resize(log.find('\0') == std::string::npos ? log.size() : log.find('\0'));
  const char* name = stage == GL_VERTEX_SHADER    ? "vertex"
                     : stage == GL_COMPUTE_SHADER ? "compute"
                                                  : "fragment";
  throw kernel::ShaderError(std::string(name) + " shader does not compile:\n" +
                            kernel::annotate_log(source, log));
}

// Links compiled shaders (deleted here: freed with the program) into a program.
GLuint link(const Api& gl, std::initializer_list<GLuint> shaders) {
  const GLuint program = gl.CreateProgram();
  for (GLuint shader : shaders) gl.AttachShader(program, shader);
  gl.LinkProgram(program);
  for (GLuint shader : shaders) gl.DeleteShader(shader);
  GLint ok = GL_FALSE, length = 0;
  gl.GetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok == GL_TRUE) return program;
  gl.GetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
  gl.GetProgramInfoLog(program, length, nullptr, log.data());
  gl.DeleteProgram(program);
  throw kernel::ShaderError("the shader program does not link:\n" + log);
}

}  // namespace

GLuint link_program(const Api& gl, const std::string& vertex, const std::string& fragment) {
  const GLuint vs = compile(gl, GL_VERTEX_SHADER, vertex);
  GLuint fs = 0;
  try {
    fs = compile(gl, GL_FRAGMENT_SHADER, fragment);
  } catch (...) {
    gl.DeleteShader(vs);
    throw;
  }
  return link(gl, {vs, fs});
}

GLuint link_compute(const Api& gl, const std::string& compute) {
  return link(gl, {compile(gl, GL_COMPUTE_SHADER, compute)});
}

namespace {

// The targets of a readback: their internal formats (0: none).
struct TargetFormats {
  GLenum colour, aovs;
};
TargetFormats formats(kernel::Readback r) {
  switch (r) {
    case kernel::Readback::colour:
      return {GL_R32UI, 0};
    case kernel::Readback::all:
      return {GL_RGBA32F, GL_RGBA32UI};
    case kernel::Readback::floats:
      break;
  }
  return {GL_RGBA32F, GL_RGBA32F};
}

}  // namespace

RenderTargets::RenderTargets(const Api& gl, int width, int height, kernel::Readback readback)
    : gl_(gl), width_(width), height_(height), readback_(readback) {
  const TargetFormats f = formats(readback);
  const GLenum internal[2] = {f.colour, f.aovs};
  gl.GenFramebuffers(1, &framebuffer_);
  gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
  const GLsizei count = f.aovs ? 2 : 1;
  gl.GenTextures(count, textures_);
  for (int k = 0; k < count; ++k) {
    const bool integer = internal[k] != GL_RGBA32F;
    gl.BindTexture(GL_TEXTURE_2D, textures_[k]);
    gl.TexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(internal[k]), width, height, 0,
                  integer ? (internal[k] == GL_R32UI ? GL_RED_INTEGER : GL_RGBA_INTEGER) : GL_RGBA,
                  integer ? GL_UNSIGNED_INT : GL_FLOAT, nullptr);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(k),
                            GL_TEXTURE_2D, textures_[k], 0);
  }
  bind();
  if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.DeleteTextures(count, textures_);
    gl.DeleteFramebuffers(1, &framebuffer_);
    throw std::runtime_error("OpenGL cannot draw to the frame's targets at " +
                             std::to_string(width) + "x" + std::to_string(height));
  }
}

void RenderTargets::bind() const {
  gl_.BindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
  const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  gl_.DrawBuffers(textures_[1] ? 2 : 1, buffers);
}

RenderTargets::~RenderTargets() {
  gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
  gl_.DeleteTextures(textures_[1] ? 2 : 1, textures_);
  gl_.DeleteFramebuffers(1, &framebuffer_);
}

Buffer::Buffer(const Api& gl) : gl_(gl) {
  gl.GenBuffers(1, &id_);
}

Buffer::~Buffer() {
  gl_.DeleteBuffers(1, &id_);
}

void Buffer::bind(GLenum target, size_t bytes, GLenum usage) {
  gl_.BindBuffer(target, id_);
  if (bytes <= size_) return;
  // Grown by half again at least: frames of growing sizes reallocate rarely.
  const size_t size = std::max(bytes, size_ + size_ / 2);
  gl_.BufferData(target, static_cast<GLsizeiptr>(size), nullptr, usage);
  size_ = size;
}

DeviceClock::DeviceClock(const Api& gl) : gl_(gl) {
  GLint bits = 0;
  gl.GetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &bits);
  if (bits <= 0) {
    why_ = "the OpenGL device has no timer (GL_TIME_ELAPSED counts 0 bits)";
    return;
  }
  gl.GenQueries(2, queries_);
}

DeviceClock::~DeviceClock() {
  if (available()) gl_.DeleteQueries(2, queries_);
}

void DeviceClock::begin(Span s) {
  if (!available()) return;
  settle(s);
  gl_.BeginQuery(GL_TIME_ELAPSED, queries_[s]);
}

void DeviceClock::end(Span s) {
  if (!available()) return;
  gl_.EndQuery(GL_TIME_ELAPSED);
  pending_[s] = true;
}

void DeviceClock::settle(Span s) {
  if (!pending_[s]) return;
  GLuint64 ns = 0;
  gl_.GetQueryObjectui64v(queries_[s], GL_QUERY_RESULT, &ns);
  seconds_[s] += static_cast<double>(ns) * 1e-9;
  pending_[s] = false;
}

DeviceTiming DeviceClock::read() {
  if (!available()) return {.why = why_};
  settle(march);
  settle(readback);
  const DeviceTiming t{
      .measured = true, .why = {}, .march_s = seconds_[march], .readback_s = seconds_[readback]};
  seconds_[march] = seconds_[readback] = 0.0;
  return t;
}

namespace {

// A buffer of the scene's tables where its shader reads them from one (kernels/scene_shader.hpp's
// tables_in_buffer), else 0.
GLuint make_table_buffer(const Api& gl, const kernel::SceneTables<float>& tables) {
  const std::string bytes = kernel::table_buffer(tables);
  if (bytes.empty()) return 0;
  GLuint id = 0;
  gl.GenBuffers(1, &id);
  gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, id);
  gl.BufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(bytes.size()), bytes.data(),
                GL_STATIC_DRAW);
  gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
  return id;
}

void bind_tables(const Api& gl, GLuint tables) {
  if (tables != 0) gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, kernel::kTableBinding, tables);
}

}  // namespace

KernelProgram::KernelProgram(const Api& gl, const kernel::SceneTables<float>& tables,
                             const kernel::ShaderVariant& variant)
    : gl_(gl), trace_(variant.trace), shared_(variant.trace && kernel::shared_trace(tables)) {
  program_ = link_program(gl, kernel::kFullScreenVertexShader,
                          kernel::scene_fragment_shader(tables, variant));
  polygon_ = gl.GetUniformLocation(program_, "u_polygon");
  from_ = gl.GetUniformLocation(program_, "u_from");
  forward_ = gl.GetUniformLocation(program_, "u_forward");
  right_ = gl.GetUniformLocation(program_, "u_right");
  up_ = gl.GetUniformLocation(program_, "u_up");
  scale_ = gl.GetUniformLocation(program_, "u_scale");
  size_ = gl.GetUniformLocation(program_, "u_size");
  rows_ = gl.GetUniformLocation(program_, "u_rows");
  gl.GenVertexArrays(1, &vertex_array_);  // the core profile draws only with one bound
  if (trace_) gl.GenBuffers(1, &events_);
  if (shared_)
    gl.GenBuffers(1, &tables_);  // filled by each trace
  else
    tables_ = make_table_buffer(gl, tables);
}

KernelProgram::~KernelProgram() {
  gl_.DeleteProgram(program_);
  gl_.DeleteVertexArrays(1, &vertex_array_);
  if (events_ != 0) gl_.DeleteBuffers(1, &events_);
  if (tables_ != 0) gl_.DeleteBuffers(1, &tables_);
}

void KernelProgram::draw(const CameraBasis<float>& c, int polygon, glm::vec3 from, int width,
                         int height, Rows rows) const {
  gl_.UseProgram(program_);
  bind_tables(gl_, tables_);
  gl_.Uniform1i(polygon_, polygon);
  gl_.Uniform3f(from_, from.x, from.y, from.z);
  gl_.Uniform3f(forward_, c.forward.x, c.forward.y, c.forward.z);
  gl_.Uniform3f(right_, c.right.x, c.right.y, c.right.z);
  gl_.Uniform3f(up_, c.up.x, c.up.y, c.up.z);
  gl_.Uniform2f(scale_, c.aspect * c.tan_half_fov, c.tan_half_fov);
  gl_.Uniform2f(size_, static_cast<float>(width), static_cast<float>(height));
  if (rows == Rows::top_up)
    gl_.Uniform2f(rows_, static_cast<float>(height), -1.0f);
  else
    gl_.Uniform2f(rows_, 0.0f, 1.0f);
  gl_.BindVertexArray(vertex_array_);
  gl_.DrawArrays(GL_TRIANGLES, 0, 3);
}

Trace KernelProgram::trace(const Ray& ray, int max_events,
                           const kernel::SceneTables<float>& tables) const {
  if (!trace_) throw std::logic_error("KernelProgram::trace needs a trace program");
  max_events = std::max(max_events, 0);
  if (shared_) {
    const std::string bytes = kernel::table_buffer(tables, true);
    gl_.BindBuffer(GL_SHADER_STORAGE_BUFFER, tables_);
    gl_.BufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(bytes.size()), bytes.data(),
                   GL_STREAM_DRAW);
  }
  const size_t bytes = shader_trace_bytes(max_events);
  const ShaderEventHeader header{0, max_events, 0, 0};
  // (Binding the tables binds their buffer to the generic binding point too: before the events'.)
  bind_tables(gl_, tables_);
  gl_.BindBuffer(GL_SHADER_STORAGE_BUFFER, events_);
  gl_.BufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(bytes), nullptr,
                 GL_DYNAMIC_READ);
  gl_.BufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof header, &header);
  gl_.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, events_);
  gl_.UseProgram(program_);
  const glm::vec3 from(ray.from), dir(ray.dir);
  gl_.Uniform1i(polygon_, ray.polygon);
  gl_.Uniform3f(from_, from.x, from.y, from.z);
  gl_.Uniform3f(forward_, dir.x, dir.y, dir.z);
  gl_.Viewport(0, 0, 1, 1);
  gl_.BindVertexArray(vertex_array_);
  gl_.DrawArrays(GL_TRIANGLES, 0, 3);
  gl_.MemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<unsigned char> data(bytes);
  gl_.GetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(bytes), data.data());
  return shader_trace(data.data(), max_events);
}

ComputeProgram::ComputeProgram(const Api& gl, const kernel::SceneTables<float>& tables,
                               const kernel::ShaderVariant& variant)
    : gl_(gl) {
  program_ =
      link_compute(gl, kernel::scene_compute_shader(tables, variant, kernel::ComputeApi::opengl));
  gl.GenBuffers(1, &constants_);
  gl.BindBuffer(GL_UNIFORM_BUFFER, constants_);
  gl.BufferData(GL_UNIFORM_BUFFER, sizeof(kernel::ComputeConstants), nullptr, GL_DYNAMIC_DRAW);
  tables_ = make_table_buffer(gl, tables);
}

ComputeProgram::~ComputeProgram() {
  gl_.DeleteProgram(program_);
  gl_.DeleteBuffers(1, &constants_);
  if (tables_ != 0) gl_.DeleteBuffers(1, &tables_);
}

void ComputeProgram::dispatch(const kernel::ComputeConstants& constants, GLuint groups_x,
                              GLuint tile_rows) const {
  gl_.UseProgram(program_);
  gl_.BindBuffer(GL_UNIFORM_BUFFER, constants_);
  gl_.BufferSubData(GL_UNIFORM_BUFFER, 0, sizeof constants, &constants);
  gl_.BindBufferBase(GL_UNIFORM_BUFFER, 0, constants_);
  bind_tables(gl_, tables_);
  gl_.DispatchCompute(groups_x, tile_rows, 1);
}

void draw_frame(const Api& gl, const KernelProgram& program, const CameraBasis<float>& camera,
                int polygon, glm::vec3 from, const Progress& progress, Frame& frame,
                std::vector<float>* aovs) {
  const int width = frame.width, height = frame.height;
  gl.Viewport(0, 0, width, height);
  gl.Enable(GL_SCISSOR_TEST);
  // The image's row j is drawn at OpenGL's row j, so that the read-back is in the frame's order.
  BandPacer bands(program.seconds_per_pixel(), width, height);
  for (int row = 0, rows = 0; row < height; row += rows) {
    rows = bands.rows(row);
    const auto start = std::chrono::steady_clock::now();
    gl.Scissor(0, row, width, rows);
    program.draw(camera, polygon, from, width, height, KernelProgram::Rows::top_first);
    gl.Finish();
    bands.done(rows,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (progress) progress(static_cast<double>(row + rows) / height);
  }
  program.set_seconds_per_pixel(bands.pace());
  gl.Disable(GL_SCISSOR_TEST);

  // The colour straight into the frame; the AOVs through one read, spread into their channels.
  gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
  gl.ReadPixels(0, 0, width, height, GL_RGB, GL_FLOAT, frame.rgb.data());
  if (!aovs) return;
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  aovs->resize(4 * pixels);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT1);
  gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, aovs->data());
  const float* aov = aovs->data();
  for (size_t px = 0; px < pixels; ++px, aov += 4) {
    frame.steps[px] = aov[0];
    frame.crossings[px] = aov[1];
    frame.hit[px] = aov[2];
    frame.t[px] = aov[3];
  }
}

}  // namespace flatmarch::gl
