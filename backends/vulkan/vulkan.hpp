// The Vulkan backend: the kernel as a compute shader (kernels/scene_shader.hpp), specialised per
// scene with its tables baked in, compiled to SPIR-V with glslang at run time, on any Vulkan
// device: a GPU where there is one, Mesa's lavapipe (on the CPU) where there is none. Colour and
// the AOVs are written to a storage buffer and read back: the 8-bit colour alone for a frame of
// the colour (render_colour), the float colour and the integer AOVs for a whole frame. Every
// frame is also timed on the device (timestamp queries). Float32 only.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "backends/backend.hpp"

namespace flatmarch {

namespace vulkan {

// A device the Vulkan loader lists.
struct Device {
  int index = 0;  // in the loader's order: what --device takes
  std::string name;
  std::string type;  // "discrete GPU", "integrated GPU", "virtual GPU", "CPU", "other"
  std::string api;   // the Vulkan version it supports, e.g. "1.3.230"
  std::string driver;
  bool usable = false;  // Vulkan 1.1 or later with a compute queue
};

// The validation layer's messages so far, from every Vulkan backend in this process (the
// creation and destruction of their instances included).
std::vector<std::string> validation_messages();

}  // namespace vulkan

class VulkanBackend final : public Backend {
 public:
  explicit VulkanBackend(const BackendOptions& options = {});
  ~VulkanBackend() override;

  static constexpr const char* kName = "vulkan";  // in the registry
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
  Frame render_colour(const Scene& scene, const Camera& camera, int width, int height,
                      const MarchParams& params, const Progress& progress) const override;
  std::optional<DeviceTiming> last_device_timing() const override;
  Trace trace(const Scene& scene, const Ray& ray, const MarchParams& params,
              int max_events) const override;

  // The devices the loader lists (none when it has no driver: availability() says why).
  std::vector<vulkan::Device> devices() const;
  // The device it runs on, or -1.
  int device_index() const;
  // Whether frames come back through a staging copy (the device's memory is not host-visible,
  // or BackendOptions::vk_staging asks for it).
  bool reads_through_staging() const;
  // Whether it runs under the validation layer.
  bool validation() const { return validation_; }

  // Compiles a compute shader (glslang) and makes a pipeline of it on the device; throws
  // kernel::ShaderError with glslang's log and the source lines it names.
  void compile(const std::string& source) const;

 private:
  struct Context;            // the instance, device, buffers and compiled pipelines
  Context* context() const;  // null when unavailable (unavailable_ says why)
  void make_context() const;
  Frame draw(const Scene& scene, const Camera& camera, int width, int height,
             const MarchParams& params, const Progress& progress, bool colour_only) const;

  BackendOptions options_;
  bool validation_;
  mutable std::once_flag made_;
  mutable std::unique_ptr<Context> context_;
  mutable std::string unavailable_;
};

}  // namespace flatmarch
