#include "bench/peer_app.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <nlohmann/json.hpp>

#include "backends/opengl/gl_kernel.hpp"
#include "interop/peer_import.hpp"
#include "scene/load.hpp"

namespace flatmarch::bench {

namespace {

// The app's shaders are GLSL 1.20 without a version line (peer-shaders.md); generic attribute 0
// is gl_Vertex in the compatibility profile.
const char* const kVertexShader = "#version 120\nvoid main() { gl_Position = gl_Vertex; }\n";

}  // namespace

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

Scene peer_scene(const PeerView& view) {
  const std::string file = std::string(view.id) + ".json";
  const PeerImport imported = import_peer_file(std::filesystem::path(FLATMARCH_SOURCE_DIR) /
                                               "tests" / "data" / "peer-geometries" / file);
  return scene_from_json(imported.scene, file);
}

AppView app_view(glm::vec3 start) {
  return {start + glm::vec3(0.5f, 0.0f, 0.5f), glm::normalize(glm::vec3(1.0f, 0.0f, 0.3f)),
          glm::vec3(0.0f, 1.0f, 0.0f)};
}

std::map<std::string, glm::vec3> app_starts(const std::filesystem::path& folder) {
  std::map<std::string, glm::vec3> starts;
  const nlohmann::json meta = nlohmann::json::parse(read_text(folder / "meta.json"));
  for (const auto& [id, m] : meta.items()) {
    const auto p = m.value("initialPosition", std::vector<float>{0.0f, 1.0f, 0.0f});
    starts[id] = glm::vec3(p.at(0), p.at(1), p.at(2));
  }
  return starts;
}

std::string app_shader(const std::filesystem::path& folder, const std::string& id) {
  return read_text(folder / (id + ".frag"));
}

AppTriangle::AppTriangle(const gl::Api& gl) : gl_(gl) {
  const float triangle[] = {-1.0f, -1.0f, 3.0f, -1.0f, -1.0f, 3.0f};
  gl.GenVertexArrays(1, &vertex_array_);
  gl.BindVertexArray(vertex_array_);
  gl.GenBuffers(1, &vertices_);
  gl.BindBuffer(GL_ARRAY_BUFFER, vertices_);
  gl.BufferData(GL_ARRAY_BUFFER, sizeof triangle, triangle, GL_STATIC_DRAW);
  gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  gl.EnableVertexAttribArray(0);
}

AppTriangle::~AppTriangle() {
  gl_.DeleteBuffers(1, &vertices_);
  gl_.DeleteVertexArrays(1, &vertex_array_);
}

void AppTriangle::bind() const {
  gl_.BindVertexArray(vertex_array_);
}

AppProgram::AppProgram(const gl::Api& gl, const std::string& fragment)
    : gl_(gl),
      program_(gl::link_program(gl, kVertexShader, "#version 120\n" + fragment)),
      resolution_(gl.GetUniformLocation(program_, "iResolution")),
      time_(gl.GetUniformLocation(program_, "iTime")),
      position_(gl.GetUniformLocation(program_, "rayMarchCamPos")),
      front_(gl.GetUniformLocation(program_, "rayMarchCamFront")),
      up_(gl.GetUniformLocation(program_, "rayMarchCamUp")) {}

AppProgram::~AppProgram() {
  gl_.DeleteProgram(program_);
}

void AppProgram::draw(const AppTriangle& triangle, const AppView& view, int width,
                      int height) const {
  gl_.UseProgram(program_);
  gl_.Uniform2f(resolution_, static_cast<float>(width), static_cast<float>(height));
  gl_.Uniform1f(time_, 0.0f);
  gl_.Uniform3f(position_, view.from.x, view.from.y, view.from.z);
  gl_.Uniform3f(front_, view.front.x, view.front.y, view.front.z);
  gl_.Uniform3f(up_, view.up.x, view.up.y, view.up.z);
  gl_.Viewport(0, 0, width, height);
  triangle.bind();
  gl_.DrawArrays(GL_TRIANGLES, 0, 3);
}

PeerApp::PeerApp(const std::filesystem::path& folder, const std::string& device)
    : folder_(folder), start_(app_starts(folder)) {
  context_ = gl::make_context(device, gl::Profile::compatibility);
  const gl::Context::Current current(*context_);
  triangle_ = std::make_unique<AppTriangle>(context_->api());
}

PeerApp::~PeerApp() {
  const gl::Context::Current current(*context_);
  const gl::Api& gl = context_->api();
  programs_.clear();
  triangle_.reset();
  if (framebuffer_ != 0) gl.DeleteFramebuffers(1, &framebuffer_);
  if (texture_ != 0) gl.DeleteTextures(1, &texture_);
}

std::string PeerApp::renderer() const {
  return context_->device().renderer + ", " + context_->device().version;
}

AppProgram& PeerApp::program(const std::string& id) {
  auto& p = programs_[id];
  if (!p) p = std::make_unique<AppProgram>(context_->api(), app_shader(folder_, id));
  return *p;
}

void PeerApp::frame(const std::string& id, int width, int height) {
  if (!start_.count(id)) throw std::runtime_error(id + " is not in meta.json");
  const gl::Context::Current current(*context_);
  const gl::Api& gl = context_->api();
  if (width != width_ || height != height_) {
    if (framebuffer_ == 0) {
      gl.GenFramebuffers(1, &framebuffer_);
      gl.GenTextures(1, &texture_);
    }
    gl.BindTexture(GL_TEXTURE_2D, texture_);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture_, 0);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("the app's framebuffer is incomplete");
    width_ = width;
    height_ = height;
  }
  gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
  program(id).draw(*triangle_, app_view(start_[id]), width, height);
  std::vector<unsigned char> pixels(4 * static_cast<size_t>(width) * static_cast<size_t>(height));
  gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
  if (const std::string e = gl::errors(gl); !e.empty())
    throw std::runtime_error("the app's frame failed: " + e);
}

}  // namespace flatmarch::bench
