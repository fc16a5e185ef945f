// OpenGL through EGL, with no window: the device platform (EGL_EXT_platform_device) on each
// device EGL enumerates, GPUs and Mesa's software device alike, or Mesa's surfaceless platform
// where EGL lists no device. libEGL.so.1 (libglvnd, which dispatches to every vendor's EGL: Mesa,
// NVIDIA, ...) is opened on first use.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>

#include "backends/opengl/platforms.hpp"
#include "output/dynamic_library.hpp"

namespace flatmarch::gl {

namespace {

// X(type, name): the EGL 1.5 functions used, exported by libEGL.
#define FLATMARCH_EGL_FUNCTIONS(X)                           \
  X(PFNEGLGETPROCADDRESSPROC, eglGetProcAddress)             \
  X(PFNEGLQUERYSTRINGPROC, eglQueryString)                   \
  X(PFNEGLGETERRORPROC, eglGetError)                         \
  X(PFNEGLINITIALIZEPROC, eglInitialize)                     \
  X(PFNEGLBINDAPIPROC, eglBindAPI)                           \
  X(PFNEGLCHOOSECONFIGPROC, eglChooseConfig)                 \
  X(PFNEGLCREATECONTEXTPROC, eglCreateContext)               \
  X(PFNEGLDESTROYCONTEXTPROC, eglDestroyContext)             \
  X(PFNEGLCREATEPBUFFERSURFACEPROC, eglCreatePbufferSurface) \
  X(PFNEGLDESTROYSURFACEPROC, eglDestroySurface)             \
  X(PFNEGLMAKECURRENTPROC, eglMakeCurrent)

struct Egl {
  DynamicLibrary library{{"libEGL.so.1"}, "libEGL (OpenGL without a window; Debian: libegl1)"};
#define FLATMARCH_EGL_MEMBER(type, name) type name = library.function<type>(#name);
  FLATMARCH_EGL_FUNCTIONS(FLATMARCH_EGL_MEMBER)
#undef FLATMARCH_EGL_MEMBER
  // Extensions (null when EGL lacks them).
  PFNEGLGETPLATFORMDISPLAYEXTPROC eglGetPlatformDisplayEXT =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
          eglGetProcAddress("eglGetPlatformDisplayEXT"));
  PFNEGLQUERYDEVICESEXTPROC eglQueryDevicesEXT =
      reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  PFNEGLQUERYDEVICESTRINGEXTPROC eglQueryDeviceStringEXT =
      reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(
          eglGetProcAddress("eglQueryDeviceStringEXT"));
  std::string client_extensions = text(eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS));

  static std::string text(const char* s) {
    return s ? s : "";
  }
  // The last error, by its name in the EGL specification.
  std::string error() const {
    static constexpr const char* kNames[] = {
        "EGL_NOT_INITIALIZED",     "EGL_BAD_ACCESS",        "EGL_BAD_ALLOC",
        "EGL_BAD_ATTRIBUTE",       "EGL_BAD_CONFIG",        "EGL_BAD_CONTEXT",
        "EGL_BAD_CURRENT_SURFACE", "EGL_BAD_DISPLAY",       "EGL_BAD_MATCH",
        "EGL_BAD_NATIVE_PIXMAP",   "EGL_BAD_NATIVE_WINDOW", "EGL_BAD_PARAMETER",
        "EGL_BAD_SURFACE",         "EGL_CONTEXT_LOST"};
    const EGLint code = eglGetError();
    if (code >= EGL_NOT_INITIALIZED && code <= EGL_CONTEXT_LOST)
      return kNames[code - EGL_NOT_INITIALIZED];
    char text[32];
    std::snprintf(text, sizeof text, "EGL error 0x%04x", static_cast<unsigned>(code));
    return text;
  }
};

// libEGL, loaded once (and kept for the life of the process); throws std::runtime_error saying
// why it cannot be.
const Egl& egl() {
  static const std::pair<const Egl*, std::string> loaded = []() {
    try {
      return std::pair<const Egl*, std::string>(new Egl, "");
    } catch (const std::exception& e) {
      return std::pair<const Egl*, std::string>(nullptr, e.what());
    }
  }();
  if (loaded.first == nullptr) throw std::runtime_error(loaded.second);
  return *loaded.first;
}

void* proc(const char* name) {
  return reinterpret_cast<void*>(egl().eglGetProcAddress(name));
}

bool has(const std::string& extensions, const std::string& name) {
  const std::string padded = " " + extensions + " ";
  return padded.find(" " + name + " ") != std::string::npos;
}

class EglContext final : public Context {
 public:
  EglContext(const Egl& egl, EGLDisplay display, Device device, Profile profile)
      : egl_(egl), display_(display) {
    device_ = std::move(device);
    EGLint major = 0, minor = 0;
    if (display == EGL_NO_DISPLAY || !egl.eglInitialize(display, &major, &minor))
      throw std::runtime_error("EGL cannot initialise the display (" + egl.error() + ")");
    const std::string extensions = Egl::text(egl.eglQueryString(display, EGL_EXTENSIONS));
    if (!egl.eglBindAPI(EGL_OPENGL_API))
      throw std::runtime_error("this EGL display has no desktop OpenGL (" + egl.error() + ")");
    // A context needs no surface (EGL_KHR_surfaceless_context) and no config
    // (EGL_KHR_no_config_context) where the driver allows; else a 1 x 1 pbuffer and its config.
    const bool surfaceless = has(extensions, "EGL_KHR_surfaceless_context");
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!surfaceless || !has(extensions, "EGL_KHR_no_config_context")) {
      const EGLint wanted[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                               EGL_OPENGL_BIT, EGL_NONE};
      EGLint found = 0;
      if (!egl.eglChooseConfig(display, wanted, &config, 1, &found) || found < 1)
        throw std::runtime_error("this EGL display has no config for desktop OpenGL");
    }
    const bool core = profile == Profile::core;
    const EGLint attributes[] = {
        EGL_CONTEXT_MAJOR_VERSION,
        core ? 4 : 1,
        EGL_CONTEXT_MINOR_VERSION,
        core ? 5 : 0,
        EGL_CONTEXT_OPENGL_PROFILE_MASK,
        core ? EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT : EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT,
        EGL_NONE};
    context_ = egl.eglCreateContext(display, config, EGL_NO_CONTEXT, attributes);
    if (context_ == EGL_NO_CONTEXT)
      throw std::runtime_error(std::string("EGL cannot make an OpenGL ") +
                               (core ? "4.5 core" : "compatibility") + " context here (" +
                               egl.error() + ")");
    if (!surfaceless) {
      const EGLint size[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
      surface_ = egl.eglCreatePbufferSurface(display, config, size);
      if (surface_ == EGL_NO_SURFACE) {
        egl.eglDestroyContext(display, context_);
        throw std::runtime_error("EGL cannot make a pbuffer (" + egl.error() + ")");
      }
    }
    try {
      const Current current(*this);
      load(proc);
    } catch (...) {
      destroy();
      throw;
    }
  }
  ~EglContext() override { destroy(); }

 protected:
  void make_current() override {
    // eglMakeCurrent acts on the thread's bound API, which is per thread.
    if (!egl_.eglBindAPI(EGL_OPENGL_API) ||
        !egl_.eglMakeCurrent(display_, surface_, surface_, context_))
      throw std::runtime_error("the opengl backend cannot make its EGL context current (" +
                               egl_.error() + ")");
  }
  void release() override {
    egl_.eglBindAPI(EGL_OPENGL_API);
    egl_.eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }

 private:
  // The display stays initialised: EGL hands every caller the same display of a device, and
  // terminating it would end the other contexts made on it.
  void destroy() {
    if (surface_ != EGL_NO_SURFACE) egl_.eglDestroySurface(display_, surface_);
    if (context_ != EGL_NO_CONTEXT) egl_.eglDestroyContext(display_, context_);
    surface_ = EGL_NO_SURFACE;
    context_ = EGL_NO_CONTEXT;
  }

  const Egl& egl_;
  EGLDisplay display_;
  EGLSurface surface_ = EGL_NO_SURFACE;
  EGLContext context_ = EGL_NO_CONTEXT;
};

Candidate unusable(const std::string& why) {
  Candidate c;
  c.device.platform = "EGL";
  c.make = [why](const Device&, Profile) -> std::unique_ptr<Context> {
    throw std::runtime_error(why);
  };
  return c;
}

}  // namespace

std::vector<Candidate> egl_candidates() {
  const Egl* e = nullptr;
  try {
    e = &egl();
  } catch (const std::exception& error) {
    return {unusable(error.what())};
  }
  std::vector<Candidate> found;
  if (e->eglQueryDevicesEXT && e->eglQueryDeviceStringEXT && e->eglGetPlatformDisplayEXT &&
      has(e->client_extensions, "EGL_EXT_platform_device")) {
    constexpr EGLint kMaxDevices = 64;
    EGLDeviceEXT devices[kMaxDevices];
    EGLint count = 0;
    if (!e->eglQueryDevicesEXT(kMaxDevices, devices, &count)) count = 0;
    for (EGLint k = 0; k < count; ++k) {
      const EGLDeviceEXT handle = devices[k];
      const std::string extensions = Egl::text(e->eglQueryDeviceStringEXT(handle, EGL_EXTENSIONS));
      Candidate c;
      c.device.platform = "EGL device";
      c.device.software = has(extensions, "EGL_MESA_device_software");
      if (has(extensions, "EGL_EXT_device_drm_render_node"))
        c.device.node = Egl::text(e->eglQueryDeviceStringEXT(handle, EGL_DRM_RENDER_NODE_FILE_EXT));
      else if (has(extensions, "EGL_EXT_device_drm"))
        c.device.node = Egl::text(e->eglQueryDeviceStringEXT(handle, EGL_DRM_DEVICE_FILE_EXT));
      c.make = [e, handle](const Device& device, Profile profile) -> std::unique_ptr<Context> {
        return std::make_unique<EglContext>(
            *e, e->eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, handle, nullptr), device,
            profile);
      };
      found.push_back(std::move(c));
    }
  }
  if (found.empty() && e->eglGetPlatformDisplayEXT &&
      has(e->client_extensions, "EGL_MESA_platform_surfaceless")) {
    Candidate c;
    c.device.platform = "EGL surfaceless";
    c.make = [e](const Device& device, Profile profile) -> std::unique_ptr<Context> {
      return std::make_unique<EglContext>(
          *e,
          e->eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr),
          device, profile);
    };
    found.push_back(std::move(c));
  }
  if (found.empty())
    return {unusable(e->client_extensions.empty()
                         ? "EGL finds no driver (Debian: libegl-mesa0, or a GPU driver's EGL)"
                         : "EGL lists no device and has no surfaceless platform (its client "
                           "extensions: " +
                               e->client_extensions + ")")};
  return found;
}

}  // namespace flatmarch::gl
