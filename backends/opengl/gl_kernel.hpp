// The kernel as an OpenGL program, for whichever context is current: the OpenGL backend's
// (OSMesa, headless) and the viewer's (a GLFW window) draw frames with it alike.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "backends/backend.hpp"
#include "backends/opengl/gl_api.hpp"
#include "kernels/camera.hpp"
#include "kernels/compile.hpp"
#include "kernels/shader_log.hpp"

namespace flatmarch::gl {

// Compiles and links; throws kernel::ShaderError.
GLuint link_program(const Api& gl, const std::string& vertex, const std::string& fragment);

// A framebuffer with two float colour targets of one size, bound for drawing while it lives:
// attachment 0 the linear colour (rgb, 1), 1 the AOVs (steps, crossings, hit, t), as
// KernelProgram draws them.
class RenderTargets {
 public:
  RenderTargets(const Api& gl, int width, int height);
  ~RenderTargets();
  RenderTargets(const RenderTargets&) = delete;
  RenderTargets& operator=(const RenderTargets&) = delete;
  GLuint framebuffer() const { return framebuffer_; }
  // Binds the framebuffer for drawing to both targets again (after another was bound).
  void bind() const;
  GLuint colour() const { return textures_[0]; }
  GLuint aovs() const { return textures_[1]; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  const Api& gl_;
  GLuint framebuffer_ = 0;
  GLuint textures_[2] = {0, 0};
  int width_, height_;
};

// The compiled kernel of one scene and one set of march parameters (both baked in).
class KernelProgram {
 public:
  // `trace`: the variant that marches one probe ray and records its events. `from_band`: one for
  // cameras within the band only (kernel::scene_fragment_shader).
  KernelProgram(const Api& gl, const kernel::SceneTables<float>& tables, bool trace,
                bool from_band = false);
  ~KernelProgram();
  KernelProgram(const KernelProgram&) = delete;
  KernelProgram& operator=(const KernelProgram&) = delete;

  // Where a drawn image's rows go: the image's top row at the framebuffer's top, as a window
  // shows it, or at its row 0, the first in memory, as glReadPixels returns it.
  enum class Rows { top_up, top_first };

  // Draws the camera's view of a width x height image into the bound framebuffer's draw
  // buffers 0 (colour) and 1 (AOVs), over its viewport: every pixel within the scissor box.
  void draw(const CameraBasis<float>& camera, int polygon, glm::vec3 from, int width, int height,
            Rows rows = Rows::top_up) const;

  // The pace of the last frame drawn, seconds per pixel (BandPacer::pace; 0 before the first),
  // by which the next frame's bands are sized.
  double seconds_per_pixel() const { return seconds_per_pixel_; }
  void set_seconds_per_pixel(double s) const { seconds_per_pixel_ = s; }

  // Marches one ray in a 1 x 1 viewport of the bound framebuffer (a trace program only).
  Trace trace(const Ray& ray, int max_events) const;

 private:
  const Api& gl_;
  bool trace_;
  GLuint program_ = 0, vertex_array_ = 0, events_ = 0;
  GLint polygon_ = -1, from_ = -1, forward_ = -1, right_ = -1, up_ = -1, scale_ = -1, size_ = -1,
        rows_ = -1;
  mutable double seconds_per_pixel_ = 0.0;
};

// A whole width x height frame of `program` drawn into the bound render targets and read back:
// in bands of rows (BandPacer, at the program's last pace; `progress` after each), the image's
// rows top first, so that the read-back is in the frame's order. The colour goes into
// frame.rgb; the AOVs too where `aovs` is given (read through it, the caller's buffer reused).
void draw_frame(const Api& gl, const KernelProgram& program, const CameraBasis<float>& camera,
                int polygon, glm::vec3 from, const Progress& progress, Frame& frame,
                std::vector<float>* aovs);

}  // namespace flatmarch::gl
