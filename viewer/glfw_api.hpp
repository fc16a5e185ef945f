// The GLFW functions the viewer calls, from libglfw.so.3 opened when the viewer starts, so that
// the other commands do not load GLFW and X11.
#pragma once

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace flatmarch::viewer {

// X(name): each function, as glfw<name> in GLFW's header.
#define FLATMARCH_GLFW_FUNCTIONS(X) \
  X(CreateWindow)                   \
  X(DestroyWindow)                  \
  X(GetFramebufferSize)             \
  X(GetProcAddress)                 \
  X(GetTime)                        \
  X(GetWindowUserPointer)           \
  X(Init)                           \
  X(MakeContextCurrent)             \
  X(PollEvents)                     \
  X(RawMouseMotionSupported)        \
  X(SetCursorPosCallback)           \
  X(SetErrorCallback)               \
  X(SetInputMode)                   \
  X(SetKeyCallback)                 \
  X(SetMouseButtonCallback)         \
  X(SetWindowFocusCallback)         \
  X(SetWindowTitle)                 \
  X(SetWindowUserPointer)           \
  X(SwapBuffers)                    \
  X(SwapInterval)                   \
  X(Terminate)                      \
  X(WaitEventsTimeout)              \
  X(WindowHint)                     \
  X(WindowShouldClose)

struct GlfwApi {
#define FLATMARCH_GLFW_MEMBER(name) decltype(&::glfw##name) name = nullptr;
  FLATMARCH_GLFW_FUNCTIONS(FLATMARCH_GLFW_MEMBER)
#undef FLATMARCH_GLFW_MEMBER
};

// GLFW, loaded on first call; throws std::runtime_error saying why it cannot be.
const GlfwApi& glfw();

}  // namespace flatmarch::viewer
