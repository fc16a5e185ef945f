// The webgl backend: the page of `flatmarch export-web` (web/page.hpp) in headless Chromium,
// driven through the DevTools protocol (chromium.hpp). Each (scene, march parameters) is one
// page in read-back mode, written to a temporary folder and opened once; a frame is drawn by
// WebGL2 into float targets (linear colour and the AOVs) and read back; a trace draws one
// fragment an event (WebGL2 has no storage buffers). WebGL runs on the GPU Chromium finds, or on
// SwiftShader, its software rasteriser. Float32 only.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "backends/backend.hpp"

namespace flatmarch {

class WebGlBackend final : public Backend {
 public:
  // options.device: "" lets Chromium choose (a GPU where it can use one, else SwiftShader);
  // "swiftshader" or "cpu" asks for SwiftShader; "gpu" asks for the GPU (ANGLE on OpenGL ES).
  explicit WebGlBackend(const BackendOptions& options = {});
  ~WebGlBackend() override;

  static constexpr const char* kName = "webgl";  // in the registry
  std::string name() const override { return kName; }
  std::string description() const override;
  Availability availability() const override;
  std::vector<Method> methods() const override {
    return {kKernelMethods.begin(), kKernelMethods.end()};
  }
  std::vector<Precision> precisions() const override { return {Precision::f32}; }
  std::optional<DeviceInfo> device() const override;
  Frame render(const Scene& scene, const Camera& camera, int width, int height,
               const MarchParams& params, const Progress& progress) const override;
  Trace trace(const Scene& scene, const Ray& ray, const MarchParams& params,
              int max_events) const override;
  // The page's own time for the last frame's draw and read-back of its float targets, without
  // the transfer through the DevTools protocol.
  std::optional<double> last_frame_seconds() const override;
  void rest() const override;
  bool runs_back_to_back() const override { return true; }

 private:
  struct Session;            // the browser, its page and the temporary folder
  Session* session() const;  // null when unavailable (unavailable_ says why)

  BackendOptions options_;
  mutable std::mutex start_;  // guards started_ and session_'s making and letting go
  mutable bool started_ = false;
  mutable std::unique_ptr<Session> session_;
  mutable std::string unavailable_;
};

}  // namespace flatmarch
