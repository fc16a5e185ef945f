#include "backends/webgl/webgl.hpp"

#include <stdlib.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "backends/kernel_trace.hpp"
#include "backends/webgl/chromium.hpp"
#include "kernels/camera.hpp"
#include "web/page.hpp"

namespace flatmarch {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// A frame of a large image on SwiftShader takes seconds; a browser that has hung is given up.
constexpr double kFrameTimeout = 600.0;
constexpr double kStartTimeout = 60.0;

// The browser's WebGL2, asked of a canvas of a blank page: null where it has none.
const char* const kProbe = R"js((() => {
  const gl = document.createElement("canvas").getContext("webgl2");
  if (!gl) return null;
  const debug = gl.getExtension("WEBGL_debug_renderer_info");
  return {
    version: gl.getParameter(gl.VERSION),
    vendor: gl.getParameter(debug ? debug.UNMASKED_VENDOR_WEBGL : gl.VENDOR),
    renderer: gl.getParameter(debug ? debug.UNMASKED_RENDERER_WEBGL : gl.RENDERER),
    float_targets: !!gl.getExtension("EXT_color_buffer_float"),
    max_size: gl.getParameter(gl.MAX_TEXTURE_SIZE),
  };
})())js";

// Standard base64 (RFC 4648), as the page's btoa() writes it, into bytes.
std::vector<unsigned char> from_base64(const std::string& text) {
  std::array<int, 256> value;
  value.fill(-1);
  const char* const alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  for (int k = 0; k < 64; ++k) value[static_cast<unsigned char>(alphabet[k])] = k;
  std::vector<unsigned char> bytes;
  bytes.reserve(text.size() / 4 * 3);
  unsigned bits = 0;
  int count = 0;
  for (const char c : text) {
    if (c == '=') break;
    const int v = value[static_cast<unsigned char>(c)];
    if (v < 0) throw std::runtime_error("the webgl backend's page sent bad base64");
    bits = (bits << 6) | static_cast<unsigned>(v);
    count += 6;
    if (count >= 8) {
      count -= 8;
      bytes.push_back(static_cast<unsigned char>((bits >> count) & 0xffu));
    }
  }
  return bytes;
}

// A float32 array the page sent (little-endian, as x86 and ARM keep floats), of `n` values.
std::vector<float> floats(const json& value, size_t n) {
  const std::vector<unsigned char> bytes = from_base64(value.get<std::string>());
  if (bytes.size() != 4 * n)
    throw std::runtime_error("the webgl backend's page sent " + std::to_string(bytes.size()) +
                             " bytes where " + std::to_string(4 * n) + " were due");
  std::vector<float> out(n);
  std::memcpy(out.data(), bytes.data(), bytes.size());
  return out;
}

json vec3_json(glm::vec3 v) {
  return {v.x, v.y, v.z};
}

void check_precision(const MarchParams& params) {
  if (params.precision != Precision::f32)
    throw std::invalid_argument(
        "the webgl backend marches in f32 only (WebGL has no double; the scalar backend runs "
        "f64)");
}

// "Chrome/156.0.8078.108" as "Chrome 156.0.8078.108 (headless)": the browser, as a driver.
std::string browser_name(std::string product) {
  if (const size_t slash = product.find('/'); slash != std::string::npos) product[slash] = ' ';
  return product + " (headless)";
}

[[noreturn]] void unavailable(const std::string& why) {
  throw std::runtime_error("the webgl backend is unavailable: " + why);
}

}  // namespace

struct WebGlBackend::Session {
  std::unique_ptr<webgl::Chromium> browser;
  fs::path folder;   // the pages, removed with the session
  std::string page;  // the text of the page open now
  int pages = 0;     // pages written
  json info;         // kProbe's answer
  std::mutex mutex;  // one frame or trace at a time
  double last_ms = -1.0;

  ~Session() {
    browser.reset();
    std::error_code ignored;
    if (!folder.empty()) fs::remove_all(folder, ignored);
  }

  std::string shape;  // ?shape= of the pages (BackendOptions::kernel_shape), "" for the page's own

  // Opens the page of `scene` and `params` in read-back mode, unless it is open.
  void open(const Scene& scene, const MarchParams& params) {
    web::PageOptions options;
    options.methods = {params.method};
    options.readback = true;
    std::string text = web::page(scene, params, options);
    if (text == page) return;
    page.clear();
    const fs::path file = folder / ("page-" + std::to_string(++pages) + ".html");
    std::ofstream(file, std::ios::binary) << text;
    browser->navigate(
        "file://" + file.string() + "?readback" + (shape.empty() ? "" : "&shape=" + shape),
        kStartTimeout);
    if (!browser->evaluate("typeof flatmarchReadback === 'object'").get<bool>())
      throw std::runtime_error(
          "the webgl backend's page did not start: " +
          browser->evaluate("document.getElementById('error').textContent").get<std::string>());
    std::error_code ignored;
    fs::remove(file, ignored);  // loaded: the browser has it
    page = std::move(text);
  }
};

WebGlBackend::WebGlBackend(const BackendOptions& options) : options_(options) {}

WebGlBackend::~WebGlBackend() = default;

// The browser starts on first use, not when the backend is listed: every command builds the
// backend registry, and few draw.
WebGlBackend::Session* WebGlBackend::session() const {
  const std::lock_guard<std::mutex> lock(start_);
  if (!started_)
    [this] {
      started_ = true;
      try {
        const std::vector<std::string> flags = webgl::device_flags(options_.device);
        const std::optional<std::string> chromium = webgl::find_chromium();
        if (!chromium) {
          unavailable_ =
              "no Chromium found (Debian's chromium package, which ci/packages.txt installs; or "
              "set FLATMARCH_CHROMIUM to a Chromium)";
          return;
        }
        auto s = std::make_unique<Session>();
        char folder[] = "/tmp/flatmarch-webgl-XXXXXX";
        if (!mkdtemp(folder)) throw std::runtime_error("cannot make a temporary folder");
        s->folder = folder;
        s->browser = std::make_unique<webgl::Chromium>(*chromium, flags, kStartTimeout);
        s->info = s->browser->evaluate(kProbe, kStartTimeout);
        if (s->info.is_null()) {
          unavailable_ = s->browser->product() + " has no WebGL2 here";
          return;
        }
        if (!s->info.value("float_targets", false)) {
          unavailable_ = s->browser->product() + "'s WebGL2 (" +
                         s->info.value("renderer", std::string()) +
                         ") cannot draw to float targets (EXT_color_buffer_float)";
          return;
        }
        if (const std::string e = kernel_shape_error(options_.kernel_shape); !e.empty()) {
          unavailable_ = e;
          return;
        }
        // Forced, the pages take the shape; else each picks it by its renderer, as on the web.
        if (options_.kernel_shape == "software" || options_.kernel_shape == "gpu")
          s->shape = options_.kernel_shape;
        session_ = std::move(s);
      } catch (const std::exception& e) {
        unavailable_ = e.what();
      }
    }();
  return session_.get();
}

std::string WebGlBackend::description() const {
  if (!session())
    return "the page of `flatmarch export-web` in headless Chromium, WebGL2 (unavailable)";
  const std::optional<DeviceInfo> d = device();
  return "the page of `flatmarch export-web` in headless Chromium through the DevTools protocol (" +
         d->driver + ", " + d->api + ", " + d->name + (d->software ? ", software" : "") + "); f32";
}

Availability WebGlBackend::availability() const {
  if (!session()) return {false, unavailable_};
  return {};
}

void WebGlBackend::rest() const {
  // The browser itself goes: a page left for about:blank was not enough, SwiftShader's threads
  // in its GPU process went on spinning. The next frame starts it again (half a second a case on a
  // 2-core Zen 5).
  const std::lock_guard<std::mutex> lock(start_);
  if (!session_) return;
  session_.reset();
  started_ = false;
}

std::optional<DeviceInfo> WebGlBackend::device() const {
  if (!session()) return std::nullopt;
  const json& info = session_->info;
  const std::string renderer = info.value("renderer", std::string());
  const bool software = renderer.find("SwiftShader") != std::string::npos ||
                        renderer.find("llvmpipe") != std::string::npos ||
                        renderer.find("Software") != std::string::npos;
  return DeviceInfo{
      .name = renderer,
      .type = software ? "CPU" : "GPU",
      .api = info.value("version", std::string()),
      .driver = browser_name(session_->browser->product()),
      .platform = "headless Chromium",
      .software = software,
      .kernel_shape = to_string(
          parse_kernel_shape(options_.kernel_shape, software).value_or(KernelShape::software))};
}

Frame WebGlBackend::render(const Scene& scene, const Camera& camera, int width, int height,
                           const MarchParams& params, const Progress& progress) const {
  check_precision(params);
  Session* s = session();
  if (!s) unavailable(unavailable_);
  const int max_size = s->info.value("max_size", 0);
  if (width < 1 || height < 1 || width > max_size || height > max_size)
    throw std::invalid_argument("the webgl backend renders 1 to " + std::to_string(max_size) +
                                " pixels a side here");
  const std::lock_guard<std::mutex> lock(s->mutex);
  if (progress) progress(0.0);
  s->open(scene, params);
  // The camera's basis as the opengl backend makes it, in float, for the same uniforms.
  const CameraBasis<float> b = camera_basis<float>(float(camera.yaw_deg), float(camera.pitch_deg),
                                                   float(camera.fov_deg), width, height);
  const json c = {{"polygon", camera.polygon},
                  {"position", vec3_json(glm::vec3(camera.position))},
                  {"basis",
                   {{"forward", vec3_json(b.forward)},
                    {"right", vec3_json(b.right)},
                    {"up", vec3_json(b.up)},
                    {"scale", {b.aspect * b.tan_half_fov, b.tan_half_fov}}}}};
  const json r =
      s->browser->evaluate("flatmarchReadback.render(" + c.dump() + ", " + std::to_string(width) +
                               ", " + std::to_string(height) + ")",
                           kFrameTimeout);
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  const std::vector<float> colour = floats(r.at("colour"), 4 * pixels);
  const std::vector<float> aov = floats(r.at("aov"), 4 * pixels);
  Frame frame(width, height);
  for (size_t px = 0; px < pixels; ++px)
    frame.set(px, colour[4 * px], colour[4 * px + 1], colour[4 * px + 2], aov[4 * px],
              aov[4 * px + 1], aov[4 * px + 2], aov[4 * px + 3]);
  s->last_ms = r.at("ms").get<double>();
  if (progress) progress(1.0);
  return frame;
}

Trace WebGlBackend::trace(const Scene& scene, const Ray& ray, const MarchParams& params,
                          int max_events) const {
  check_precision(params);
  Session* s = session();
  if (!s) unavailable(unavailable_);
  const std::lock_guard<std::mutex> lock(s->mutex);
  s->open(scene, params);
  const int count = std::max(max_events, 1);
  const json r = s->browser->evaluate("flatmarchReadback.trace(" + std::to_string(ray.polygon) +
                                          ", " + vec3_json(glm::vec3(ray.from)).dump() + ", " +
                                          vec3_json(glm::vec3(ray.dir)).dump() + ", " +
                                          std::to_string(count) + ")",
                                      kFrameTimeout);
  const size_t cells = static_cast<size_t>(r.at("w").get<int>()) * r.at("h").get<size_t>();
  if (cells < static_cast<size_t>(count))
    throw std::runtime_error("the webgl backend's page traced into too few fragments");
  const std::vector<float> kind = floats(r.at("kind"), 4 * cells);
  const std::vector<float> more = floats(r.at("more"), 4 * cells);
  const std::vector<float> at = floats(r.at("at"), 4 * cells);
  const int steps = static_cast<int>(more[2]), recorded = static_cast<int>(more[3]);
  std::vector<kernel::KernelEvent> events;
  for (int k = 0; k < std::min(recorded, max_events); ++k) {
    const size_t i = 4 * static_cast<size_t>(k);
    const auto whole = [](float x) { return static_cast<int>(x); };
    events.push_back({whole(kind[i]), whole(kind[i + 1]), whole(kind[i + 2]), whole(kind[i + 3]),
                      whole(more[i]), whole(more[i + 1]), static_cast<double>(at[i + 3]),
                      glm::dvec3(at[i], at[i + 1], at[i + 2])});
  }
  return kernel_trace(events, steps);
}

std::optional<double> WebGlBackend::last_frame_seconds() const {
  if (!session_) return std::nullopt;
  const std::lock_guard<std::mutex> lock(session_->mutex);
  if (session_->last_ms < 0.0) return std::nullopt;
  return session_->last_ms / 1000.0;
}

}  // namespace flatmarch
