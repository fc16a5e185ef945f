// `flatmarch export-web`: a scene as a self-contained web page that marches it with WebGL2 (issue
// 23, first part): the kernel's shader in GLSL ES 3.00, the scene's camera and the viewer's look
// controls, no network needed to open it.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "kernels/compile.hpp"
#include "kernels/scene_shader.hpp"
#include "scene/load.hpp"

namespace flatmarch::cli {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The page. @DATA@ is replaced by the scene's JSON (its name, description, camera, the march
// parameters and one fragment shader per method); the script reads it and draws.
const char* const kPage = R"html(<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>@TITLE@ - flatmarch</title>
<style>
  html, body { margin: 0; height: 100%; background: #000; overflow: hidden; }
  canvas { display: block; width: 100%; height: 100%; touch-action: none; }
  body.frame canvas { width: auto; height: auto; }
  #hud { position: fixed; left: 8px; top: 8px; color: #eee; font: 13px/1.4 sans-serif;
         background: rgba(0, 0, 0, 0.55); padding: 6px 10px; border-radius: 4px; max-width: 42em; }
  #hud b { color: #fff; }
  #error { position: fixed; inset: 0; color: #fbb; background: #200; font: 13px monospace;
           white-space: pre-wrap; padding: 1em; overflow: auto; display: none; }
  body.frame #hud { display: none; }
</style>
</head>
<body>
<canvas id="view"></canvas>
<div id="hud"></div>
<div id="error"></div>
<script id="scene" type="application/json">@DATA@</script>
<script>
"use strict";
const scene = JSON.parse(document.getElementById("scene").textContent);
const canvas = document.getElementById("view");
const hud = document.getElementById("hud");
const query = new URLSearchParams(location.search);
// ?frame=WxH: one frame of exactly that size from the scene's camera, for tests and comparisons;
// the page then sets its title to "flatmarch: rendered" (or "flatmarch: error").
const frame = query.get("frame");
const camera = Object.assign({}, scene.camera);
let method = query.get("method") || scene.method;
let renderScale = 1.0;

function fail(message) {
  const box = document.getElementById("error");
  box.textContent = message;
  box.style.display = "block";
  document.title = "flatmarch: error";
}

const gl = canvas.getContext("webgl2", { antialias: false, preserveDrawingBuffer: true });
if (!gl) fail("This browser has no WebGL2: flatmarch's page needs it.");

function compile(type, source) {
  const shader = gl.createShader(type);
  gl.shaderSource(shader, source);
  gl.compileShader(shader);
  if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS))
    throw new Error("shader: " + gl.getShaderInfoLog(shader));
  return shader;
}

const programs = {};
function program(name) {
  if (programs[name]) return programs[name];
  const p = gl.createProgram();
  gl.attachShader(p, compile(gl.VERTEX_SHADER, scene.vertex_shader));
  gl.attachShader(p, compile(gl.FRAGMENT_SHADER, scene.shaders[name]));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error("link: " + gl.getProgramInfoLog(p));
  const u = {};
  for (const n of ["u_polygon", "u_from", "u_forward", "u_right", "u_up", "u_scale", "u_size"])
    u[n] = gl.getUniformLocation(p, n);
  programs[name] = { p, u };
  return programs[name];
}

// DESIGN.md section 2: the camera's basis, as every backend computes it.
function basis(c) {
  const a = c.yaw_deg * Math.PI / 180, b = c.pitch_deg * Math.PI / 180;
  const f = [Math.cos(b) * Math.cos(a), Math.cos(b) * Math.sin(a), Math.sin(b)];
  const r = [Math.sin(a), -Math.cos(a), 0];
  const u = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]];
  return { f, r, u };
}

function size() {
  if (frame) {
    const m = /^(\d+)x(\d+)$/.exec(frame);
    if (!m) throw new Error("?frame= wants WxH, got " + frame);
    return [Number(m[1]), Number(m[2])];
  }
  const ratio = (window.devicePixelRatio || 1) * renderScale;
  return [Math.max(1, Math.round(canvas.clientWidth * ratio)),
          Math.max(1, Math.round(canvas.clientHeight * ratio))];
}

let lastMs = 0;
const probe = new Uint8Array(4);
function draw() {
  const [w, h] = size();
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  const { p, u } = program(method);
  const { f, r, u: up } = basis(camera);
  const t = Math.tan(camera.fov_deg * Math.PI / 360);
  gl.viewport(0, 0, w, h);
  gl.useProgram(p);
  gl.uniform1i(u.u_polygon, camera.polygon);
  gl.uniform3fv(u.u_from, camera.position);
  gl.uniform3fv(u.u_forward, f);
  gl.uniform3fv(u.u_right, r);
  gl.uniform3fv(u.u_up, up);
  gl.uniform2f(u.u_scale, (w / h) * t, t);
  gl.uniform2f(u.u_size, w, h);
  const start = performance.now();
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  // A one-pixel read waits for the frame (gl.finish does not, in a browser): its time is honest.
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, probe);
  lastMs = performance.now() - start;
  showHud(w, h);
}

function showHud(w, h) {
  hud.innerHTML = "<b>" + scene.name + "</b> &middot; " + method + ", eps " + scene.eps +
    ", offset " + scene.offset + " &middot; " + w + "&times;" + h + ", " + lastMs.toFixed(1) + " ms<br>" +
    "drag or arrow keys: look &middot; 1 sphere, 2 relaxed, 3 analytic &middot; [ ] field of view (" +
    camera.fov_deg.toFixed(0) + "&deg;) &middot; - + resolution &middot; P screenshot &middot; H hide this";
}

let pending = false;
function redraw() {
  if (pending) return;
  pending = true;
  requestAnimationFrame(() => {
    pending = false;
    try { draw(); } catch (e) { fail(String(e.message || e)); }
  });
}

function look(dyaw, dpitch) {
  camera.yaw_deg = ((camera.yaw_deg + dyaw + 540) % 360) - 180;
  camera.pitch_deg = Math.max(-89, Math.min(89, camera.pitch_deg + dpitch));
  redraw();
}

function screenshot() {
  canvas.toBlob((blob) => {
    const a = document.createElement("a");
    a.href = URL.createObjectURL(blob);
    a.download = scene.name + ".png";
    a.click();
  });
}

// ?frame=WxH&bench=N: N frames more after the first, timed each (a one-pixel read-back waits
// for it); the title then says "flatmarch: rendered; median M ms over N frames", and
// window.flatmarchTimes holds every frame's milliseconds.
const bench = Math.max(0, Math.min(1000, Number(query.get("bench")) || 0));
if (gl && frame) {
  document.body.classList.add("frame");
  try {
    draw();
    const times = [];
    for (let k = 0; k < bench; ++k) { draw(); times.push(lastMs); }
    window.flatmarchTimes = times;
    times.sort((a, b) => a - b);
    document.title = "flatmarch: rendered" + (bench ? "; median " +
      times[Math.floor(times.length / 2)].toFixed(3) + " ms over " + bench + " frames" : "");
  } catch (e) { fail(String(e.message || e)); }
} else if (gl) {
  let drag = null;
  canvas.addEventListener("pointerdown", (e) => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener("pointerup", () => { drag = null; });
  canvas.addEventListener("pointermove", (e) => {
    if (!drag) return;
    look(-0.2 * (e.clientX - drag[0]), -0.2 * (e.clientY - drag[1]));
    drag = [e.clientX, e.clientY];
  });
  window.addEventListener("keydown", (e) => {
    const keys = {
      ArrowLeft: () => look(5, 0), ArrowRight: () => look(-5, 0),
      ArrowUp: () => look(0, 5), ArrowDown: () => look(0, -5),
      "1": () => { method = "sphere"; }, "2": () => { method = "relaxed"; }, "3": () => { method = "analytic"; },
      "[": () => { camera.fov_deg = Math.max(10, camera.fov_deg - 5); },
      "]": () => { camera.fov_deg = Math.min(150, camera.fov_deg + 5); },
      "-": () => { renderScale = Math.max(0.125, renderScale / 2); },
      "+": () => { renderScale = Math.min(2, renderScale * 2); },
      "=": () => { renderScale = Math.min(2, renderScale * 2); },
      p: screenshot, P: screenshot,
      h: () => { hud.hidden = !hud.hidden; }, H: () => { hud.hidden = !hud.hidden; },
    };
    if (keys[e.key]) { keys[e.key](); redraw(); e.preventDefault(); }
  });
  window.addEventListener("resize", redraw);
  redraw();
}
</script>
</body>
</html>
)html";

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
  return s;
}

// Text as HTML (for the title).
std::string html_text(const std::string& s) {
  return replace_all(replace_all(replace_all(s, "&", "&amp;"), "<", "&lt;"), ">", "&gt;");
}

// The scene's page.
std::string page(const Scene& scene, const MarchParams& params) {
  json shaders = json::object();
  for (const Method m : kKernelMethods) {
    MarchParams p = params;
    p.method = m;
    shaders[to_string(m)] = kernel::web_fragment_shader(kernel::compile_scene<float>(scene, p));
  }
  const Camera& c = scene.camera;
  const json data = {{"name", scene.name},
                     {"description", scene.description},
                     {"camera",
                      {{"polygon", c.polygon},
                       {"position", {c.position.x, c.position.y, c.position.z}},
                       {"yaw_deg", c.yaw_deg},
                       {"pitch_deg", c.pitch_deg},
                       {"fov_deg", c.fov_deg}}},
                     {"method", to_string(params.method)},
                     {"eps", params.eps},
                     {"offset", params.offset},
                     {"vertex_shader", kernel::kWebVertexShader},
                     {"shaders", shaders}};
  // In a script element "</" would end it early.
  const std::string text = replace_all(data.dump(), "</", "<\\/");
  return replace_all(replace_all(kPage, "@TITLE@", html_text(scene.name)), "@DATA@", text);
}

void write_file(const fs::path& file, const std::string& text) {
  std::error_code error;
  fs::create_directories(file.parent_path(), error);
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw UsageError("-o: cannot write " + file.string());
}

std::string kilobytes(size_t bytes) {
  char s[32];
  std::snprintf(s, sizeof s, "%.0f KB", static_cast<double>(bytes) / 1024.0);
  return s;
}

}  // namespace

void add_export_web(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "export-web",
      "Write each scene as a self-contained web page that marches it in the browser with WebGL2:\n"
      "the kernel's shader (kernels/march.glsl) in GLSL ES 3.00, specialised on the scene with "
      "its\n"
      "tables baked in, one per method, and the scene's camera. Nothing is fetched when the page\n"
      "opens: it works from a file, offline. Controls: drag or arrow keys to look, 1/2/3 for\n"
      "sphere/relaxed/analytic, [ ] the field of view, - + the resolution, P a screenshot, H the\n"
      "help line. The page takes ?frame=WxH to draw one frame of that size from the scene's "
      "camera\n"
      "(for comparisons with `flatmarch render`; &bench=N times N more and puts the median in\n"
      "the title) and ?method=NAME. Walking (and being carried\n"
      "through gluings, as the viewer is) is not in the page yet. One scene: OUT/index.html;\n"
      "several: OUT/NAME/index.html each and OUT/index.html linking them.");
  struct Options {
    std::vector<std::string> scenes;
    std::string out, method = "analytic";
    MarchParams params;
    bool quiet = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("SCENE", o->scenes, "Scene files (JSON)")->required();
  cmd->add_option("-o,--output", o->out, "Output folder")->required();
  cmd->add_option("--method", o->method, "The method the page starts with")->capture_default_str();
  add_march_param_options(*cmd, o->params);
  cmd->add_flag("-q,--quiet", o->quiet, "No summary on stderr");
  cmd->callback([o] {
    check_march_params(o->params);
    const std::vector<Method> methods = parse_methods({o->method});
    if (methods.size() != 1 || methods[0] == Method::oracle)
      throw UsageError("--method: one of sphere, relaxed, analytic");
    o->params.method = methods[0];
    std::vector<Scene> scenes;
    for (const std::string& file : o->scenes) {
      scenes.push_back(load_scene(file));
      check_reach(scenes.back(), scenes.back().camera, o->params);
    }
    const fs::path out(o->out);
    std::string links;
    for (const Scene& scene : scenes) {
      const fs::path file =
          scenes.size() == 1 ? out / "index.html" : out / scene.name / "index.html";
      const std::string text = page(scene, o->params);
      write_file(file, text);
      links += "<li><a href=\"" + html_text(scene.name) + "/index.html\">" + html_text(scene.name) +
               "</a> " + html_text(scene.description) + "</li>\n";
      if (!o->quiet)
        std::fprintf(stderr, "export-web: wrote %s (%s)\n", file.string().c_str(),
                     kilobytes(text.size()).c_str());
    }
    if (scenes.size() > 1) {
      write_file(
          out / "index.html",
          "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>flatmarch "
          "scenes</title></head>\n<body style=\"font-family: sans-serif\"><h1>flatmarch "
          "scenes</h1><p>Each page marches its surface in the browser (WebGL2).</p><ul>\n" +
              links + "</ul></body></html>\n");
      if (!o->quiet)
        std::fprintf(stderr, "export-web: wrote %s\n", (out / "index.html").string().c_str());
    }
  });
}

}  // namespace flatmarch::cli
