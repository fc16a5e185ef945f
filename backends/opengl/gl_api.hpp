// The OpenGL 4.5 core functions the OpenGL backend and the viewer call, loaded from whichever
// context is current. One table serves both because the two contexts come from different
// libraries: OSMesa's (headless) exports its own entry points, while a GLFW window's come through
// libGL (GLX); calling one library's functions with the other's context current does nothing.
#pragma once

#include <GL/glcorearb.h>

#include <string>

namespace flatmarch::gl {

// glcorearb.h has no pointer types for OpenGL 1.1's functions.
using DrawArraysProc = void(APIENTRYP)(GLenum mode, GLint first, GLsizei count);
using GenTexturesProc = void(APIENTRYP)(GLsizei n, GLuint* textures);
using DeleteTexturesProc = void(APIENTRYP)(GLsizei n, const GLuint* textures);
using BindTextureProc = void(APIENTRYP)(GLenum target, GLuint texture);

// X(type, name): each function, typed by glcorearb.h's PFNGL...PROC.
#define FLATMARCH_GL_FUNCTIONS(X)                              \
  X(PFNGLGETERRORPROC, GetError)                               \
  X(PFNGLGETSTRINGPROC, GetString)                             \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                         \
  X(PFNGLGETINTEGERI_VPROC, GetIntegeri_v)                     \
  X(PFNGLGETINTEGER64VPROC, GetInteger64v)                     \
  X(PFNGLCREATESHADERPROC, CreateShader)                       \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                       \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                     \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                         \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)               \
  X(PFNGLDELETESHADERPROC, DeleteShader)                       \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                     \
  X(PFNGLATTACHSHADERPROC, AttachShader)                       \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                         \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                       \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)             \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                     \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                           \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)           \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                             \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                             \
  X(PFNGLUNIFORM2FPROC, Uniform2f)                             \
  X(PFNGLUNIFORM3FPROC, Uniform3f)                             \
  X(PFNGLUNIFORM4FPROC, Uniform4f)                             \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                           \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                     \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                           \
  X(PFNGLBUFFERDATAPROC, BufferData)                           \
  X(PFNGLBUFFERSUBDATAPROC, BufferSubData)                     \
  X(PFNGLBINDBUFFERBASEPROC, BindBufferBase)                   \
  X(PFNGLGETBUFFERSUBDATAPROC, GetBufferSubData)               \
  X(PFNGLMEMORYBARRIERPROC, MemoryBarrier)                     \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                 \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)           \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                 \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)         \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray) \
  X(DrawArraysProc, DrawArrays)                                \
  X(GenTexturesProc, GenTextures)                              \
  X(DeleteTexturesProc, DeleteTextures)                        \
  X(BindTextureProc, BindTexture)                              \
  X(PFNGLTEXIMAGE2DPROC, TexImage2D)                           \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri)                     \
  X(PFNGLGENERATEMIPMAPPROC, GenerateMipmap)                   \
  X(PFNGLGETTEXIMAGEPROC, GetTexImage)                         \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                 \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)           \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                 \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)       \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)   \
  X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                         \
  X(PFNGLREADBUFFERPROC, ReadBuffer)                           \
  X(PFNGLREADPIXELSPROC, ReadPixels)                           \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                         \
  X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer)                 \
  X(PFNGLVIEWPORTPROC, Viewport)                               \
  X(PFNGLSCISSORPROC, Scissor)                                 \
  X(PFNGLENABLEPROC, Enable)                                   \
  X(PFNGLDISABLEPROC, Disable)                                 \
  X(PFNGLCLEARCOLORPROC, ClearColor)                           \
  X(PFNGLCLEARPROC, Clear)                                     \
  X(PFNGLFINISHPROC, Finish)                                   \
  X(PFNGLFLUSHPROC, Flush)                                     \
  X(PFNGLLINEWIDTHPROC, LineWidth)                             \
  X(PFNGLDISPATCHCOMPUTEPROC, DispatchCompute)                 \
  X(PFNGLCOPYBUFFERSUBDATAPROC, CopyBufferSubData)             \
  X(PFNGLMAPBUFFERRANGEPROC, MapBufferRange)                   \
  X(PFNGLUNMAPBUFFERPROC, UnmapBuffer)                         \
  X(PFNGLGENQUERIESPROC, GenQueries)                           \
  X(PFNGLDELETEQUERIESPROC, DeleteQueries)                     \
  X(PFNGLBEGINQUERYPROC, BeginQuery)                           \
  X(PFNGLENDQUERYPROC, EndQuery)                               \
  X(PFNGLGETQUERYIVPROC, GetQueryiv)                           \
  X(PFNGLGETQUERYOBJECTUI64VPROC, GetQueryObjectui64v)

struct Api {
#define FLATMARCH_GL_MEMBER(type, name) type name = nullptr;
  FLATMARCH_GL_FUNCTIONS(FLATMARCH_GL_MEMBER)
#undef FLATMARCH_GL_MEMBER
};

using GetProcAddress = void* (*)(const char* name);

// Loads every function from the current context; throws std::runtime_error naming the first
// one the context lacks.
Api load(GetProcAddress get);

// The GL error flags set since the last call, as text ("" when none); clears them.
std::string errors(const Api& gl);

}  // namespace flatmarch::gl
