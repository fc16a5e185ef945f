// The OpenGL backend's entry in the registry: its options, its devices as the fingerprint and
// `flatmarch backends` give them, and the shaders `flatmarch shader` prints and compiles.
#include <nlohmann/json.hpp>

#include "backends/opengl/context.hpp"
#include "backends/opengl/opengl.hpp"
#include "kernels/compile.hpp"
#include "kernels/scene_shader.hpp"

namespace flatmarch {

namespace {

// The OpenGL backend's gpu shape is a compute shader, but for its probe-ray traces.
bool is_compute(const ShaderRequest& r) {
  return r.shape == KernelShape::gpu && !r.trace;
}

}  // namespace

BackendEntry opengl_backend_entry() {
  return {
      .name = OpenGlBackend::kName,
      .make = [](const BackendOptions& o) { return std::make_unique<OpenGlBackend>(o); },
      .options = {{"--device", &BackendOptions::device,
                   "the device, by its index or a part of its name as `flatmarch backends` "
                   "lists them (default: a GPU, else the CPU: llvmpipe through EGL, then "
                   "OSMesa)"},
                  {"--kernel-shape", &BackendOptions::kernel_shape, kKernelShapeHelp}},
      .cost = {.frame_seconds = 0.02},
      .fingerprint =
          [](nlohmann::json& fp) {
            // The device it chooses by default (a report run with --device says its own in
            // each case).
            const OpenGlBackend opengl;
            if (const std::optional<DeviceInfo> d = opengl.device())
              fp["opengl"] = {{"renderer", opengl.renderer()},
                              {"device", d->name},
                              {"api", d->api},
                              {"driver", d->driver},
                              {"platform", d->platform},
                              {"software", d->software}};
            else
              fp["opengl"] = {{"unavailable", opengl.availability().reason}};
          },
      .fingerprint_rows =
          [](const nlohmann::json& fp) {
            const nlohmann::json gl = fp.value("opengl", nlohmann::json::object());
            std::string text;
            if (gl.contains("renderer")) {
              text = gl["renderer"].get<std::string>();
              if (gl.contains("platform")) text += " through " + gl["platform"].get<std::string>();
              if (gl.value("software", false)) text += ", software: a rasteriser on the CPU";
            } else {
              text = "unavailable: " + gl.value("unavailable", "?");
            }
            return std::vector<std::pair<std::string, std::string>>{{"OpenGL", text}};
          },
      .describe_machine =
          [](const nlohmann::json& fp) {
            const nlohmann::json gl = fp.value("opengl", nlohmann::json::object());
            if (!gl.contains("renderer")) return std::string();
            return "OpenGL: " + gl["renderer"].get<std::string>() +
                   (gl.value("software", false) ? " (software)" : "");
          },
      .list =
          [](const Backend& b, nlohmann::json& listing) {
            const auto& opengl = dynamic_cast<const OpenGlBackend&>(b);
            nlohmann::json devices = nlohmann::json::array();
            for (const gl::Device& d : gl::list_devices())
              devices.push_back({{"index", d.index},
                                 {"platform", d.platform},
                                 {"node", d.node},
                                 {"vendor", d.vendor},
                                 {"renderer", d.renderer},
                                 {"version", d.version},
                                 {"software", d.software},
                                 {"usable", d.usable},
                                 {"reason", d.reason},
                                 {"default", d.index == opengl.device_index()}});
            listing["devices"] = devices;
          },
      .list_text =
          [](const nlohmann::json& listing) {
            const nlohmann::json& devices = listing.at("devices");
            if (devices.empty()) return std::string("opengl devices (--device): none\n");
            std::string text = "opengl devices (--device), * the default:\n";
            for (const auto& d : devices) {
              const std::string mark = d["default"].get<bool>() ? "*" : " ";
              const std::string node = d["node"].get<std::string>();
              const std::string where =
                  d["platform"].get<std::string>() + (node.empty() ? "" : " " + node);
              const std::string index = std::to_string(d["index"].get<int>());
              if (!d["usable"].get<bool>()) {
                text += "  " + mark + " " + index + "  " + where +
                        "  not usable: " + d["reason"].get<std::string>() + "\n";
                continue;
              }
              text += "  " + mark + " " + index + "  " + d["renderer"].get<std::string>() + "  (" +
                      where + ", " + d["vendor"].get<std::string>() + ", OpenGL " +
                      d["version"].get<std::string>() +
                      (d["software"].get<bool>() ? ", software" : "") + ")\n";
            }
            return text;
          },
      .shader =
          [](const Scene& scene, const MarchParams& params, const ShaderRequest& r) {
            const kernel::SceneTables<float> tables = kernel::compile_scene<float>(scene, params);
            const kernel::ShaderVariant variant{
                .trace = r.trace, .shape = r.shape, .readback = kernel::Readback::all};
            return is_compute(r)
                       ? kernel::scene_compute_shader(tables, variant, kernel::ComputeApi::opengl)
                       : kernel::scene_fragment_shader(tables, variant);
          },
      .compile_shader =
          [](const Backend& b, const std::string& source, const ShaderRequest& r) {
            const auto& opengl = dynamic_cast<const OpenGlBackend&>(b);
            opengl.compile(source, is_compute(r));
            return opengl.renderer();
          }};
}

}  // namespace flatmarch
