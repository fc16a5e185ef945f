// The original web app's shaders (Lander & Taha's RayMarchingFlatSurfaces), regenerated locally
// as ../shared/peer-shaders.md says (they are not ours to ship), drawn on the same OpenGL device
// as the opengl backend, so that both are timed in one run.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include <glm/glm.hpp>

#include "backends/opengl/context.hpp"

namespace flatmarch::bench {

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
  struct Program;
  Program& program(const std::string& id);

  std::filesystem::path folder_;
  std::map<std::string, glm::vec3> start_;  // initialPosition per id
  std::unique_ptr<gl::Context> context_;
  std::map<std::string, std::unique_ptr<Program>> programs_;
  unsigned framebuffer_ = 0, texture_ = 0, vertices_ = 0, vertex_array_ = 0;
  int width_ = 0, height_ = 0;
};

}  // namespace flatmarch::bench
