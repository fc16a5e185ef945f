"use strict";
const scene = JSON.parse(document.getElementById("scene").textContent);
const canvas = document.getElementById("view");
const hud = document.getElementById("hud");
const query = new URLSearchParams(location.search);
document.title = scene.name + " - flatmarch";
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

// eps and offset as the viewer steps them (motion/settings.hpp): by quarter decades from the
// export's values, eps within scene.eps_range, offset above eps and at most scene.max_offset.
let epsSteps = 0, offsetSteps = 0;
const quarterDecades = (start, steps) => start * Math.pow(10, steps / 4);
const eps = () => quarterDecades(scene.eps, epsSteps);
const offset = () => quarterDecades(scene.offset, offsetSteps);
function stepEps(steps) {
  const e = quarterDecades(scene.eps, epsSteps + steps);
  if (e < scene.eps_range[0] || e > scene.eps_range[1]) return;
  epsSteps += steps;
  for (let k = 0; k < 64 && offset() <= eps(); ++k) ++offsetSteps;  // offset follows eps up
}
function stepOffset(steps) {
  const o = quarterDecades(scene.offset, offsetSteps + steps);
  if (o <= eps() || o > scene.max_offset) return;
  offsetSteps += steps;
}
// A shader with other eps and offset: they are baked into its parameters' constant
// (kernels/scene_shader.cpp, baked_params: method, max_steps, polygons, convex, eps, offset, ...).
function withParams(source, e, o) {
  const glslFloat = (x) => x.toExponential(8);
  return source.replace(/(const KernelParams params = KernelParams\(\s*[^,]+,\s*[^,]+,\s*[^,]+,\s*[^,]+,\s*)[^,]+,\s*[^,]+,/,
                        (all, head) => head + glslFloat(e) + ", " + glslFloat(o) + ",");
}

// The kernel's shape (kernels/march_params.hpp, KernelShape): ?shape=software or gpu, else by the
// renderer WebGL names. A software rasteriser (Chromium's SwiftShader, Mesa's llvmpipe) runs
// every branch for every lane, and gets the kernel shaped for that; a GPU gets the gpu shape.
function softwareRenderer() {
  const debug = gl && gl.getExtension("WEBGL_debug_renderer_info");
  const name = gl ? String(gl.getParameter(debug ? debug.UNMASKED_RENDERER_WEBGL : gl.RENDERER)) : "";
  return /swiftshader|llvmpipe|softpipe|software/i.test(name);
}
const shape = query.get("shape") || (softwareRenderer() ? "software" : "gpu");
if (shape !== "software" && shape !== "gpu") fail("?shape= wants software or gpu, got " + shape);
// Our own shaders in the page's shape: the gpu shape's define after the version line.
const shaped = (source) =>
  shape === "gpu" ? source.replace(/^(#version[^\n]*\n)/, "$1#define FLATMARCH_GPU_SHAPE\n") : source;

const programs = {};
// A method's program (its shader in scene.shaders, with the eps and offset of the keys), or
// `source` under `name`: the page's own in its shape, or `foreign` (the original app's) as it is.
function program(name, source, foreign = false) {
  if (!source && (epsSteps || offsetSteps)) {
    const key = name + "@" + epsSteps + "," + offsetSteps;
    if (!programs[key]) programs[key] = link(shaped(withParams(scene.shaders[name], eps(), offset())));
    return programs[key];
  }
  if (!programs[name]) {
    const fragment = source || scene.shaders[name];
    programs[name] = link(foreign ? fragment : shaped(fragment));
  }
  return programs[name];
}
function link(fragment) {
  const p = gl.createProgram();
  gl.attachShader(p, compile(gl.VERTEX_SHADER, scene.vertex_shader));
  gl.attachShader(p, compile(gl.FRAGMENT_SHADER, fragment));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error("link: " + gl.getProgramInfoLog(p));
  const u = {};
  for (const n of ["u_polygon", "u_from", "u_forward", "u_right", "u_up", "u_scale", "u_size", "u_rows"])
    u[n] = gl.getUniformLocation(p, n);
  return { p, u };
}

// Sets a program's camera uniforms for a w x h frame; `rows` as kernels/scene_shader.hpp says
// (a canvas: [h, -1], its row 0 at the top; a read-back: [0, 1]).
// A camera may bring its basis and scale made already (c.basis: forward, right, up, scale), as
// the webgl backend does, with the values of the other backends' uniforms.
function setCamera(u, c, w, h, rows) {
  const t = Math.tan(c.fov_deg * Math.PI / 360);
  const { f, r, u: up } = c.basis ? { f: c.basis.forward, r: c.basis.right, u: c.basis.up } : basis(c);
  const scale = c.basis ? c.basis.scale : [(w / h) * t, t];
  gl.uniform1i(u.u_polygon, c.polygon);
  gl.uniform3fv(u.u_from, c.position);
  gl.uniform3fv(u.u_forward, f);
  gl.uniform3fv(u.u_right, r);
  gl.uniform3fv(u.u_up, up);
  gl.uniform2f(u.u_scale, scale[0], scale[1]);
  gl.uniform2f(u.u_size, w, h);
  gl.uniform2f(u.u_rows, rows[0], rows[1]);
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
// Draws a frame of `prog` on the canvas at w x h, `set` setting its uniforms, and returns its
// milliseconds: a one-pixel read waits for it (gl.finish does not, in a browser).
function drawFrame(prog, set, w, h) {
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  gl.viewport(0, 0, w, h);
  gl.useProgram(prog.p);
  set(prog.u);
  const start = performance.now();
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, probe);
  return performance.now() - start;
}

function draw() {
  const [w, h] = size();
  lastMs = drawFrame(program(method), (u) => setCamera(u, camera, w, h, [h, -1]), w, h);
  showHud(w, h);
}

// Times n frames on the canvas at w x h, as a visitor sees them (benchmarks:
// bench/web_bench.cpp): the page's shader of `method` from camera `c`, or `fragment`, another
// GLSL ES 3.00 fragment shader (the original app's) under the page's vertex shader, with
// `uniforms` (name -> numbers). Returns each frame's milliseconds; the first call compiles.
window.flatmarchTimeFrames = ({ method: m = method, camera: c = camera, fragment, uniforms, w, h, n = 1 }) => {
  document.body.classList.add("frame");
  let prog, set;
  if (fragment) {
    prog = program("fragment:" + fragment, fragment, true);
    const setters = [gl.uniform1fv, gl.uniform2fv, gl.uniform3fv, gl.uniform4fv];
    set = () => {
      for (const [name, v] of Object.entries(uniforms || {}))
        setters[v.length - 1].call(gl, gl.getUniformLocation(prog.p, name), v);
    };
  } else {
    if (!scene.shaders[m]) throw new Error("this page has no shader for " + m);
    prog = program(m);
    set = (u) => setCamera(u, c, w, h, [h, -1]);
  }
  const times = [];
  for (let k = 0; k < n; ++k) times.push(drawFrame(prog, set, w, h));
  const error = gl.getError();
  if (error !== gl.NO_ERROR) throw new Error("WebGL error " + error);
  return times;
};

function showHud(w, h) {
  hud.innerHTML = "<b>" + scene.name + "</b> &middot; " + method + ", eps " + eps().toPrecision(3) +
    ", offset " + offset().toPrecision(3) + " &middot; " + w + "&times;" + h + ", " + lastMs.toFixed(1) + " ms<br>" +
    "W/A/S/D walk, E/Q up and down (Shift: faster) &middot; click to look with the mouse (Esc frees it), " +
    "or drag, or arrow keys &middot; touch: drag to look, two fingers to move &middot; " +
    "1 sphere, 2 relaxed, 3 analytic &middot; [ ] eps, ; ' offset &middot; wheel: field of view (" +
    camera.fov_deg.toFixed(0) + "&deg;) &middot; - + resolution &middot; M map &middot; P screenshot &middot; H hide this";
  drawInset();
}

// The floor-plan inset (scene.floor_plan: the plan of `flatmarch plan`, its title left out) with
// the camera on it, a dot and a line along its heading, as the viewer draws it.
const inset = document.getElementById("inset");
const plan = scene.floor_plan;
let planImage = null;
if (plan) {
  planImage = new Image();
  planImage.onload = () => drawInset();
  planImage.src = "data:image/svg+xml;charset=utf-8," + encodeURIComponent(plan.svg);
  inset.hidden = false;
}
function drawInset() {
  if (!plan || inset.hidden || !planImage.complete) return;
  const ratio = window.devicePixelRatio || 1;
  const w = Math.round(Math.min(plan.width, inset.clientWidth || plan.width) * ratio);
  const k = w / plan.width, h = Math.round((plan.height - plan.title_height) * k);
  if (inset.width !== w || inset.height !== h) { inset.width = w; inset.height = h; }
  const c = inset.getContext("2d");
  c.drawImage(planImage, 0, plan.title_height, plan.width, plan.height - plan.title_height, 0, 0, w, h);
  const x = (plan.origin[0] + plan.scale * camera.position[0]) * k;
  const y = (plan.origin[1] - plan.scale * camera.position[1] - plan.title_height) * k;
  const a = camera.yaw_deg * Math.PI / 180, reach = 14 * ratio;
  c.strokeStyle = "#d00"; c.fillStyle = "#d00"; c.lineWidth = 2 * ratio;
  c.beginPath(); c.moveTo(x, y); c.lineTo(x + reach * Math.cos(a), y - reach * Math.sin(a)); c.stroke();
  c.beginPath(); c.arc(x, y, 4 * ratio, 0, 2 * Math.PI); c.fill();
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

// Walking (a port of motion/walk.cpp: the same rules, in double precision): the horizontal path
// is followed across glued edges, each crossing mapping the point and the rest of the path by
// the edge's gluing and turning the yaw with it; mirrors and walls stop the walker kWalkMargin
// short and the rest slides along them; a vertex stops it; z stays inside the band, or is taken
// modulo the period of a prism; above or below the band the walker flies.
const W = scene.walk;
const { margin: kWalkMargin, max_segments: kMaxSegments, reach: kWalkReach } = W;
const kVertexRadius = 1e-6, kPush = 1e-9;  // as motion/walk.cpp's own
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
// says "flatmarch: walked " and the camera as JSON (tests compare it with motion/walk.cpp's).
let walked = null;
if (query.get("walk") !== null) {
  let crossings = 0;
  for (const step of query.get("walk").split(";").filter((x) => x))
    crossings += walk(camera, ...step.split(",").map(Number)).crossings;
  walked = JSON.stringify(
    { polygon: camera.polygon, position: camera.position, yaw_deg: camera.yaw_deg, crossings });
}
// A key press as the viewer takes it (W/A/S/D and E/Q one stride each); whether it was one.
function press(e) {
  const keys = {
    ArrowLeft: () => look(5, 0), ArrowRight: () => look(-5, 0),
    ArrowUp: () => look(0, 5), ArrowDown: () => look(0, -5),
    w: () => walk(camera, stride(e), 0, 0), s: () => walk(camera, -stride(e), 0, 0),
    d: () => walk(camera, 0, stride(e), 0), a: () => walk(camera, 0, -stride(e), 0),
    e: () => walk(camera, 0, 0, stride(e)), q: () => walk(camera, 0, 0, -stride(e)),
    "1": () => setMethod("sphere"), "2": () => setMethod("relaxed"), "3": () => setMethod("analytic"),
    "[": () => stepEps(-1), "]": () => stepEps(1),
    ";": () => stepOffset(-1), "'": () => stepOffset(1),
    m: () => { inset.hidden = !plan || !inset.hidden; }, M: () => { inset.hidden = !plan || !inset.hidden; },
    "-": () => { renderScale = Math.max(0.125, renderScale / 2); },
    "+": () => { renderScale = Math.min(2, renderScale * 2); },
    "=": () => { renderScale = Math.min(2, renderScale * 2); },
    p: screenshot, P: screenshot,
    h: () => { hud.hidden = !hud.hidden; }, H: () => { hud.hidden = !hud.hidden; },
  };
  const key = e.key.length === 1 && /[wasdeq]/i.test(e.key) ? e.key.toLowerCase() : e.key;
  if (!keys[key]) return false;
  keys[key]();
  return true;
}
function setMethod(name) {
  if (scene.shaders[name]) method = name;  // a page exported with its shader
}
// What the controls have set, for tests that drive the page (web/tests/web_page_test.cpp).
window.flatmarchState = () => ({ camera, method, eps: eps(), offset: offset(),
                                 inset: plan ? !inset.hidden : null });
// ?keys=K,K,...: these key presses first (tests: `]` raises eps a quarter decade).
for (const key of (query.get("keys") || "").split(",").filter((k) => k))
  press({ key, shiftKey: false });

// Read-back mode (web/page.hpp, PageOptions::readback): the page opened with ?readback draws
// nothing by itself and offers window.flatmarchReadback to a driver (the webgl backend,
// backends/webgl, through the DevTools protocol). Frames go to float targets (WebGL2's
// EXT_color_buffer_float) and come back as base64 of their float32 values, little-endian.
const readback = scene.readback && query.has("readback");
if (readback && gl) {
  const floatTargets = gl.getExtension("EXT_color_buffer_float");
  let targets = null;  // { w, h, n, fb }: the framebuffer of the last size and count
  function bindTargets(w, h, n) {
    if (!floatTargets) throw new Error("this browser's WebGL2 cannot draw to float targets (EXT_color_buffer_float)");
    if (!targets || targets.w !== w || targets.h !== h || targets.n !== n) {
      if (targets) { gl.deleteFramebuffer(targets.fb); targets.textures.forEach((t) => gl.deleteTexture(t)); }
      const fb = gl.createFramebuffer(), textures = [];
      gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
      for (let k = 0; k < n; ++k) {
        const t = gl.createTexture();
        gl.bindTexture(gl.TEXTURE_2D, t);
        gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, w, h);
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + k, gl.TEXTURE_2D, t, 0);
        textures.push(t);
      }
      const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
      if (status !== gl.FRAMEBUFFER_COMPLETE) throw new Error("float targets incomplete: " + status);
      targets = { w, h, n, fb, textures };
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, targets.fb);
    gl.drawBuffers(targets.textures.map((t, k) => gl.COLOR_ATTACHMENT0 + k));
    gl.viewport(0, 0, w, h);
  }
  function readTarget(k, w, h) {
    const out = new Float32Array(4 * w * h);
    gl.readBuffer(gl.COLOR_ATTACHMENT0 + k);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, out);
    return out;
  }
  function base64(floats) {
    const bytes = new Uint8Array(floats.buffer, floats.byteOffset, floats.byteLength);
    let s = "";
    for (let i = 0; i < bytes.length; i += 0x8000)
      s += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
    return btoa(s);
  }
  function checked(result) {
    const e = gl.getError();
    if (e !== gl.NO_ERROR) throw new Error("WebGL error " + e);
    return result;
  }
  window.flatmarchReadback = {
    // A w x h frame from camera `c` (as scene.camera, or with c.basis): its linear colour (rgba) and AOVs (steps,
    // crossings, hit, t), rows from the top; `ms` is the page's own time for the draw and the
    // read-back of both targets (not the transfer to the driver).
    render(c, w, h) {
      const { p, u } = program("readback", scene.readback.render);
      bindTargets(w, h, 2);
      gl.useProgram(p);
      setCamera(u, c, w, h, [0, 1]);
      const start = performance.now();
      gl.drawArrays(gl.TRIANGLES, 0, 3);
      const colour = readTarget(0, w, h), aov = readTarget(1, w, h);
      const ms = performance.now() - start;
      return checked({ ms, colour: base64(colour), aov: base64(aov) });
    },
    // The probe ray from `from` along `dir` in `polygon`: its first `count` events (at least
    // one fragment, for the steps and the count of events), as kernels/scene_shader.hpp's
    // WebShader::trace lays them out, in three arrays.
    trace(polygon, from, dir, count) {
      const { p, u } = program("trace", scene.readback.trace);
      const n = Math.max(1, count), w = Math.min(n, 1024), h = Math.ceil(n / w);
      bindTargets(w, h, 3);
      gl.useProgram(p);
      setCamera(u, { polygon, position: from, basis: { forward: dir, right: [0, 0, 0], up: [0, 0, 0],
                                                      scale: [1, 1] } }, w, h, [0, 1]);
      gl.drawArrays(gl.TRIANGLES, 0, 3);
      return checked({ w, h, kind: base64(readTarget(0, w, h)), more: base64(readTarget(1, w, h)),
                       at: base64(readTarget(2, w, h)) });
    },
  };
  document.body.classList.add("frame");
}

if (readback) {
  // The driver draws.
} else if (walked !== null && !frame) {
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
  // The mouse: a click locks the pointer and then it looks, as in the viewer (Esc frees it);
  // where the lock is refused, dragging looks. Touch: one finger drags to look, two drag to move
  // (up the screen forward, sideways to the side).
  const perPixel = scene.degrees_per_pixel;
  const touches = new Map();  // pointerId -> [x, y]
  const locked = () => document.pointerLockElement === canvas;
  let drag = null;
  const centroid = () => {
    let x = 0, y = 0;
    for (const [px, py] of touches.values()) { x += px; y += py; }
    return [x / touches.size, y / touches.size];
  };
  canvas.addEventListener("pointerdown", (e) => {
    if (e.pointerType === "touch") {
      touches.set(e.pointerId, [e.clientX, e.clientY]);
    } else if (!locked()) {
      drag = [e.clientX, e.clientY];
      if (canvas.requestPointerLock) {
        const request = canvas.requestPointerLock();
        if (request && request.catch) request.catch(() => {});  // refused: dragging looks
      }
    }
    canvas.setPointerCapture(e.pointerId);
  });
  const release = (e) => { touches.delete(e.pointerId); drag = null; };
  canvas.addEventListener("pointerup", release);
  canvas.addEventListener("pointercancel", release);
  canvas.addEventListener("pointermove", (e) => {
    if (e.pointerType === "touch") {
      if (!touches.has(e.pointerId)) return;
      const before = centroid(), one = touches.size === 1;
      touches.set(e.pointerId, [e.clientX, e.clientY]);
      const after = centroid(), dx = after[0] - before[0], dy = after[1] - before[1];
      if (one) look(-2 * perPixel * dx, -2 * perPixel * dy);
      else if (touches.size === 2) { walk(camera, -dy * W.scale / 200, dx * W.scale / 200, 0); redraw(); }
    } else if (locked()) {
      look(-perPixel * e.movementX, -perPixel * e.movementY);
    } else if (drag) {
      look(-2 * perPixel * (e.clientX - drag[0]), -2 * perPixel * (e.clientY - drag[1]));
      drag = [e.clientX, e.clientY];
    }
  });
  canvas.addEventListener("wheel", (e) => {
    camera.fov_deg = Math.max(10, Math.min(150, camera.fov_deg + (e.deltaY > 0 ? 5 : -5)));
    redraw();
    e.preventDefault();
  }, { passive: false });
  window.addEventListener("keydown", (e) => {
    if (press(e)) { redraw(); e.preventDefault(); }
  });
  window.addEventListener("resize", redraw);
  redraw();
}
