#include "backends/opengl/context.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "backends/opengl/platforms.hpp"

namespace flatmarch::gl {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// EGL's devices in its order, then OSMesa, indexed.
std::vector<Candidate> candidates() {
  std::vector<Candidate> all = egl_candidates();
  all.push_back(osmesa_candidate());
  for (size_t k = 0; k < all.size(); ++k) all[k].device.index = static_cast<int>(k);
  return all;
}

}  // namespace

std::string Device::name() const {
  if (!renderer.empty()) return renderer;
  return platform + (node.empty() ? "" : " " + node);
}

std::string Device::driver() const {
  // GL_VERSION is "<major.minor[.release]> [(profile)] <vendor-specific information>".
  std::string rest = version.substr(std::min(version.find(' '), version.size()));
  if (const size_t profile = rest.find(')'); rest.find(" (") == 0 && profile != std::string::npos)
    rest = rest.substr(profile + 1);
  const size_t start = rest.find_first_not_of(' ');
  return start == std::string::npos ? std::string() : rest.substr(start);
}

bool software_renderer(const std::string& renderer) {
  const std::string r = lower(renderer);
  for (const char* name : {"llvmpipe", "softpipe", "swrast", "swiftshader", "software rasterizer"})
    if (r.find(name) != std::string::npos) return true;
  return false;
}

void Context::load(GetProcAddress get) {
  api_ = gl::load(get);
  const auto text = [&](GLenum what) {
    const GLubyte* s = api_.GetString(what);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
  };
  device_.vendor = text(GL_VENDOR);
  device_.renderer = text(GL_RENDERER);
  device_.version = text(GL_VERSION);
  device_.software = device_.software || software_renderer(device_.renderer);
  device_.usable = true;
  device_.reason.clear();
}

std::vector<Device> list_devices() {
  std::vector<Device> devices;
  for (Candidate& c : candidates()) {
    try {
      devices.push_back(c.make(c.device, Profile::core)->device());
    } catch (const std::exception& e) {
      c.device.reason = e.what();
      devices.push_back(c.device);
    }
  }
  return devices;
}

std::unique_ptr<Context> make_context(const std::string& want, Profile profile) {
  std::vector<Candidate> all = candidates();
  std::vector<Candidate*> order;
  if (want.empty()) {
    // GPUs first, then EGL's software device, then OSMesa; each in EGL's order.
    for (Candidate& c : all)
      if (!c.device.software) order.push_back(&c);
    for (Candidate& c : all)
      if (c.device.software) order.push_back(&c);
  } else {
    for (Candidate& c : all)
      if (std::to_string(c.device.index) == want) order.push_back(&c);
    if (order.empty()) {
      // Names are matched on the devices' contexts, made for the purpose.
      const std::vector<Device> listed = list_devices();
      for (Candidate& c : all) {
        const Device& d = listed[static_cast<size_t>(c.device.index)];
        if (lower(d.platform + " " + d.node + " " + d.vendor + " " + d.renderer)
                .find(lower(want)) != std::string::npos) {
          order.push_back(&c);
          break;
        }
      }
    }
    if (order.empty()) {
      std::string names;
      for (const Device& d : list_devices())
        names += (names.empty() ? "" : "; ") + std::to_string(d.index) + " " + d.name() + " (" +
                 d.platform + ")";
      throw std::runtime_error("no OpenGL device matches --device \"" + want +
                               "\" (devices: " + names + ")");
    }
  }
  std::string why;
  // A device EGL does not call software may still turn out to be (a DRM device that Mesa drives
  // with its software rasteriser): kept while the other GPUs are tried.
  std::unique_ptr<Context> software;
  for (Candidate* c : order) {
    if (software && c->device.software) break;
    try {
      std::unique_ptr<Context> made = c->make(c->device, profile);
      if (!want.empty() || !made->device().software) return made;
      if (!software) software = std::move(made);
    } catch (const std::exception& e) {
      why += (why.empty() ? "" : "; ") + std::to_string(c->device.index) + " " + c->device.name() +
             ": " + e.what();
    }
  }
  if (software) return software;
  throw std::runtime_error("no OpenGL 4.5 core context can be made (" + why + ")");
}

}  // namespace flatmarch::gl
