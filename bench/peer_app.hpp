// The original web app's shaders (Lander & Taha's RayMarchingFlatSurfaces), regenerated locally
// as ../shared/peer-shaders.md says (they are not ours to ship), drawn on the same OpenGL device
// as the opengl backend, so that both are timed in one run. peer_adapter draws them with the same
// pieces (AppTriangle, AppProgram) to judge the app under the external renderer protocol.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include <glm/glm.hpp>

#include "backends/opengl/context.hpp"
#include "scene/scene.hpp"

namespace flatmarch::bench {

// The app's benchmark views: its geometry file (in tests/data/peer-geometries, and its shader's
// name in the app) and ours.
struct PeerView {
  const char* id;
  const char* name;
};
inline constexpr PeerView kPeerViews[] = {{"L_shape", "l_shape"},
                                          {"DoublePentagonTranslation", "double_pentagon"},
                                          {"torus", "torus"},
                                          {"L_shapePrism", "l_shape_prism"},
                                          {"equilateralTriangle", "equilateral_triangle"},
                                          {"irrationalTriangle", "triangle_1rad"},
                                          {"cube", "cube"}};
// A view's geometry imported as our scene (interop/peer_import.hpp).
Scene peer_scene(const PeerView& view);

// The same view as the app's shader takes it: its uniforms rayMarchCamPos, rayMarchCamFront and
// rayMarchCamUp, from the app's start point.
struct AppView {
  glm::vec3 from, front, up;
};
AppView app_view(glm::vec3 start);
// The app's start points (initialPosition, default (0, 1, 0)) by id, from FOLDER/meta.json.
std::map<std::string, glm::vec3> app_starts(const std::filesystem::path& folder);
// A file's text; throws std::runtime_error "cannot read FILE".
std::string read_text(const std::filesystem::path& file);
// FOLDER/ID.frag, the app's shader of a geometry, as it comes (GLSL without a version line).
std::string app_shader(const std::filesystem::path& folder, const std::string& id);

// The full-screen triangle the app's shaders are drawn over, made on the current compatibility
// context (generic attribute 0 is gl_Vertex there).
class AppTriangle {
 public:
  explicit AppTriangle(const gl::Api& gl);
  ~AppTriangle();
  AppTriangle(const AppTriangle&) = delete;
  AppTriangle& operator=(const AppTriangle&) = delete;
  void bind() const;

 private:
  const gl::Api& gl_;
  GLuint vertices_ = 0, vertex_array_ = 0;
};

// One of the app's fragment shaders as it generates them (GLSL 1.20 without a version line),
// linked on the current compatibility context. Throws std::runtime_error with the compiler's log.
class AppProgram {
 public:
  AppProgram(const gl::Api& gl, const std::string& fragment);
  ~AppProgram();
  AppProgram(const AppProgram&) = delete;
  AppProgram& operator=(const AppProgram&) = delete;

  // Draws a width x height frame of `view` (iTime 0) over `triangle` into the bound framebuffer.
  void draw(const AppTriangle& triangle, const AppView& view, int width, int height) const;

 private:
  const gl::Api& gl_;
  GLuint program_;
  GLint resolution_, time_, position_, front_, up_;
};

class PeerApp {
 public:
  // Reads FOLDER/meta.json and makes a compatibility-profile context on `device` (as --device).
  // Throws std::runtime_error saying what is missing.
  PeerApp(const std::filesystem::path& folder, const std::string& device);
  ~PeerApp();
  PeerApp(const PeerApp&) = delete;
  PeerApp& operator=(const PeerApp&) = delete;

  // Compiles FOLDER/ID.frag (once) and draws one width x height frame of its benchmark view:
  // from the geometry's start point + (0.5, 0, 0.5), looking along normalize(1, 0, 0.3), up
  // +y (its coordinates), then waits for it and reads the 8-bit colour back, as a page would
  // present it.
  void frame(const std::string& id, int width, int height);

  std::string renderer() const;

 private:
  AppProgram& program(const std::string& id);

  std::filesystem::path folder_;
  std::map<std::string, glm::vec3> start_;  // initialPosition per id
  std::unique_ptr<gl::Context> context_;
  std::unique_ptr<AppTriangle> triangle_;
  std::map<std::string, std::unique_ptr<AppProgram>> programs_;
  unsigned framebuffer_ = 0, texture_ = 0;
  int width_ = 0, height_ = 0;
};

}  // namespace flatmarch::bench
