// The OpenGL backend: the kernel as a fragment shader (the software shape) or a compute shader
// (the gpu shape; kernels/scene_shader.hpp), specialised per scene with its tables baked in, run
// headless on the machine's GPU through EGL, or on the CPU (Mesa's llvmpipe, through EGL or
// OSMesa) where it has none (backends/opengl/context.hpp). A frame is read back through a
// buffer: the 8-bit colour alone for a frame of the colour (render_colour), the float colour and
// the integer AOVs for a whole frame; every frame is timed on the device (timer queries).
// Float32 only.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "backends/backend.hpp"

namespace flatmarch {

class OpenGlBackend final : public Backend {
 public:
  // options.device picks the device (an index or a part of its name, as gl::list_devices()).
  explicit OpenGlBackend(const BackendOptions& options = {});
  ~OpenGlBackend() override;

  static constexpr const char* kName = "opengl";  // in the registry (the viewer draws with it)
  std::string name() const override { return kName; }
  std::string description() const override;
  Availability availability() const override;
  std::vector<Method> methods() const override {
    return {kKernelMethods.begin(), kKernelMethods.end()};
  }
  std::vector<Precision> precisions() const override { return {Precision::f32}; }
  std::optional<DeviceInfo> device() const override;
  bool compiles_per_scene() const override { return true; }
  Frame render(const Scene& scene, const Camera& camera, int width, int height,
               const MarchParams& params, const Progress& progress) const override;
  bool colour_frames_whole() const override { return false; }
  bool colour_program_apart() const override;
  Frame render_colour(const Scene& scene, const Camera& camera, int width, int height,
                      const MarchParams& params, const Progress& progress) const override;
  std::optional<DeviceTiming> last_device_timing() const override;
  Trace trace(const Scene& scene, const Ray& ray, const MarchParams& params,
              int max_events) const override;

  // Compiles a fragment shader for this backend's program (with the full-screen vertex shader),
  // or a compute shader; throws kernel::ShaderError with the driver's log and the source lines it
  // names.
  void compile(const std::string& source, bool compute = false) const;

  // The OpenGL renderer and version of its context ("" when unavailable).
  std::string renderer() const;
  // Its device's index in gl::list_devices(), or -1 when unavailable.
  int device_index() const;

 private:
  struct Context;            // the context, its GL functions and compiled programs
  Context* context() const;  // null when unavailable (unavailable_ says why)
  void make_context() const;
  Frame draw(const Scene& scene, const Camera& camera, int width, int height,
             const MarchParams& params, const Progress& progress, bool colour_only) const;

  BackendOptions options_;
  mutable std::once_flag made_;
  mutable std::unique_ptr<Context> context_;
  mutable std::string unavailable_;
};

}  // namespace flatmarch
