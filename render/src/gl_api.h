#pragma once
// The GL functions the renderer uses, as a table of pointers loaded from the
// context (OSMesaGetProcAddress). Call them as gl.Clear(...), gl.DrawArrays(...).
#include <GL/glcorearb.h>

#include "gl_context.h"

namespace rocklab::render::detail {

#define ROCKLAB_GL_FUNCTIONS(X)                                                                        \
  X(PFNGLGETSTRINGPROC, GetString)                                                                     \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                                                                 \
  X(PFNGLGETFLOATVPROC, GetFloatv)                                                                     \
  X(PFNGLGETERRORPROC, GetError)                                                                       \
  X(PFNGLENABLEPROC, Enable)                                                                           \
  X(PFNGLDISABLEPROC, Disable)                                                                         \
  X(PFNGLCLEARCOLORPROC, ClearColor)                                                                   \
  X(PFNGLCLEARDEPTHPROC, ClearDepth)                                                                   \
  X(PFNGLCLEARPROC, Clear)                                                                             \
  X(PFNGLVIEWPORTPROC, Viewport)                                                                       \
  X(PFNGLDEPTHFUNCPROC, DepthFunc)                                                                     \
  X(PFNGLDEPTHMASKPROC, DepthMask)                                                                     \
  X(PFNGLBLENDFUNCSEPARATEPROC, BlendFuncSeparate)                                                     \
  X(PFNGLREADPIXELSPROC, ReadPixels)                                                                   \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                                                                 \
  X(PFNGLFINISHPROC, Finish)                                                                           \
  X(PFNGLREADBUFFERPROC, ReadBuffer)                                                                   \
  X(PFNGLDRAWBUFFERPROC, DrawBuffer)                                                                   \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                                                         \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                                                         \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                                                   \
  X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)                                         \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                                           \
  X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer)                                                         \
  X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)                                                       \
  X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)                                                       \
  X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers)                                                 \
  X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)                                                 \
  X(PFNGLRENDERBUFFERSTORAGEMULTISAMPLEPROC, RenderbufferStorageMultisample)                           \
  X(PFNGLCREATESHADERPROC, CreateShader)                                                               \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                                                               \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                                                             \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                                                                 \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                                                       \
  X(PFNGLDELETESHADERPROC, DeleteShader)                                                               \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                                             \
  X(PFNGLATTACHSHADERPROC, AttachShader)                                                               \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                                                                 \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                                               \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                                                     \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                                                             \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                                                                   \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                                                   \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                                                                     \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                                                                     \
  X(PFNGLUNIFORM2FPROC, Uniform2f)                                                                     \
  X(PFNGLUNIFORM4FPROC, Uniform4f)                                                                     \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                                                       \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                                                         \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                                                         \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                                                   \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                                                                   \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                                                                   \
  X(PFNGLBUFFERDATAPROC, BufferData)                                                                   \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                                             \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)                                         \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                                                 \
  X(PFNGLVERTEXATTRIBDIVISORPROC, VertexAttribDivisor)                                                 \
  X(PFNGLDRAWARRAYSPROC, DrawArrays)                                                                   \
  X(PFNGLDRAWARRAYSINSTANCEDPROC, DrawArraysInstanced)                                                 \
  X(PFNGLDRAWELEMENTSPROC, DrawElements)

struct GlApi {
#define ROCKLAB_GL_MEMBER(type, name) type name = nullptr;
  ROCKLAB_GL_FUNCTIONS(ROCKLAB_GL_MEMBER)
#undef ROCKLAB_GL_MEMBER

  /// Fills every pointer from the current context; throws std::runtime_error
  /// naming the first function the context does not have.
  void load(const GlContext& context);
  /// Throws std::runtime_error("render: GL error 0x... in <where>") if glGetError reports one.
  void check(const char* where) const;
};

}  // namespace rocklab::render::detail
