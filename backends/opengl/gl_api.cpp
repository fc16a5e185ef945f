#include "backends/opengl/gl_api.hpp"

#include <stdexcept>

namespace flatmarch::gl {

Api load(GetProcAddress get) {
  Api gl;
#define FLATMARCH_GL_LOAD(type, name)                             \
  gl.name = reinterpret_cast<type>(get("gl" #name));              \
  if (gl.name == nullptr)                                         \
    throw std::runtime_error("the OpenGL context has no gl" #name \
                             " (OpenGL 4.5 core "                 \
                             "is needed)");
  FLATMARCH_GL_FUNCTIONS(FLATMARCH_GL_LOAD)
#undef FLATMARCH_GL_LOAD
  return gl;
}

std::string errors(const Api& gl) {
  std::string text;
  for (int n = 0; n < 16; ++n) {  // each call clears one flag; there are few
    const GLenum e = gl.GetError();
    if (e == GL_NO_ERROR) break;
    char code[16];
    std::snprintf(code, sizeof code, "0x%04x", e);
    text += (text.empty() ? "GL error " : ", ") + std::string(code);
  }
  return text;
}

}  // namespace flatmarch::gl
