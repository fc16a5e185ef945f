// Headless OpenGL 4.5 core contexts on whatever devices the machine has: through EGL, without a
// window (its devices on the device platform, or Mesa's surfaceless platform where the driver
// lists none), preferring a GPU as the Vulkan backend does, and through OSMesa (Mesa's llvmpipe)
// as the software fallback. libEGL and libOSMesa are opened at run time, when a context is first
// asked for.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "backends/opengl/gl_api.hpp"

namespace flatmarch::gl {

// A device a context can be made on.
struct Device {
  int index = 0;         // in the order of list_devices(): what --device takes
  std::string platform;  // how it is reached: "EGL device", "EGL surfaceless", "OSMesa"
  std::string node;      // the DRM node EGL names for it, or ""
  // Its context's GL_VENDOR, GL_RENDERER and GL_VERSION ("" until a context has been made).
  std::string vendor, renderer, version;
  bool software = false;  // a rasteriser on the CPU (llvmpipe, softpipe, SwiftShader)
  bool usable = false;    // an OpenGL 4.5 core context was made on it
  std::string reason;     // why not, when a context could not be made

  // The renderer, or the platform and node before a context is made.
  std::string name() const;
  // The driver and its version, from GL_VERSION ("Mesa 22.3.6", "NVIDIA 550.54.15").
  std::string driver() const;
};

// A context and the GL functions it gives. Current on a thread only inside a Current scope: it
// is released after every use, so that any thread may take it next and contexts of EGL and
// OSMesa in one process cannot find each other's state current.
class Context {
 public:
  virtual ~Context() = default;
  const Api& api() const { return api_; }
  const Device& device() const { return device_; }

  class Current {
   public:
    explicit Current(Context& c) : c_(c) { c_.make_current(); }
    ~Current() { c_.release(); }
    Current(const Current&) = delete;
    Current& operator=(const Current&) = delete;

   private:
    Context& c_;
  };

 protected:
  virtual void make_current() = 0;  // throws std::runtime_error
  virtual void release() = 0;
  // Loads the functions and reads the device's strings; call with the context current.
  void load(GetProcAddress get);

  Api api_;
  Device device_;
};

// Whether a renderer string (GL_RENDERER) names a rasteriser on the CPU.
bool software_renderer(const std::string& renderer);

// What a context offers: OpenGL 4.5 core (the kernel's programs), or the compatibility profile
// (GLSL 1.20 programs, such as the original web app's shaders that the benchmarks time).
enum class Profile { core, compatibility };

// Every device EGL lists, then OSMesa's, each tried: a context is made on it (and destroyed) to
// read its renderer, or the reason it cannot be made is kept.
std::vector<Device> list_devices();

// A context on the device `want` names: its index in list_devices(), or a part of its platform
// or renderer ("osmesa", "llvmpipe", "nvidia"), case-insensitive. Empty: the first GPU that
// makes one, else EGL's software device, else OSMesa. Throws std::runtime_error saying why no
// device matches or none makes a context.
std::unique_ptr<Context> make_context(const std::string& want, Profile profile = Profile::core);

}  // namespace flatmarch::gl
