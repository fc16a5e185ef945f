#include "backends/opengl/gl_kernel.hpp"

#include <algorithm>
#include <cstring>
#include <regex>
#include <set>
#include <sstream>

#include "backends/kernel_trace.hpp"
#include "kernels/scene_shader.hpp"

namespace flatmarch::gl {

std::string annotate_log(const std::string& source, const std::string& log, int context) {
  std::vector<std::string> lines;
  std::istringstream in(source);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  // The lines errors name; the lines warnings name only when there is no error.
  std::set<int> named, warned;
  static const std::regex kLine(R"((?:^|\n)\s*\d+:(\d+)\(\d+\):\s*(\w+))");
  for (auto it = std::sregex_iterator(log.begin(), log.end(), kLine); it != std::sregex_iterator();
       ++it)
    ((*it)[2] == "error" ? named : warned).insert(std::stoi((*it)[1]));
  if (named.empty()) named = warned;
  std::string out = log;
  int shown_to = 0;  // the last line shown, so that nearby errors share their context
  for (const int n : named) {
    const int from = std::max({1, n - context, shown_to + 1});
    const int to = std::min(static_cast<int>(lines.size()), n + context);
    if (from > to) continue;
    out += "\n  ...\n";
    for (int k = from; k <= to; ++k) {
      char number[16];
      std::snprintf(number, sizeof number, "%5d", k);
      out += std::string(k == n ? ">" : " ") + number + "  " + lines[static_cast<size_t>(k - 1)] +
             "\n";
    }
    shown_to = to;
  }
  return out;
}

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
  throw ShaderError(std::string(stage == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                    " shader does not compile:\n" + annotate_log(source, log));
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
  const GLuint program = gl.CreateProgram();
  gl.AttachShader(program, vs);
  gl.AttachShader(program, fs);
  gl.LinkProgram(program);
  gl.DeleteShader(vs);  // freed with the program
  gl.DeleteShader(fs);
  GLint ok = GL_FALSE, length = 0;
  gl.GetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok == GL_TRUE) return program;
  gl.GetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
  gl.GetProgramInfoLog(program, length, nullptr, log.data());
  gl.DeleteProgram(program);
  throw ShaderError("the shader program does not link:\n" + log);
}

RenderTargets::RenderTargets(const Api& gl, int width, int height)
    : gl_(gl), width_(width), height_(height) {
  gl.GenFramebuffers(1, &framebuffer_);
  gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
  gl.GenTextures(2, textures_);
  for (int k = 0; k < 2; ++k) {
    gl.BindTexture(GL_TEXTURE_2D, textures_[k]);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(k),
                            GL_TEXTURE_2D, textures_[k], 0);
  }
  const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  gl.DrawBuffers(2, buffers);
  if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.DeleteTextures(2, textures_);
    gl.DeleteFramebuffers(1, &framebuffer_);
    throw std::runtime_error("OpenGL cannot draw to float targets of " + std::to_string(width) +
                             "x" + std::to_string(height));
  }
}

RenderTargets::~RenderTargets() {
  gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
  gl_.DeleteTextures(2, textures_);
  gl_.DeleteFramebuffers(1, &framebuffer_);
}

KernelProgram::KernelProgram(const Api& gl, const kernel::SceneTables<float>& tables, bool trace)
    : gl_(gl), trace_(trace) {
  program_ = link_program(gl, kernel::kFullScreenVertexShader,
                          kernel::scene_fragment_shader(tables, trace));
  polygon_ = gl.GetUniformLocation(program_, "u_polygon");
  from_ = gl.GetUniformLocation(program_, "u_from");
  forward_ = gl.GetUniformLocation(program_, "u_forward");
  right_ = gl.GetUniformLocation(program_, "u_right");
  up_ = gl.GetUniformLocation(program_, "u_up");
  scale_ = gl.GetUniformLocation(program_, "u_scale");
  size_ = gl.GetUniformLocation(program_, "u_size");
  gl.GenVertexArrays(1, &vertex_array_);  // the core profile draws only with one bound
  if (trace) gl.GenBuffers(1, &events_);
}

KernelProgram::~KernelProgram() {
  gl_.DeleteProgram(program_);
  gl_.DeleteVertexArrays(1, &vertex_array_);
  if (events_ != 0) gl_.DeleteBuffers(1, &events_);
}

void KernelProgram::draw(const CameraBasis<float>& c, int polygon, glm::vec3 from, int width,
                         int height) const {
  gl_.UseProgram(program_);
  gl_.Uniform1i(polygon_, polygon);
  gl_.Uniform3f(from_, from.x, from.y, from.z);
  gl_.Uniform3f(forward_, c.forward.x, c.forward.y, c.forward.z);
  gl_.Uniform3f(right_, c.right.x, c.right.y, c.right.z);
  gl_.Uniform3f(up_, c.up.x, c.up.y, c.up.z);
  gl_.Uniform2f(scale_, c.aspect * c.tan_half_fov, c.tan_half_fov);
  gl_.Uniform2f(size_, static_cast<float>(width), static_cast<float>(height));
  gl_.BindVertexArray(vertex_array_);
  gl_.DrawArrays(GL_TRIANGLES, 0, 3);
}

namespace {
// The event buffer's layout (kernels/shader_prelude.glsl, std430).
struct EventHeader {
  GLint count, max_events, steps, pad;
};
struct EventRecord {
  GLint kind[4];
  GLint more[4];
  GLfloat at[4];
};
}  // namespace

Trace KernelProgram::trace(const Ray& ray, int max_events) const {
  if (!trace_) throw std::logic_error("KernelProgram::trace needs a trace program");
  max_events = std::max(max_events, 0);
  const size_t bytes = sizeof(EventHeader) + sizeof(EventRecord) * static_cast<size_t>(max_events);
  const EventHeader header{0, max_events, 0, 0};
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
  EventHeader got;
  std::memcpy(&got, data.data(), sizeof got);
  std::vector<kernel::KernelEvent> events;
  for (int k = 0; k < std::min(got.count, max_events); ++k) {
    EventRecord e;
    std::memcpy(&e,
                data.data() + sizeof(EventHeader) + sizeof(EventRecord) * static_cast<size_t>(k),
                sizeof e);
    events.push_back({e.kind[0], e.kind[1], e.kind[2], e.kind[3], e.more[0], e.more[1],
                      static_cast<double>(e.at[3]), glm::dvec3(e.at[0], e.at[1], e.at[2])});
  }
  return kernel_trace(events, got.steps);
}

}  // namespace flatmarch::gl
