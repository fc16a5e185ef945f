// OpenGL through OSMesa: Mesa's off-screen interface to its software rasteriser (llvmpipe), the
// fallback where EGL makes no context. libOSMesa (which brings LLVM) is opened on first use.
#include <GL/osmesa.h>

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "backends/opengl/platforms.hpp"
#include "output/dynamic_library.hpp"

namespace flatmarch::gl {

namespace {

struct OsMesa {
  DynamicLibrary library{{"libOSMesa.so.8", "libOSMesa.so.6"},
                         "libOSMesa (Mesa's software OpenGL; Debian: libosmesa6)"};
  decltype(&OSMesaCreateContextAttribs) create =
      library.function<decltype(&OSMesaCreateContextAttribs)>("OSMesaCreateContextAttribs");
  decltype(&OSMesaMakeCurrent) make_current =
      library.function<decltype(&OSMesaMakeCurrent)>("OSMesaMakeCurrent");
  decltype(&OSMesaGetProcAddress) get_proc_address =
      library.function<decltype(&OSMesaGetProcAddress)>("OSMesaGetProcAddress");
  decltype(&OSMesaDestroyContext) destroy =
      library.function<decltype(&OSMesaDestroyContext)>("OSMesaDestroyContext");
};

// libOSMesa, loaded once (and kept for the life of the process); throws std::runtime_error
// saying why it cannot be.
const OsMesa& osmesa() {
  static const std::pair<const OsMesa*, std::string> loaded = []() {
    try {
      return std::pair<const OsMesa*, std::string>(new OsMesa, "");
    } catch (const std::exception& e) {
      return std::pair<const OsMesa*, std::string>(nullptr, e.what());
    }
  }();
  if (loaded.first == nullptr) throw std::runtime_error(loaded.second);
  return *loaded.first;
}

void* proc(const char* name) {
  return reinterpret_cast<void*>(osmesa().get_proc_address(name));
}

class OsMesaContext final : public Context {
 public:
  OsMesaContext(Device device, Profile profile) : osmesa_(osmesa()) {
    device_ = std::move(device);
    const bool core = profile == Profile::core;
    const int attributes[] = {OSMESA_FORMAT,
                              OSMESA_RGBA,
                              OSMESA_DEPTH_BITS,
                              0,
                              OSMESA_PROFILE,
                              core ? OSMESA_CORE_PROFILE : OSMESA_COMPAT_PROFILE,
                              OSMESA_CONTEXT_MAJOR_VERSION,
                              core ? 4 : 1,
                              OSMESA_CONTEXT_MINOR_VERSION,
                              core ? 5 : 0,
                              0};
    context_ = osmesa_.create(attributes, nullptr);
    if (context_ == nullptr)
      throw std::runtime_error(core ? "OSMesa cannot create an OpenGL 4.5 core context here"
                                    : "OSMesa cannot create a compatibility context here");
    try {
      const Current current(*this);
      load(proc);
    } catch (...) {
      osmesa_.destroy(context_);
      throw;
    }
  }
  ~OsMesaContext() override { osmesa_.destroy(context_); }

 protected:
  void make_current() override {
    if (!osmesa_.make_current(context_, surface_, GL_UNSIGNED_BYTE, 1, 1))
      throw std::runtime_error("the opengl backend cannot make its OSMesa context current");
  }
  void release() override { osmesa_.make_current(nullptr, nullptr, 0, 0, 0); }

 private:
  const OsMesa& osmesa_;
  OSMesaContext context_ = nullptr;
  unsigned char surface_[4] = {};  // OSMesa's own framebuffer, 1 x 1: unused (we draw to FBOs)
};

}  // namespace

Candidate osmesa_candidate() {
  Candidate c;
  c.device.platform = "OSMesa";
  c.device.software = true;
  c.make = [](const Device& device, Profile profile) -> std::unique_ptr<Context> {
    return std::make_unique<OsMesaContext>(device, profile);
  };
  return c;
}

}  // namespace flatmarch::gl
