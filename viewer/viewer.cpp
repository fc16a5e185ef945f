#include "viewer/viewer.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "backends/lru_cache.hpp"
#include "backends/opengl/context.hpp"
#include "backends/opengl/gl_api.hpp"
#include "backends/opengl/gl_kernel.hpp"
#include "kernels/camera.hpp"
#include "kernels/compile.hpp"
#include "kernels/shader_source.hpp"
#include "motion/walk.hpp"
#include "output/image_io.hpp"
#include "scene/load.hpp"
#include "viewer/controls.hpp"
#include "viewer/glfw_api.hpp"
#include "viewer/inset.hpp"

namespace flatmarch::viewer {

using motion::kDegreesPerPixel;
using motion::kFastFactor;
using motion::kSpeedPerScale;
using motion::look;
using motion::MarchSettings;
using motion::RenderScale;
using motion::walk;

namespace {

// Compiled kernel programs kept (one per scene and march settings visited recently).
constexpr size_t kMaxPrograms = 8;
// Seconds between updates of the window title (frame time, mean steps).
constexpr double kTitlePeriod = 0.25;
// Real time one frame moves the camera by at most, so that a stall does not jump it.
constexpr double kMaxFrameTime = 0.1;
// Screenshot file numbers tried for a free name at most.
constexpr int kMaxScreenshotNumber = 100000;

const char* const kPresentVertexShader = R"glsl(#version 450 core
// One triangle that covers the viewport, with texture coordinates.
out vec2 v_uv;
void main() {
  vec2 p = vec2(float((gl_VertexID & 1) << 2), float((gl_VertexID & 2) << 1));
  v_uv = 0.5 * p;
  gl_Position = vec4(p - 1.0, 0.0, 1.0);
}
)glsl";

// The linear colour encoded to sRGB (kernels/maths.glsl's srgb(), clamped), as OpenImageIO's
// "linear" to "sRGB" conversion encodes the PNGs of `flatmarch render` (output/image_io.cpp).
std::string present_fragment_shader() {
  return "#version 450 core\n" + kernel::maths_source() + R"glsl(
uniform sampler2D u_colour;
in vec2 v_uv;
layout(location = 0) out vec4 o_colour;
void main() {
  o_colour = vec4(srgb(texture(u_colour, v_uv).rgb), 1.0);
}
)glsl";
}

const char* const kInsetVertexShader = R"glsl(#version 450 core
layout(location = 0) in vec2 a_position;  // window pixels, y down
layout(location = 1) in vec3 a_colour;
uniform vec2 u_window;
out vec3 v_colour;
void main() {
  v_colour = a_colour;
  gl_Position = vec4(2.0 * a_position.x / u_window.x - 1.0, 1.0 - 2.0 * a_position.y / u_window.y,
                     0.0, 1.0);
}
)glsl";

const char* const kInsetFragmentShader = R"glsl(#version 450 core
in vec3 v_colour;
layout(location = 0) out vec4 o_colour;
void main() { o_colour = vec4(v_colour, 1.0); }
)glsl";

// GLFW reports errors through a callback; the last one explains a failure.
std::string last_glfw_error = "no further detail";

void on_glfw_error(int, const char* description) {
  last_glfw_error = description;
}

void* gl_proc(const char* name) {
  return reinterpret_cast<void*>(glfw().GetProcAddress(name));
}

// GLFW, initialised for the viewer's lifetime.
struct Glfw {
  Glfw() {
    try {
      glfw();
    } catch (const std::exception& e) {
      throw Unavailable(std::string("the viewer cannot open a window: ") + e.what());
    }
    glfw().SetErrorCallback(on_glfw_error);
    if (glfw().Init() == GLFW_TRUE) return;
    const bool no_display = !std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY");
    throw Unavailable(
        "the viewer cannot open a window: " + last_glfw_error +
        (no_display ? " (no display here: DISPLAY is not set; on a machine without one, run it "
                      "under a virtual display: xvfb-run -a flatmarch view ...)"
                    : ""));
  }
  ~Glfw() { glfw().Terminate(); }
  Glfw(const Glfw&) = delete;
  Glfw& operator=(const Glfw&) = delete;
};

struct WindowDeleter {
  void operator()(GLFWwindow* w) const { glfw().DestroyWindow(w); }
};

bool same_params(const MarchParams& a, const MarchParams& b) {
  return a.method == b.method && a.eps == b.eps && a.offset == b.offset &&
         a.max_steps == b.max_steps && a.max_distance == b.max_distance && a.omega == b.omega;
}

// The scene files Tab cycles through: the *.json of a folder, sorted.
std::vector<std::filesystem::path> scene_files(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> files;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error))
    if (entry.path().extension() == ".json") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

class Viewer {
 public:
  explicit Viewer(const ViewerOptions& options);
  ~Viewer();
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;
  void run();

  // The input handlers, which real input (GLFW callbacks) and scripts both call.
  void key(int key, bool press);
  void mouse_motion(double dx, double dy);
  void click();

  // Real input, ignored while a script runs. Exceptions are kept for after glfwPollEvents
  // rather than thrown through GLFW's C code.
  void real_key(int key, bool press) {
    if (!options_.scripted) guard([&] { this->key(key, press); });
  }
  void real_cursor(double x, double y);
  void real_click() {
    if (!options_.scripted) guard([&] { click(); });
  }
  void focus_lost() { held_.clear(); }

 private:
  template <typename F>
  void guard(F f) {
    try {
      f();
    } catch (...) {
      if (!pending_) pending_ = std::current_exception();
    }
  }
  void set_captured(bool captured);
  void switch_scene(int direction);
  const gl::KernelProgram& program();
  CameraBasis<float> basis(int width, int height) const;
  bool frame(double dt);  // false when there was nothing to draw (minimised)
  void draw_inset(int width, int height);
  double mean_steps();
  void update_title(double frame_ms);
  void screenshot(const std::filesystem::path& path);
  std::filesystem::path next_screenshot_path() const;
  void write_state(const std::filesystem::path& path);
  void run_step(const ScriptStep& step, int& frames_left, int& release);

  ViewerOptions options_;
  Scene scene_;
  std::filesystem::path scene_file_;
  Camera camera_;
  HeldKeys held_;
  MarchSettings settings_;
  RenderScale scale_;
  bool captured_ = true, quit_ = false, title_due_ = true, compiled_ = false;
  bool have_cursor_ = false;
  double cursor_x_ = 0.0, cursor_y_ = 0.0;
  int frames_ = 0;
  std::exception_ptr pending_;

  Glfw glfw_;  // GL objects below are freed (in reverse order) before the window and GLFW
  std::unique_ptr<GLFWwindow, WindowDeleter> window_;
  gl::Api gl_;
  GLuint present_ = 0, inset_program_ = 0, empty_vertex_array_ = 0, inset_vertex_array_ = 0,
         inset_buffer_ = 0;
  GLint inset_window_ = -1;
  // Programs by their scene file and march parameters.
  struct ProgramKey {
    std::filesystem::path scene_file;
    MarchParams params;
    bool operator==(const ProgramKey& o) const {
      return scene_file == o.scene_file && same_params(params, o.params);
    }
  };
  LruCache<ProgramKey, std::unique_ptr<gl::KernelProgram>> programs_{kMaxPrograms};
  std::unique_ptr<gl::RenderTargets> targets_;
  KernelShape shape_ = KernelShape::software;
};

Viewer& viewer_of(GLFWwindow* window) {
  return *static_cast<Viewer*>(glfw().GetWindowUserPointer(window));
}

Viewer::Viewer(const ViewerOptions& options)
    : options_(options),
      scene_(options.scene),
      scene_file_(options.scene_file),
      camera_(options.scene.camera),
      settings_(options.params),
      scale_(options.scale) {
  glfw().WindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfw().WindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfw().WindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  window_.reset(
      glfw().CreateWindow(options.width, options.height, "flatmarch view", nullptr, nullptr));
  if (!window_)
    throw Unavailable("the viewer cannot open a window with an OpenGL 4.5 core context: " +
                      last_glfw_error);
  glfw().MakeContextCurrent(window_.get());
  try {
    gl_ = gl::load(gl_proc);
  } catch (const std::exception& e) {
    throw Unavailable(std::string("the viewer's window has no OpenGL 4.5 core context: ") +
                      e.what());
  }
  // The kernel shaped for the window's device: the software shape on llvmpipe (Xvfb), else the
  // gpu shape's code (the viewer draws a fragment shader either way: into the window).
  const GLubyte* renderer = gl_.GetString(GL_RENDERER);
  shape_ = renderer && gl::software_renderer(reinterpret_cast<const char*>(renderer))
               ? KernelShape::software
               : KernelShape::gpu;
  // A script runs as fast as it draws; a person gets frames paced by the display.
  glfw().SwapInterval(options.scripted ? 0 : 1);

  present_ = gl::link_program(gl_, kPresentVertexShader, present_fragment_shader());
  inset_program_ = gl::link_program(gl_, kInsetVertexShader, kInsetFragmentShader);
  inset_window_ = gl_.GetUniformLocation(inset_program_, "u_window");
  gl_.GenVertexArrays(1, &empty_vertex_array_);
  gl_.GenVertexArrays(1, &inset_vertex_array_);
  gl_.GenBuffers(1, &inset_buffer_);
  gl_.BindVertexArray(inset_vertex_array_);
  gl_.BindBuffer(GL_ARRAY_BUFFER, inset_buffer_);
  gl_.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, sizeof(InsetVertex),
                          reinterpret_cast<const void*>(offsetof(InsetVertex, x)));
  gl_.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(InsetVertex),
                          reinterpret_cast<const void*>(offsetof(InsetVertex, r)));
  gl_.EnableVertexAttribArray(0);
  gl_.EnableVertexAttribArray(1);

  glfw().SetWindowUserPointer(window_.get(), this);
  glfw().SetKeyCallback(window_.get(), [](GLFWwindow* w, int key, int, int action, int) {
    if (action != GLFW_REPEAT) viewer_of(w).real_key(key, action == GLFW_PRESS);
  });
  glfw().SetCursorPosCallback(
      window_.get(), [](GLFWwindow* w, double x, double y) { viewer_of(w).real_cursor(x, y); });
  glfw().SetMouseButtonCallback(window_.get(), [](GLFWwindow* w, int button, int action, int) {
    if (button == GLFW_MOUSE_BUTTON_LEFT && action == GLFW_PRESS) viewer_of(w).real_click();
  });
  glfw().SetWindowFocusCallback(window_.get(), [](GLFWwindow* w, int focused) {
    if (!focused) viewer_of(w).focus_lost();  // no key stays held while another window types
  });
  if (!options.scripted && glfw().RawMouseMotionSupported())
    glfw().SetInputMode(window_.get(), GLFW_RAW_MOUSE_MOTION, GLFW_TRUE);
  set_captured(true);
  if (const std::string e = gl::errors(gl_); !e.empty())
    throw std::runtime_error("the viewer failed to set up OpenGL: " + e);
}

Viewer::~Viewer() {
  glfw().MakeContextCurrent(window_.get());
  targets_.reset();
  programs_.clear();
  gl_.DeleteBuffers(1, &inset_buffer_);
  gl_.DeleteVertexArrays(1, &inset_vertex_array_);
  gl_.DeleteVertexArrays(1, &empty_vertex_array_);
  gl_.DeleteProgram(inset_program_);
  gl_.DeleteProgram(present_);
}

void Viewer::set_captured(bool captured) {
  captured_ = captured;
  have_cursor_ = false;    // the next cursor position is a new start, not a motion
  if (!options_.scripted)  // a script's logical cursor leaves the real one alone
    glfw().SetInputMode(window_.get(), GLFW_CURSOR,
                        captured ? GLFW_CURSOR_DISABLED : GLFW_CURSOR_NORMAL);
}

void Viewer::key(int key, bool press) {
  if (!press) {
    held_.release(key);
    return;
  }
  held_.press(key);
  title_due_ = true;
  switch (command_for_key(key)) {
    case Command::none:
      break;
    case Command::method_sphere:
      settings_.set_method(Method::sphere);
      break;
    case Command::method_relaxed:
      settings_.set_method(Method::relaxed);
      break;
    case Command::method_analytic:
      settings_.set_method(Method::analytic);
      break;
    case Command::eps_down:
      settings_.step_eps(-1);
      break;
    case Command::eps_up:
      settings_.step_eps(1);
      break;
    case Command::offset_down:
      settings_.step_offset(-1);
      break;
    case Command::offset_up:
      settings_.step_offset(1);
      break;
    case Command::scale_down:
      scale_.step(-1);
      break;
    case Command::scale_up:
      scale_.step(1);
      break;
    case Command::next_scene:
      switch_scene(held_.fast() ? -1 : 1);
      break;
    case Command::screenshot:
      screenshot(next_screenshot_path());
      break;
    case Command::escape:
      if (captured_)
        set_captured(false);
      else
        quit_ = true;
      break;
  }
}

void Viewer::mouse_motion(double dx, double dy) {
  if (captured_) camera_ = look(camera_, -dx * kDegreesPerPixel, -dy * kDegreesPerPixel);
}

void Viewer::click() {
  if (!captured_) set_captured(true);
}

void Viewer::real_cursor(double x, double y) {
  if (options_.scripted) return;
  if (have_cursor_) guard([&] { mouse_motion(x - cursor_x_, y - cursor_y_); });
  have_cursor_ = true;
  cursor_x_ = x;
  cursor_y_ = y;
}

void Viewer::switch_scene(int direction) {
  const std::vector<std::filesystem::path> files = scene_files(scene_file_.parent_path());
  const int n = static_cast<int>(files.size());
  int current = -1;
  for (int k = 0; k < n; ++k)
    if (files[static_cast<size_t>(k)].filename() == scene_file_.filename()) current = k;
  for (int k = 1; k <= n; ++k) {  // the next scene that loads
    const int next = (((current + direction * k) % n) + n) % n;
    if (next == current) return;
    const std::filesystem::path& file = files[static_cast<size_t>(next)];
    try {
      scene_ = load_scene(file);
    } catch (const SceneError& e) {
      std::fprintf(stderr, "warning: skipping a scene that does not load: %s\n", e.what());
      continue;
    }
    scene_file_ = file;
    camera_ = scene_.camera;
    return;
  }
}

const gl::KernelProgram& Viewer::program() {
  const MarchParams params = settings_.params();
  return *programs_.get({scene_file_, params}, [&] {
    glfw().SetWindowTitle(window_.get(),
                          ("flatmarch view: " + scene_.name + " | compiling").c_str());
    compiled_ = true;
    return std::make_unique<gl::KernelProgram>(gl_, kernel::compile_scene<float>(scene_, params),
                                               kernel::ShaderVariant{.shape = shape_});
  });
}

CameraBasis<float> Viewer::basis(int width, int height) const {
  return camera_basis<float>(static_cast<float>(camera_.yaw_deg),
                             static_cast<float>(camera_.pitch_deg),
                             static_cast<float>(camera_.fov_deg), width, height);
}

bool Viewer::frame(double dt) {
  const double speed = kSpeedPerScale * scene_.scale * (held_.fast() ? kFastFactor : 1.0) * dt;
  const Vec3 move = held_.direction() * speed;
  if (move != Vec3(0.0)) camera_ = walk(scene_, camera_, move.x, move.y, move.z).camera;

  int width = 0, height = 0;
  glfw().GetFramebufferSize(window_.get(), &width, &height);
  if (width <= 0 || height <= 0) return false;
  const int w = std::max(1, static_cast<int>(std::lround(width * scale_.value())));
  const int h = std::max(1, static_cast<int>(std::lround(height * scale_.value())));
  const gl::KernelProgram& kernel = program();
  if (!targets_ || targets_->width() != w || targets_->height() != h) {
    targets_.reset();
    targets_ = std::make_unique<gl::RenderTargets>(gl_, w, h);
    gl_.BindTexture(GL_TEXTURE_2D, targets_->colour());
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  }
  gl_.BindFramebuffer(GL_FRAMEBUFFER, targets_->framebuffer());
  gl_.Viewport(0, 0, w, h);
  kernel.draw(basis(w, h), camera_.polygon, glm::vec3(camera_.position), w, h);

  gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
  gl_.Viewport(0, 0, width, height);
  gl_.UseProgram(present_);
  gl_.BindVertexArray(empty_vertex_array_);
  gl_.BindTexture(GL_TEXTURE_2D, targets_->colour());
  gl_.DrawArrays(GL_TRIANGLES, 0, 3);
  draw_inset(width, height);
  glfw().SwapBuffers(window_.get());
  if (const std::string e = gl::errors(gl_); !e.empty())
    throw std::runtime_error("the viewer failed to draw a frame: " + e);
  ++frames_;
  return true;
}

void Viewer::draw_inset(int width, int height) {
  const InsetBox box = inset_box(scene_, width, height);
  const std::vector<InsetVertex> triangles = inset_triangles(scene_, camera_, box);
  gl_.UseProgram(inset_program_);
  gl_.Uniform2f(inset_window_, static_cast<float>(width), static_cast<float>(height));
  gl_.BindVertexArray(inset_vertex_array_);
  gl_.BindBuffer(GL_ARRAY_BUFFER, inset_buffer_);
  gl_.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(triangles.size() * sizeof(InsetVertex)),
                 triangles.data(), GL_STREAM_DRAW);
  // Only within the box: a camera above the rooms may stand outside the plan.
  gl_.Enable(GL_SCISSOR_TEST);
  gl_.Scissor(static_cast<GLint>(std::floor(box.x)),
              static_cast<GLint>(std::floor(height - box.y - box.height)),
              static_cast<GLsizei>(std::ceil(box.width)),
              static_cast<GLsizei>(std::ceil(box.height)));
  gl_.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(triangles.size()));
  gl_.Disable(GL_SCISSOR_TEST);
}

// The mean of the steps AOV over the last frame: the top (1 x 1) level of its mipmap, so that
// only one texel comes back.
double Viewer::mean_steps() {
  if (!targets_) return 0.0;
  int level = 0;
  for (int size = std::max(targets_->width(), targets_->height()); size > 1; size /= 2) ++level;
  gl_.BindTexture(GL_TEXTURE_2D, targets_->aovs());
  gl_.GenerateMipmap(GL_TEXTURE_2D);
  float texel[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 4);
  gl_.GetTexImage(GL_TEXTURE_2D, level, GL_RGBA, GL_FLOAT, texel);
  return texel[0];
}

void Viewer::update_title(double frame_ms) {
  const MarchParams p = settings_.params();
  char text[512];
  std::snprintf(text, sizeof text,
                "flatmarch view: %s | polygon %d | %s eps %.3g offset %.3g | scale %.3g (%dx%d) | "
                "%.1f ms | %.1f steps/px",
                scene_.name.c_str(), camera_.polygon, to_string(p.method), p.eps, p.offset,
                scale_.value(), targets_ ? targets_->width() : 0, targets_ ? targets_->height() : 0,
                frame_ms, mean_steps());
  glfw().SetWindowTitle(window_.get(), text);
}

// The view at the window's full resolution, drawn by the same program and written by the PNG
// writer of `flatmarch render` (output/image_io.hpp): the inset is not in it.
void Viewer::screenshot(const std::filesystem::path& path) {
  int width = 0, height = 0;
  glfw().GetFramebufferSize(window_.get(), &width, &height);
  if (width <= 0 || height <= 0) width = options_.width, height = options_.height;
  const gl::KernelProgram& kernel = program();
  Frame frame(width, height);
  {
    const gl::RenderTargets shot(gl_, width, height);  // bound until it goes
    gl::draw_frame(gl_, kernel, basis(width, height), camera_.polygon, glm::vec3(camera_.position),
                   {}, frame, nullptr);
  }
  if (const std::string e = gl::errors(gl_); !e.empty())
    throw std::runtime_error("the viewer failed to draw a screenshot: " + e);
  write_png(frame, path);
  if (!options_.quiet) std::fprintf(stderr, "wrote %s\n", path.string().c_str());
}

std::filesystem::path Viewer::next_screenshot_path() const {
  for (int n = 1; n <= kMaxScreenshotNumber; ++n) {
    std::filesystem::path path =
        options_.screenshot_dir / ("flatmarch-screenshot-" + std::to_string(n) + ".png");
    if (!std::filesystem::exists(path)) return path;
  }
  throw std::runtime_error("no free screenshot name in " + options_.screenshot_dir.string());
}

void Viewer::write_state(const std::filesystem::path& path) {
  const MarchParams p = settings_.params();
  const Vec3 x = camera_.position;
  nlohmann::ordered_json state = {
      {"scene", scene_.name},
      {"scene_file", scene_file_.string()},
      {"polygon", camera_.polygon},
      {"position", {x.x, x.y, x.z}},
      {"yaw_deg", camera_.yaw_deg},
      {"pitch_deg", camera_.pitch_deg},
      {"fov_deg", camera_.fov_deg},
      {"method", to_string(p.method)},
      {"eps", p.eps},
      {"offset", p.offset},
      {"scale", scale_.value()},
      {"frames", frames_},
  };
  // Of the last frame drawn, if any.
  state["mean_steps"] = targets_ ? nlohmann::ordered_json(mean_steps()) : nullptr;
  std::ofstream out(path);
  out << state.dump(2) << "\n";
  if (!out.flush()) throw std::runtime_error("cannot write the viewer's state to " + path.string());
}

void Viewer::run_step(const ScriptStep& step, int& frames_left, int& release) {
  switch (step.kind) {
    case ScriptStep::Kind::hold:
      key(step.key, true);
      frames_left = step.frames;
      release = step.key;
      break;
    case ScriptStep::Kind::key:
      key(step.key, true);
      key(step.key, false);
      break;
    case ScriptStep::Kind::mouse:
      mouse_motion(step.dx, step.dy);
      break;
    case ScriptStep::Kind::click:
      click();
      break;
    case ScriptStep::Kind::frames:
      frames_left = step.frames;
      break;
    case ScriptStep::Kind::screenshot:
      screenshot(step.path);
      break;
    case ScriptStep::Kind::state:
      write_state(step.path);
      break;
  }
}

void Viewer::run() {
  size_t next_step = 0;
  int frames_left = 0, release = -1;
  // Frame times for the title and for the summary (frames that compiled a program aside).
  double last = glfw().GetTime(), title_at = last, title_ms = 0.0, total_ms = 0.0;
  int title_frames = 0, timed_frames = 0;
  // Ends when the window closes, Esc quits, the script ends or the frames are drawn; a script
  // runs a bounded number of frames.
  while (!quit_) {
    glfw().PollEvents();
    if (pending_) std::rethrow_exception(pending_);
    if (glfw().WindowShouldClose(window_.get()) || quit_) break;
    double dt = 0.0;
    if (options_.scripted) {
      // The script's steps up to the next one that takes frames (a hold or frames).
      while (frames_left == 0 && !quit_) {
        if (release >= 0) key(release, false);
        release = -1;
        if (next_step == options_.script.size())
          quit_ = true;  // the script's end
        else
          run_step(options_.script[next_step++], frames_left, release);
      }
      if (quit_) break;
      --frames_left;
      dt = kScriptFrameTime;
    } else {
      dt = std::min(glfw().GetTime() - last, kMaxFrameTime);
    }
    compiled_ = false;
    if (!frame(dt)) {
      glfw().WaitEventsTimeout(0.1);  // minimised: nothing to draw, so wait rather than spin
      last = glfw().GetTime();
      continue;
    }
    const double now = glfw().GetTime(), ms = 1000.0 * (now - last);
    last = now;
    if (!compiled_) title_ms += ms, ++title_frames, total_ms += ms, ++timed_frames;
    if (title_due_ || now - title_at >= kTitlePeriod) {
      update_title(title_frames > 0 ? title_ms / title_frames : 0.0);
      title_at = now, title_ms = 0.0, title_frames = 0, title_due_ = false;
    }
    if (options_.frames > 0 && frames_ >= options_.frames) break;
  }
  if (!options_.quiet && targets_)
    std::fprintf(stderr, "view: %d frames of %dx%d, %.1f ms a frame (those that compiled aside)\n",
                 frames_, targets_->width(), targets_->height(),
                 timed_frames > 0 ? total_ms / timed_frames : 0.0);
}

}  // namespace

void run(const ViewerOptions& options) {
  Viewer viewer(options);
  viewer.run();
}

}  // namespace flatmarch::viewer
