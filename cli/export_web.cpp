// `flatmarch export-web`: a scene as a self-contained web page that marches it with WebGL2 (issue
// 23, first part): the kernel's shader in GLSL ES 3.00, the scene's camera and the viewer's look
// controls, no network needed to open it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "kernels/compile.hpp"
#include "kernels/scene_shader.hpp"
#include "plan/floor_plan.hpp"
#include "scene/load.hpp"
#include "viewer/walk.hpp"

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
    "W/A/S/D walk, E/Q up and down (Shift: faster) &middot; drag or arrow keys: look &middot; 1 sphere, 2 relaxed, 3 analytic &middot; [ ] field of view (" +
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

// Walking (a port of viewer/walk.cpp: the same rules, in double precision): the horizontal path
// is followed across glued edges, each crossing mapping the point and the rest of the path by
// the edge's gluing and turning the yaw with it; mirrors and walls stop the walker kWalkMargin
// short and the rest slides along them; a vertex stops it; z stays inside the band, or is taken
// modulo the period of a prism; above or below the band the walker flies.
const W = scene.walk;
const { margin: kWalkMargin, max_segments: kMaxSegments, reach: kWalkReach } = W;
const kVertexRadius = 1e-6, kPush = 1e-9;  // as viewer/walk.cpp's own
const dot = (a, b) => a[0] * b[0] + a[1] * b[1];
const cross2 = (a, b) => a[0] * b[1] - a[1] * b[0];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1]];
const mul = (k, a) => [k * a[0], k * a[1]];
const len = (a) => Math.hypot(a[0], a[1]);
const apply = (m, v) => [m[0] * v[0] + m[2] * v[1], m[1] * v[0] + m[3] * v[1]];
function edgeDistance(e, p) {
  if (e.at_infinity) return Infinity;
  const u = Math.min(Math.max(dot(sub(p, e.start), e.along), 0), e.length === null ? Infinity : e.length);
  return len(sub(p, add(e.start, mul(u, e.along))));
}
function inBand(z) { return W.period !== null || (z >= 0 && z <= W.height); }
function contains(poly, p, margin) {
  let inside = false;
  const pts = poly.outline, n = pts.length;
  for (let i = 0; i < n; ++i) {
    const a = pts[i], b = pts[(i + 1) % n];
    if ((a[1] > p[1]) !== (b[1] > p[1])) {
      const x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
      if (x > p[0]) inside = !inside;
    }
  }
  let d = Infinity;
  for (const e of poly.edges) d = Math.min(d, edgeDistance(e, p));
  return inside && d > (margin || 0);
}
function exitOf(poly, o, d, vertexRadius, sTolerance) {
  let best = { s: Infinity, edge: -1 };
  if (d[0] === 0 && d[1] === 0) return best;
  poly.edges.forEach((e, i) => {
    if (dot(d, e.normal) <= 0) return;
    const denom = cross2(d, e.along);
    const s = cross2(sub(e.start, o), e.along) / denom;
    const u = cross2(sub(e.start, o), d) / denom;
    const length = e.length === null ? Infinity : e.length;
    if (u < -vertexRadius || u > length + vertexRadius || s < -sTolerance || s > 1) return;
    if (s < best.s) best = { s: Math.max(s, 0), edge: i };
  });
  return best;
}
function wrapYaw(y) { return y - 360 * Math.round(y / 360); }
function turnedYaw(e, yaw) {
  const angle = Math.atan2(e.linear[1], e.linear[0]) * 180 / Math.PI;
  if (e.gluing === "reflection") return wrapYaw(angle - yaw);
  if (e.gluing === "affine") {
    const f = apply(e.linear, [Math.cos(yaw * Math.PI / 180), Math.sin(yaw * Math.PI / 180)]);
    return Math.atan2(f[1], f[0]) * 180 / Math.PI;
  }
  return wrapYaw(yaw + angle);
}
function bandZ(z) {
  if (W.period !== null) return z - W.period * Math.floor(z / W.period);
  const margin = Math.min(kWalkMargin, 0.25 * W.height);
  return Math.min(Math.max(z, margin), W.height - margin);
}
function walkRooms(c, d, result) {
  let o = [c.position[0], c.position[1]];
  const vertexRadius = kVertexRadius * W.scale;
  for (let segment = 0; d[0] !== 0 || d[1] !== 0; ++segment) {
    if (segment === kMaxSegments) { result.blocked = true; break; }
    const poly = W.polygons[c.polygon];
    const reach = kWalkReach * W.scale;
    if (poly.infinite && len(o) + len(d) > reach) {
      d = mul(Math.max(reach - len(o), 0) / len(d), d);
      result.blocked = true;
      if (d[0] === 0 && d[1] === 0) break;
    }
    const exit = exitOf(poly, o, d, vertexRadius, vertexRadius / len(d));
    if (exit.edge < 0) {
      if (contains(poly, add(o, d), 0)) o = add(o, d); else result.blocked = true;
      break;
    }
    const e = poly.edges[exit.edge];
    const at = add(o, mul(exit.s, d));
    const toVertex = Math.min(len(sub(at, e.start)),
      e.length === null ? Infinity : len(sub(at, add(e.start, mul(e.length, e.along)))));
    if (toVertex <= vertexRadius) {
      o = add(o, mul(Math.max(exit.s - kWalkMargin / len(d), 0), d));
      result.blocked = true;
      break;
    }
    if (e.kind !== "glued") {
      const s = Math.max(exit.s - kWalkMargin / dot(d, e.normal), 0);
      o = add(o, mul(s, d));
      const rest = mul(1 - s, d);
      d = sub(rest, mul(dot(rest, e.normal), e.normal));
      result.blocked = true;
      continue;
    }
    const entry = W.polygons[e.to[0]].edges[e.to[1]];
    const p = add(apply(e.linear, at), e.translation);
    o = sub(p, mul(dot(sub(p, entry.start), entry.normal) + kPush * W.scale, entry.normal));
    d = apply(e.linear, mul(1 - exit.s, d));
    c.yaw_deg = turnedYaw(e, c.yaw_deg);
    c.polygon = e.to[0];
    ++result.crossings;
  }
  c.position = [o[0], o[1], c.position[2]];
}
function fly(c, d, up) {
  const x = c.position;
  const above = x[2] > W.height;
  c.position = [x[0] + d[0], x[1] + d[1], x[2] + up];
  const z = c.position[2];
  if (above ? z > W.height : z < 0) return;
  if (above || !W.floor) {
    for (let k = 0; k < W.polygons.length; ++k) {
      if (contains(W.polygons[k], [c.position[0], c.position[1]], kWalkMargin)) {
        c.polygon = k;
        c.position[2] = bandZ(z);
        return;
      }
    }
  }
  c.position[2] = above ? W.height + kWalkMargin : -kWalkMargin;
}
// Moves the camera `forward`, `right` (horizontally, in its yaw frame) and `up`.
function walk(c, forward, right, up) {
  const a = c.yaw_deg * Math.PI / 180;
  const d = [forward * Math.cos(a) + right * Math.sin(a), forward * Math.sin(a) - right * Math.cos(a)];
  const result = { crossings: 0, blocked: false };
  if (inBand(c.position[2])) {
    const z = c.position[2];
    walkRooms(c, d, result);
    c.position[2] = bandZ(z + up);
  } else {
    fly(c, d, up);
  }
  return result;
}

// A step of walking: a fiftieth of the scene's scale, four times that with Shift.
function stride(e) { return (e.shiftKey ? 0.08 : 0.02) * W.scale; }

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
// ?walk=F,R,U;F,R,U...: these walks from the scene's camera first; without ?frame the title then
// says "flatmarch: walked " and the camera as JSON (tests compare it with viewer/walk.cpp's).
let walked = null;
if (query.get("walk") !== null) {
  let crossings = 0;
  for (const step of query.get("walk").split(";").filter((x) => x))
    crossings += walk(camera, ...step.split(",").map(Number)).crossings;
  walked = JSON.stringify(
    { polygon: camera.polygon, position: camera.position, yaw_deg: camera.yaw_deg, crossings });
}
if (walked !== null && !frame) {
  document.title = "flatmarch: walked " + walked;
} else if (gl && frame) {
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
      w: () => walk(camera, stride(e), 0, 0), s: () => walk(camera, -stride(e), 0, 0),
      d: () => walk(camera, 0, stride(e), 0), a: () => walk(camera, 0, -stride(e), 0),
      e: () => walk(camera, 0, 0, stride(e)), q: () => walk(camera, 0, 0, -stride(e)),
      "1": () => { method = "sphere"; }, "2": () => { method = "relaxed"; }, "3": () => { method = "analytic"; },
      "[": () => { camera.fov_deg = Math.max(10, camera.fov_deg - 5); },
      "]": () => { camera.fov_deg = Math.min(150, camera.fov_deg + 5); },
      "-": () => { renderScale = Math.max(0.125, renderScale / 2); },
      "+": () => { renderScale = Math.min(2, renderScale * 2); },
      "=": () => { renderScale = Math.min(2, renderScale * 2); },
      p: screenshot, P: screenshot,
      h: () => { hud.hidden = !hud.hidden; }, H: () => { hud.hidden = !hud.hidden; },
    };
    const key = e.key.length === 1 && /[wasdeq]/i.test(e.key) ? e.key.toLowerCase() : e.key;
    if (keys[key]) { keys[key](); redraw(); e.preventDefault(); }
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

json pair(Vec2 v) {
  return {v.x, v.y};
}

// What the page's walk (a port of viewer/walk.cpp) needs of the scene: its band, and each
// polygon's edges with their gluings and an outline for the inside test (an unbounded room's cut
// off far beyond where a walk may go, kWalkReach).
json walk_data(const Scene& scene) {
  json polygons = json::array();
  for (const Polygon& polygon : scene.polygons) {
    double reach = viewer::kWalkReach * scene.scale;
    for (int i = 0; i < polygon.size(); ++i)
      if (!polygon.is_ideal(i)) reach = std::max(reach, glm::length(polygon.vertex(i)));
    json outline = json::array();
    for (const Vec2 v :
         polygon.infinite() ? polygon.outline(8.0 * (reach + 1.0)) : polygon.vertices)
      outline.push_back(pair(v));
    json edges = json::array();
    for (const Edge& e : polygon.edges) {
      const Mat2& m = e.map.linear;
      edges.push_back(
          {{"kind", to_string(e.kind)},
           {"at_infinity", e.shape == EdgeShape::at_infinity},
           {"start", pair(e.start)},
           {"along", pair(e.along)},
           {"length", std::isfinite(e.length) ? json(e.length) : json(nullptr)},
           {"normal", pair(e.normal)},
           {"to", {e.to.polygon, e.to.edge}},
           {"linear", {m[0].x, m[0].y, m[1].x, m[1].y}},
           {"translation", pair(e.map.translation)},
           {"gluing",
            e.gluing >= 0 ? to_string(scene.gluings[static_cast<size_t>(e.gluing)].type) : ""}});
    }
    polygons.push_back({{"infinite", polygon.infinite()}, {"outline", outline}, {"edges", edges}});
  }
  return {{"margin", viewer::kWalkMargin},
          {"max_segments", viewer::kMaxSegments},
          {"reach", viewer::kWalkReach},
          {"scale", scene.scale},
          {"height", scene.height},
          {"period", scene.period ? json(*scene.period) : json(nullptr)},
          {"floor", scene.floor},
          {"polygons", polygons}};
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
                     {"walk", walk_data(scene)},
                     {"vertex_shader", kernel::kWebVertexShader},
                     {"shaders", shaders}};
  // In a script element "</" would end it early.
  const std::string text = replace_all(data.dump(), "</", "<\\/");
  return replace_all(replace_all(kPage, "@TITLE@", xml_escape(scene.name)), "@DATA@", text);
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
      "the title), ?method=NAME, and ?walk=F,R,U;... (walks, as the viewer's, whose end the\n"
      "title then gives). W/A/S/D walk, E/Q up and down, carried through gluings as in the\n"
      "viewer. One scene: OUT/index.html;\n"
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
      links += "<li><a href=\"" + xml_escape(scene.name) + "/index.html\">" +
               xml_escape(scene.name) + "</a> " + xml_escape(scene.description) + "</li>\n";
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
