// A scene's own shader: the kernel specialised on the scene's features with its compiled tables
// baked in as constants (kernels/shader_source.hpp), and a main() that marches one pixel (or one
// probe ray). The OpenGL backend, the viewer and `flatmarch shader` use it.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "kernels/compile.hpp"

namespace flatmarch::kernel {

// The tables as GLSL constant arrays and the parameters as a constant, with exactly the values
// of `tables` (printed so that they read back as the same floats). Baked in, they let the
// compiler drop what this scene and these parameters never run (the other methods' code above
// all): GPU compilers and llvmpipe run both sides of a branch that is not known to be uniform.
// A change of parameters is a new program.
// `constant_arrays`: declare the tables `const` (false: plain globals with the same initialisers).
std::string baked_tables(const SceneTables<float>& tables, bool constant_arrays = true);

// Where a scene's shader reads its tables. One room: baked in (baked_tables), its loops over the
// room's edges unrolled and their reads folded into constants. Several rooms: from a read-only
// storage buffer (binding kTableBinding, table_buffer's bytes), since a ray's room is known only
// at run time. Baked, such tables are arrays that every invocation fills before it marches, and
// LLVM's code generation for llvmpipe and lavapipe grows steeply with them: on a 2-vCPU Intel
// Xeon (AVX-512, Mesa 22.3.6, LLVM 15, 256-bit vectors) a Vulkan frame program of the cube (six
// rooms) compiled in 15.8 s, from the buffer in 0.3 s. Its frames are the same pixels, but the
// buffer's reads are dearer there than the arrays' (per lane, bounds-checked): the several-room
// gallery scenes' frames a median 1.3-1.4x as long (docs/vulkan.md). On a GPU a dynamically indexed
// array is per-thread scratch memory, and a buffer the usual place for such tables (not measured
// here). The parameters are baked in either way.
bool tables_in_buffer(const SceneTables<float>& tables);
constexpr int kTableBinding = 6;
// The buffer's bytes (std430): polygons, edges, objects, as the block scene_fragment_shader and
// scene_compute_shader declare them (an empty table is one zero record); empty where the
// tables are baked in. For a `trace` shared by scenes (shared_trace): the parameters, the
// features, the polygons and objects each padded to its table's bound, then the edges.
std::string table_buffer(const SceneTables<float>& tables, bool trace = false);

// A probe ray's trace (ShaderVariant::trace) runs one program that every scene of at most
// kTracePolygons rooms and kTraceObjects objects shares, whatever its method and parameters: the
// tables, the parameters and the scene's features are read from the table buffer (binding
// kTableBinding, table_buffer(tables, true)), not baked in. A trace marches one ray, whose speed
// is not what a case measures; a program per case was half of a first report's compiles (OpenGL
// and Vulkan on llvmpipe and lavapipe, 2-vCPU Intel Xeon: the compile stage 58 s with them, 31 s
// without). The same kernel source, specialised at run time instead of at compile time. A larger
// scene's trace is a program of its own, its tables where its frames have them.
constexpr size_t kTracePolygons = 256, kTraceObjects = 64;
bool shared_trace(const SceneTables<float>& tables);

// What a frame's shader writes, and its backend reads back. A compute shader writes either, as
// ComputeConstants::order.y says, so that a scene compiles one compute program for its frames,
// not two (a first report compiles some 150 on lavapipe). A fragment shader writes one: llvmpipe
// compiles a fragment shader again for each set of targets, and one shader for both moved a first
// report's compiles out of its compile stage into its matrix (OpenGL, 2-vCPU Intel Xeon, cache
// empty: compile stage 29.5 -> 20.3 s, matrix 42.6 -> 52.4 s).
enum class Readback {
  // The colour alone, tone-mapped and sRGB-encoded (as OpenImageIO writes the PNGs): one uint a
  // pixel, packUnorm4x8's, r in the low byte. What a timed frame or a display needs.
  colour,
  // The linear colour's float bits, then the AOVs as integers (steps, crossings, hit as two's
  // complement) and t's float bits: two uvec4 a pixel. What a comparison needs.
  all,
  // The fragment shader for the viewer and the web page's read-back: the linear colour and the
  // AOVs (steps, crossings, hit, t) as floats, in two float targets (a float target can be
  // filtered and mipmapped: the viewer's mean steps). A compute shader has no such variant.
  floats,
};

// Which of a scene's shaders.
struct ShaderVariant {
  // The variant that marches one probe ray (u_polygon, u_from and the direction u_forward) and
  // writes its events to the event buffer (binding 4, see kernels/shader_prelude.glsl).
  bool trace = false;
  // Every ray starts within the band [0, height] (a camera there, not a probe ray): the shader
  // then leaves out how a ray from outside enters the band. llvmpipe and lavapipe run the code of
  // every branch for every pixel, taken or not and uniform or not, and the entry tests the ray
  // against every polygon's footprint (0.4 of the L-shape's 13 ms a 640x360 frame).
  bool from_band = false;
  KernelShape shape = KernelShape::software;  // kernels/march.glsl's FLATMARCH_GPU_SHAPE
  Readback readback = Readback::floats;       // a frame's outputs (not a trace's)
};

// Uniforms of the fragment shader (scene_fragment_shader), and its table buffer where
// tables_in_buffer:
//   u_polygon, u_from         the camera's polygon and position
//   u_forward, u_right, u_up  its basis (kernels/camera.hpp)
//   u_scale                   (aspect * tan(fov / 2), tan(fov / 2))
//   u_size                    the image's width and height in pixels
// Outputs by the variant's readback: colour, location 0 the uint (packUnorm4x8); all, location
// 0 the linear colour (rgb, 1) and 1 the uvec4 of AOVs; floats, 0 the colour and 1 the AOVs as
// a vec4. The trace variant marches one probe ray instead.
std::string scene_fragment_shader(const SceneTables<float>& tables,
                                  const ShaderVariant& variant = {});

// The web page's fragment shaders (web/page.hpp): scene_fragment_shader's kernel, baked tables,
// uniforms and main() in GLSL ES 3.00 for WebGL2. Every ray may start outside the band.
enum class WebShader {
  canvas,    // one output: the colour sRGB-encoded, for the page's canvas
  readback,  // as scene_fragment_shader's: linear colour and the AOVs, for float targets
  // WebGL2 has no storage buffers: a frame of fragments, fragment k (row by row, from the
  // bottom-left) marching the probe ray (u_polygon, u_from, direction u_forward) and writing its
  // k-th event to three float targets: (kind, polygon, edge, to_polygon), (to_edge, object, the
  // ray's steps, its count of events), (the point, t). Past the last event, kind is -1.
  trace,
};
std::string web_fragment_shader(const SceneTables<float>& tables,
                                WebShader kind = WebShader::canvas);
// Its vertex shader: one triangle over the viewport, drawn with 3 vertices and no attributes.
extern const char* const kWebVertexShader;

// Whether a camera at `position` sees from within the band, as the kernel tests it.
bool within_band(const SceneTables<float>& tables, const glm::dvec3& position);

// The compute shader of the Vulkan backend, and of the OpenGL backend's gpu shape: the same
// kernel and tables, one invocation a pixel in workgroups of kComputeTile x kComputeTile, over
// rows frame.z .. of the image (a band). Constants (ComputeConstants: Vulkan's push constants,
// OpenGL's uniform block at binding 0): the camera's position, basis and scale as above, and
// frame = (width, height, first row, polygon). Output: buffer binding 5, rows from the top; by
// ComputeConstants::order.y, `uint colours[]` of the colour (Readback::colour), or `uvec4
// pixels[]`, the colour's bits of every pixel, then the AOVs of every pixel (all; two 16-byte
// stores a pixel ran up to 1.2x faster on lavapipe than seven planar float stores): two views of
// one buffer, one program for both read-backs, whatever the variant's readback. The
// trace variant (one invocation) marches the ray from `from` along `forward` in polygon frame.w
// and writes its events to binding 4 as the fragment shader's does.
// Baked in (one room: tables_in_buffer), its tables are not `const` arrays but plain ones with
// the same initialisers: glslang gives a dynamically indexed `const` array a function-local copy
// at each use (344 in the cube), which lavapipe took 35 s to compile (the plain arrays: 2.4 s, and
// 0.3 s once SPIRV-Tools' optimiser has run, which in turn made the `const` arrays' copies run
// 300x slower). A one-room scene's tables in buffers ran 1.4-15x slower: their loads are not
// folded where the indices are constant.
enum class ComputeApi { vulkan, opengl };
std::string scene_compute_shader(const SceneTables<float>& tables,
                                 const ShaderVariant& variant = {},
                                 ComputeApi api = ComputeApi::vulkan);

// The compute shader's push constants (std430: as laid out in C++).
struct ComputeConstants {
  glm::vec4 from, forward, right, up;  // xyz
  glm::vec4 scale;                     // xy
  glm::ivec4 frame;                    // width, height, first row, polygon
  glm::ivec4 order;                    // x: row_stride(rows of workgroups in the dispatch);
                                       // y: 1 the colour alone (Readback::colour), 0 all
};
static_assert(sizeof(ComputeConstants) == 112);
constexpr int kComputeTile = 8;

// The order in which a dispatch's rows of workgroups draw the band's rows of tiles: row k draws
// row k * stride mod `rows`. lavapipe (Mesa 22.3) hands each of its threads one run of
// consecutive workgroups, so in row order a thread whose run holds the costly part of a frame (a
// grazing view, a far corner) is left to finish alone; the stride, near the golden section of
// `rows` and prime to it, spreads every run over the whole band (sphere tracing on the L-shape at
// 640x360 on two threads: 142 -> 114 ms). A GPU schedules workgroups as it likes: no matter there.
int row_stride(int rows);

// A full-screen triangle, the vertex shader that goes with it.
extern const char* const kFullScreenVertexShader;

}  // namespace flatmarch::kernel
