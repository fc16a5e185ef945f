#include "kernels/scene_shader.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <type_traits>

#include "kernels/shader_source.hpp"

namespace flatmarch::kernel {

namespace {

// Up to this many objects, a baked shader finds a hit solid's normal with the solid's shape known.
constexpr size_t kFewObjects = 4;

// Nine significant digits read back as the same float; always a float literal ("2.0", not "2"),
// which GLSL ES (the web export) needs where a structure's constructor takes a float.
std::string number(float x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", static_cast<double>(x));
  std::string s = text;
  if (s.find_first_of(".eEni") == std::string::npos) s += ".0";
  return s;
}

std::string vec4_literal(const glm::vec4& v) {
  return "vec4(" + number(v.x) + ", " + number(v.y) + ", " + number(v.z) + ", " + number(v.w) + ")";
}

std::string ivec4_literal(const ivec4& v) {
  return "ivec4(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) +
         ", " + std::to_string(v.w) + ")";
}

// `const T name[N] = T[N](...);` GLSL has no empty arrays: an empty table gets one zero record
// that the kernel never reads (it reads only the runs the polygons name).
template <typename Record, typename F>
std::string array(bool constant, const char* type, const char* name,
                  const std::vector<Record>& records, const std::string& zero, F&& literal) {
  const size_t n = records.empty() ? 1 : records.size();
  std::string s = std::string(constant ? "const " : "") + type + " " + name + "[" +
                  std::to_string(n) + "] = " + type + "[" + std::to_string(n) + "](\n";
  for (size_t k = 0; k < n; ++k) {
    s += "    " + (records.empty() ? zero : literal(records[k]));
    s += k + 1 < n ? ",\n" : ");\n";
  }
  return s;
}

const char* const kFragmentMain = R"glsl(
uniform int u_polygon;
uniform vec3 u_from;
uniform vec3 u_forward;
uniform vec3 u_right;
uniform vec3 u_up;
uniform vec2 u_scale;
uniform vec2 u_size;
uniform vec2 u_rows;  // the pixel's row from the top is u_rows.x + u_rows.y * gl_FragCoord.y

#ifdef FLATMARCH_COLOUR8
layout(location = 0) out uint out_srgb;  // packUnorm4x8 of the sRGB colour
#else
layout(location = 0) out vec4 out_color;
#endif
#if defined(FLATMARCH_PACKED_AOVS)
layout(location = 1) out uvec4 out_aov;  // steps, crossings, hit (two's complement), t's bits
#elif !defined(FLATMARCH_CANVAS) && !defined(FLATMARCH_COLOUR8)
layout(location = 1) out vec4 out_aov;
#endif
#ifdef FLATMARCH_TRACE_PICK
layout(location = 2) out vec4 out_at;
#endif

void main() {
#if defined(FLATMARCH_TRACE)
  Ray r = march(u_polygon, u_from, u_forward);
  trace_steps = r.steps;
  out_color = vec4(0.0);
  out_aov = vec4(0.0);
#elif defined(FLATMARCH_TRACE_PICK)
  // Fragment k (row by row) marches the probe ray and keeps its k-th event: the event, then
  // (to_edge, object, the ray's steps, its event count), then the point and t.
  trace_pick = int(gl_FragCoord.y) * int(u_size.x) + int(gl_FragCoord.x);
  Ray r = march(u_polygon, u_from, u_forward);
  out_color = vec4(picked_event.kind);
  out_aov = vec4(vec2(picked_event.more.xy), float(r.steps), float(event_count));
  out_at = picked_event.at;
#else
  // DESIGN.md section 2: x from the left, y from the top, through the pixel's centre
  // (gl_FragCoord is at the centre). The image's top row is OpenGL's top row (u_rows = (height,
  // -1)), or its first row in memory, row 0 (u_rows = (0, 1)), as a read-back wants it.
  vec2 p = vec2(gl_FragCoord.x, u_rows.x + u_rows.y * gl_FragCoord.y);
  float u = (2.0 * p.x / u_size.x - 1.0) * u_scale.x;
  float v = (1.0 - 2.0 * p.y / u_size.y) * u_scale.y;
  Ray r = march(u_polygon, u_from, normalize(u_forward + u * u_right + v * u_up));
#if defined(FLATMARCH_CANVAS)
  out_color = vec4(srgb(shade(r)), 1.0);
#elif defined(FLATMARCH_COLOUR8)
  out_srgb = packUnorm4x8(vec4(srgb(shade(r)), 1.0));
#elif defined(FLATMARCH_PACKED_AOVS)
  out_color = vec4(shade(r), 1.0);
  out_aov = uvec4(uint(r.steps), uint(r.crossings), uint(r.hit), floatBitsToUint(r.t));
#else
  out_color = vec4(shade(r), 1.0);
  out_aov = vec4(float(r.steps), float(r.crossings), float(r.hit), r.t);
#endif
#endif
}
)glsl";

// The compute shaders' main() (see scene_compute_shader). The pixel's ray is computed as the
// fragment shader computes it.
const char* const kComputeMain = R"glsl(
#ifdef FLATMARCH_GL_COMPUTE
layout(std140, binding = 0) uniform Constants {
#else
layout(push_constant) uniform Constants {
#endif
  vec4 from;
  vec4 forward;
  vec4 right;
  vec4 up;
  vec4 scale;
  ivec4 frame;  // width, height, first row, polygon
  ivec4 order;  // x: the stride of the rows of workgroups (row_stride); y: 1 the colour alone
} pc;

#ifdef FLATMARCH_TRACE
layout(local_size_x = 1) in;
void main() {
  Ray r = march(pc.frame.w, pc.from.xyz, pc.forward.xyz);
  trace_steps = r.steps;
}
#else
layout(local_size_x = TILE, local_size_y = TILE) in;
// One buffer in two views. A frame of the colour alone: a uint a pixel (packUnorm4x8 of the sRGB
// colour); a whole frame: the linear colour's float bits, a uvec4 a pixel, then the AOVs, a uvec4
// a pixel. One program writes either (pc.order.y), so that a scene has one frame program to
// compile, not two.
layout(std430, binding = 5) writeonly buffer Pixels { uvec4 pixels[]; };
layout(std430, binding = 5) writeonly buffer Colours { uint colours[]; };
void main() {
  // The workgroups' rows draw the band's rows of tiles in a spread order (row_stride).
  uint row = (gl_WorkGroupID.y * uint(pc.order.x)) % gl_NumWorkGroups.y;
  ivec2 p = ivec2(ivec2(gl_WorkGroupID.x, row) * TILE + ivec2(gl_LocalInvocationID.xy)) +
            ivec2(0, pc.frame.z);
  if (p.x < pc.frame.x && p.y < pc.frame.y) {
    vec2 size = vec2(pc.frame.xy);
    float u = (2.0 * (float(p.x) + 0.5) / size.x - 1.0) * pc.scale.x;
    float v = (1.0 - 2.0 * (float(p.y) + 0.5) / size.y) * pc.scale.y;
    Ray r = march(pc.frame.w, pc.from.xyz,
                  normalize(pc.forward.xyz + u * pc.right.xyz + v * pc.up.xyz));
    vec3 color = shade(r);
    uint px = uint(p.y) * uint(pc.frame.x) + uint(p.x);
    if (pc.order.y != 0) {
      colours[px] = packUnorm4x8(vec4(srgb(color), 1.0));
    } else {
      uint n = uint(pc.frame.x) * uint(pc.frame.y);
      pixels[px] = floatBitsToUint(vec4(color, 1.0));
      pixels[n + px] = uvec4(uint(r.steps), uint(r.crossings), uint(r.hit), floatBitsToUint(r.t));
    }
  }
}
#endif
)glsl";

}  // namespace

int row_stride(int rows) {
  if (rows <= 2) return 1;
  int stride = static_cast<int>(std::lround(0.6180339887498949 * rows));
  while (std::gcd(stride, rows) != 1) ++stride;
  return stride;
}

std::string baked_params(const Tables<float>::KernelParams& p) {
  // In the order of KernelParams' fields (kernels/tables.glsl). The web page's eps and offset keys
  // rewrite the fifth and sixth (web/page.js, withParams).
  return "const KernelParams params = KernelParams(\n    " + std::to_string(p.method) + ", " +
         std::to_string(p.max_steps) + ", " + std::to_string(p.polygon_count) + ", " +
         std::to_string(p.convex) + ",\n    " + number(p.eps) + ", " + number(p.offset) + ", " +
         number(p.max_distance) + ", " + number(p.omega) + ",\n    " + number(p.height) + ", " +
         number(p.top) + ", " + number(p.vertex_tolerance) + ", " + number(p.fog_distance) +
         ",\n    " + vec4_literal(p.fog) + ", " + vec4_literal(p.sky) + ", " +
         vec4_literal(p.ground) + ", " + vec4_literal(p.wall) + ", " +
         vec4_literal(p.floor_colour) + ", " + vec4_literal(p.period_tint) + ",\n    " +
         vec4_literal(p.seams) + ", " + vec4_literal(p.seam_colour) + ", " +
         vec4_literal(p.cone_colour) + ");\n";
}

std::string baked_tables(const SceneTables<float>& tables, bool constant_arrays) {
  using Edge = Tables<float>::EdgeRecord;
  using Object = Tables<float>::ObjectRecord;
  const std::string zero4 = "vec4(0.0)", zeroi = "ivec4(0)";
  std::string s = "\n// The scene's tables, baked in.\n";
  s += array(constant_arrays, "ivec4", "polygons", tables.polygons, zeroi, ivec4_literal);
  s += array(constant_arrays, "EdgeRecord", "edges", tables.edges,
             "EdgeRecord(" + zero4 + ", " + zero4 + ", " + zero4 + ", " + zero4 + ", " + zeroi +
                 ", " + zero4 + ", " + zero4 + ")",
             [](const Edge& e) {
               return "EdgeRecord(" + vec4_literal(e.segment) + ", " + vec4_literal(e.line) + ", " +
                      vec4_literal(e.map_linear) + ", " + vec4_literal(e.map_shift) + ", " +
                      ivec4_literal(e.link) + ", " + vec4_literal(e.tint) + ", " +
                      vec4_literal(e.seam) + ")";
             });
  s += array(constant_arrays, "ObjectRecord", "objects", tables.objects,
             "ObjectRecord(" + zero4 + ", " + zero4 + ", " + zero4 + ", " + zeroi + ")",
             [](const Object& o) {
               return "ObjectRecord(" + vec4_literal(o.center) + ", " + vec4_literal(o.shape) +
                      ", " + vec4_literal(o.color) + ", " + ivec4_literal(o.info) + ")";
             });
  // kernels/march.glsl's solid_look then evaluates each solid's normal with its shape known.
  if (tables.objects.size() <= kFewObjects) s += "#define FLATMARCH_FEW_OBJECTS\n";
  return s + baked_params(tables.params);
}

bool tables_in_buffer(const SceneTables<float>& tables) {
  return tables.polygons.size() > 1;
}

namespace {

// Appends a table's records, or one zero record where it has none (as `array` declares it).
template <typename Record>
void append_records(std::string& bytes, const std::vector<Record>& records) {
  static_assert(sizeof(Record) % 16 == 0, "std430 lays the records out as C++ does");
  if (records.empty()) {
    bytes.append(sizeof(Record), '\0');
    return;
  }
  bytes.append(reinterpret_cast<const char*>(records.data()), records.size() * sizeof(Record));
}

// The tables' declaration in a shader that reads them from the table buffer: one block of the
// three arrays at their sizes (so that a loop over the objects still has a constant bound).
std::string buffered_tables(const SceneTables<float>& tables) {
  const auto count = [](size_t n) { return std::to_string(std::max<size_t>(n, 1)); };
  std::string s = "\n// The scene's tables, from the table buffer (several rooms).\n";
  s += "layout(std430, binding = " + std::to_string(kTableBinding) +
       ") readonly buffer SceneTableBuffer {\n  ivec4 polygons[" + count(tables.polygons.size()) +
       "];\n  EdgeRecord edges[" + count(tables.edges.size()) + "];\n  ObjectRecord objects[" +
       count(tables.objects.size()) + "];\n};\n";
  if (tables.objects.size() <= kFewObjects) s += "#define FLATMARCH_FEW_OBJECTS\n";
  return s + baked_params(tables.params);
}

// A frame or trace shader's tables: baked in (`const` arrays or plain ones) or from the buffer.
std::string scene_tables(const SceneTables<float>& tables, bool constant_arrays) {
  return tables_in_buffer(tables) ? buffered_tables(tables) : baked_tables(tables, constant_arrays);
}

}  // namespace

bool shared_trace(const SceneTables<float>& tables) {
  return tables.polygons.size() <= kTracePolygons && tables.objects.size() <= kTraceObjects;
}

std::string table_buffer(const SceneTables<float>& tables, bool trace) {
  std::string bytes;
  if (trace && shared_trace(tables)) {  // as shared_trace_tables() declares them
    static_assert(std::is_trivially_copyable_v<Tables<float>::KernelParams>);
    bytes.append(reinterpret_cast<const char*>(&tables.params), sizeof tables.params);
    const std::array<uint, 4> scene{tables.features, 0u, 0u, 0u};
    bytes.append(reinterpret_cast<const char*>(scene.data()), sizeof scene);
    const auto padded = [&](const auto& records, size_t bound) {
      using Record = typename std::decay_t<decltype(records)>::value_type;
      const size_t start = bytes.size();
      append_records(bytes, records);
      bytes.resize(start + bound * sizeof(Record), '\0');
    };
    padded(tables.polygons, kTracePolygons);
    padded(tables.objects, kTraceObjects);
    append_records(bytes, tables.edges);
    return bytes;
  }
  if (!tables_in_buffer(tables)) return bytes;
  append_records(bytes, tables.polygons);
  append_records(bytes, tables.edges);
  append_records(bytes, tables.objects);
  return bytes;
}

namespace {

// The tables of a trace that scenes share (shared_trace), read from the table buffer with the
// parameters and the scene's features: what table_buffer(tables, true) holds. The edges, of any
// number, come last.
std::string shared_trace_tables() {
  const auto n = [](size_t bound) { return std::to_string(bound); };
  return "\n// A trace shared by scenes: their tables, parameters and features from the table "
         "buffer.\nlayout(std430, binding = " +
         std::to_string(kTableBinding) +
         ") readonly buffer SceneTraceBuffer {\n  KernelParams params;\n  uvec4 trace_scene;  // "
         "x: the scene's features\n  ivec4 polygons[" +
         n(kTracePolygons) + "];\n  ObjectRecord objects[" + n(kTraceObjects) +
         "];\n  EdgeRecord edges[];\n};\n#define FEATURES (trace_scene.x)\n";
}

// A shared trace's variant: the gpu shape whatever the backend's (its loops test first, and it
// picks no edge from constants), since what the software shape saves is in the frames of a
// software rasteriser, not in one ray; on llvmpipe and lavapipe it compiled in a quarter of the
// time (2-vCPU Intel Xeon, caches empty: Vulkan 5.8 -> 1.0-1.5 s, OpenGL 2.8 -> 0.7 s).
ShaderVariant shared_trace_variant(const ShaderVariant& v) {
  ShaderVariant shared = v;
  shared.shape = KernelShape::gpu;
  return shared;
}

// The defines that pick a variant's code, after the baked tables.
std::string variant_defines(const ShaderVariant& v) {
  std::string s;
  if (v.from_band && !v.trace) s += "#define FLATMARCH_FROM_BAND\n";
  if (v.shape == KernelShape::gpu) s += "#define FLATMARCH_GPU_SHAPE\n";
  // The fragment shader's outputs; the compute shader writes either read-back (kComputeMain).
  if (!v.trace && v.readback == Readback::colour) s += "#define FLATMARCH_COLOUR8\n";
  if (!v.trace && v.readback == Readback::all) s += "#define FLATMARCH_PACKED_AOVS\n";
  return s;
}

}  // namespace

bool within_band(const SceneTables<float>& tables, const glm::dvec3& position) {
  const float z = static_cast<float>(position.z);  // as the shader receives it
  return !(z < 0.0f || z > tables.params.height);
}

std::string scene_fragment_shader(const SceneTables<float>& tables, const ShaderVariant& v) {
  if (v.trace && shared_trace(tables))
    return shader_source(kFeaturesInTables,
                         shared_trace_tables() + variant_defines(shared_trace_variant(v)), true) +
           kFragmentMain;
  return shader_source(tables.features, scene_tables(tables, true) + variant_defines(v), v.trace) +
         kFragmentMain;
}

std::string scene_compute_shader(const SceneTables<float>& tables, const ShaderVariant& v,
                                 ComputeApi api) {
  // One program for both read-backs (ComputeConstants::order.y picks the outputs).
  ShaderVariant compute = v;
  compute.readback = Readback::floats;
  const bool shared = v.trace && shared_trace(tables);
  if (shared) compute = shared_trace_variant(compute);
  return shader_source(shared ? kFeaturesInTables : tables.features,
                       (shared ? shared_trace_tables() : scene_tables(tables, false)) +
                           variant_defines(compute),
                       v.trace) +
         (api == ComputeApi::opengl ? "#define FLATMARCH_GL_COMPUTE\n" : "") + "#define TILE " +
         std::to_string(kComputeTile) + "\n" + kComputeMain;
}

namespace {

// GLSL ES 3.00 (WebGL2) in place of the first line's desktop version, with `defines`.
std::string as_glsl_es(const std::string& source, const std::string& defines) {
  const size_t end = source.find('\n');
  return "#version 300 es\n" + defines + "precision highp float;\nprecision highp int;\n" +
         source.substr(end + 1);
}

}  // namespace

std::string web_fragment_shader(const SceneTables<float>& tables, WebShader kind) {
  const char* const defines[] = {"#define FLATMARCH_CANVAS\n", "",
                                 "#define FLATMARCH_TRACE_PICK\n"};
  // Plain global arrays, not constants: SwiftShader (Chromium's WebGL without a GPU) crashes its
  // GPU process on a struct read from a constant array at an index known only at run time.
  return as_glsl_es(shader_source(tables.features, baked_tables(tables, false)) + kFragmentMain,
                    defines[static_cast<int>(kind)]);
}

const char* const kWebVertexShader = R"glsl(#version 300 es
// One triangle that covers the viewport.
void main() {
  vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
)glsl";

const char* const kFullScreenVertexShader = R"glsl(#version 450
// One triangle that covers the viewport.
void main() {
  vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
)glsl";

}  // namespace flatmarch::kernel
