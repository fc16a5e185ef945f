// The kernel as OpenGL programs, for whichever context is current: a fragment program (the
// software shape; the viewer's window draws with it too) and a compute program (the gpu shape), the
// targets and buffers their frames go to, and the device's clock that times them.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "backends/backend.hpp"
#include "backends/opengl/gl_api.hpp"
#include "kernels/camera.hpp"
#include "kernels/compile.hpp"
#include "kernels/scene_shader.hpp"
#include "kernels/shader_log.hpp"

namespace flatmarch::gl {

// Compiles and links; throws kernel::ShaderError.
GLuint link_program(const Api& gl, const std::string& vertex, const std::string& fragment);
GLuint link_compute(const Api& gl, const std::string& compute);

// A framebuffer with the colour targets of one size that a fragment program of `readback`
// draws (kernels/scene_shader.hpp), bound for drawing while it lives: floats, attachment 0 the
// linear colour (RGBA32F) and 1 the AOVs (RGBA32F); all, 0 the colour (RGBA32F) and 1 the
// integer AOVs (RGBA32UI); colour, 0 alone, the packed sRGB colour (R32UI).
class RenderTargets {
 public:
  RenderTargets(const Api& gl, int width, int height,
                kernel::Readback readback = kernel::Readback::floats);
  ~RenderTargets();
  RenderTargets(const RenderTargets&) = delete;
  RenderTargets& operator=(const RenderTargets&) = delete;
  GLuint framebuffer() const { return framebuffer_; }
  // Binds the framebuffer for drawing to its targets again (after another was bound).
  void bind() const;
  GLuint colour() const { return textures_[0]; }
  GLuint aovs() const { return textures_[1]; }  // 0 where there are none
  int width() const { return width_; }
  int height() const { return height_; }
  kernel::Readback readback() const { return readback_; }

 private:
  const Api& gl_;
  GLuint framebuffer_ = 0;
  GLuint textures_[2] = {0, 0};
  int width_, height_;
  kernel::Readback readback_;
};

// A buffer object whose storage grows to what is asked of it.
class Buffer {
 public:
  explicit Buffer(const Api& gl);
  ~Buffer();
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  // Binds it to `target` with room for at least `bytes` (new storage of `usage` where it had
  // less; its contents are then undefined).
  void bind(GLenum target, size_t bytes, GLenum usage);
  GLuint id() const { return id_; }

 private:
  const Api& gl_;
  GLuint id_ = 0;
  size_t size_ = 0;
};

// Spans of commands timed on the device's clock (ARB_timer_query's GL_TIME_ELAPSED queries):
// what the device took for them, without the host's submission and waits. Two spans, the march
// and the read-back, each summed over its begin()/end() pairs until read().
class DeviceClock {
 public:
  enum Span { march = 0, readback = 1 };
  explicit DeviceClock(const Api& gl);
  ~DeviceClock();
  DeviceClock(const DeviceClock&) = delete;
  DeviceClock& operator=(const DeviceClock&) = delete;
  // Whether the device has the clock; why not where it has not.
  bool available() const { return why_.empty(); }
  const std::string& why() const { return why_; }
  void begin(Span s);
  void end(Span s);
  // The spans' seconds since the last read(), waiting for what the device has still to report.
  DeviceTiming read();

 private:
  void settle(Span s);  // adds a finished span's time to its sum
  const Api& gl_;
  std::string why_;
  GLuint queries_[2] = {0, 0};
  bool pending_[2] = {false, false};
  double seconds_[2] = {0.0, 0.0};
};

// The compiled fragment kernel of one scene, one set of march parameters (both baked in, or the
// scene's tables in a buffer of the program's: kernels/scene_shader.hpp's tables_in_buffer) and
// one variant.
class KernelProgram {
 public:
  KernelProgram(const Api& gl, const kernel::SceneTables<float>& tables,
                const kernel::ShaderVariant& variant);
  ~KernelProgram();
  KernelProgram(const KernelProgram&) = delete;
  KernelProgram& operator=(const KernelProgram&) = delete;

  // Where a drawn image's rows go: the image's top row at the framebuffer's top, as a window
  // shows it, or at its row 0, the first in memory, as glReadPixels returns it.
  enum class Rows { top_up, top_first };

  // Draws the camera's view of a width x height image into the bound framebuffer's draw
  // buffers (RenderTargets of the variant's readback), over its viewport: every pixel within the
  // scissor box.
  void draw(const CameraBasis<float>& camera, int polygon, glm::vec3 from, int width, int height,
            Rows rows = Rows::top_up) const;

  // The pace of the last frame drawn, seconds per pixel (BandPacer::pace; 0 before the first),
  // by which the next frame's bands are sized.
  double seconds_per_pixel() const { return seconds_per_pixel_; }
  void set_seconds_per_pixel(double s) const { seconds_per_pixel_ = s; }

  // Marches one ray of `tables`' scene in a 1 x 1 viewport of the bound framebuffer (a trace
  // program only; one shared by scenes loads their tables into its buffer first).
  Trace trace(const Ray& ray, int max_events, const kernel::SceneTables<float>& tables) const;

 private:
  const Api& gl_;
  bool trace_, shared_ = false;  // a trace program shared by scenes (kernel::shared_trace)
  GLuint program_ = 0, vertex_array_ = 0, events_ = 0;
  GLuint tables_ = 0;  // the scene's table buffer, where its shader reads one; a shared trace's
  GLint polygon_ = -1, from_ = -1, forward_ = -1, right_ = -1, up_ = -1, scale_ = -1, size_ = -1,
        rows_ = -1;
  mutable double seconds_per_pixel_ = 0.0;
};

// The compiled compute kernel (kernels/scene_shader.hpp's scene_compute_shader for OpenGL) of one
// scene, its march parameters and a frame variant: one invocation a pixel, into the buffer at
// shader storage binding 5.
class ComputeProgram {
 public:
  ComputeProgram(const Api& gl, const kernel::SceneTables<float>& tables,
                 const kernel::ShaderVariant& variant);
  ~ComputeProgram();
  ComputeProgram(const ComputeProgram&) = delete;
  ComputeProgram& operator=(const ComputeProgram&) = delete;

  // Dispatches one band: `tile_rows` rows of `groups_x` workgroups from row constants.frame.z.
  void dispatch(const kernel::ComputeConstants& constants, GLuint groups_x, GLuint tile_rows) const;

  double seconds_per_pixel() const { return seconds_per_pixel_; }
  void set_seconds_per_pixel(double s) const { seconds_per_pixel_ = s; }

 private:
  const Api& gl_;
  GLuint program_ = 0, constants_ = 0;
  GLuint tables_ = 0;  // as KernelProgram's
  mutable double seconds_per_pixel_ = 0.0;
};

// A whole width x height frame of the floats `program` drawn into the bound floats render
// targets and read back, as the viewer's screenshots take it: in bands of rows (BandPacer, at the
// program's last pace; `progress` after each), the image's rows top first, so that the read-back
// is in the frame's order. The colour goes into frame.rgb; the AOVs too where `aovs` is given
// (read through it, the caller's buffer reused).
void draw_frame(const Api& gl, const KernelProgram& program, const CameraBasis<float>& camera,
                int polygon, glm::vec3 from, const Progress& progress, Frame& frame,
                std::vector<float>* aovs);

}  // namespace flatmarch::gl
