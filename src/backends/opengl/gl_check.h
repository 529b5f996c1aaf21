// The check of glGetError after GL calls, shared by the GL backend, its programs and the renderer.
#pragma once
#include <glad/gl.h>

#include <cstdio>
#include <string>

#include <sffd/error.h>

namespace sffd::gl {

// Throws an Error "WHO: ... in WHAT" when GL reports an error (all pending ones are drained): a device
// Error for GL_OUT_OF_MEMORY, an internal one for the others.
inline void checkGlErrors(const char* who, const std::string& what) {
  GLenum first = glGetError();
  if (first == GL_NO_ERROR) return;
  for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) {}
  if (first == GL_OUT_OF_MEMORY) throw deviceError(std::string(who) + ": out of GPU memory in " + what);
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", first);
  throw Error(ErrorKind::Internal, std::string(who) + ": GL error " + code + " in " + what);
}

// The compute backend's form.
inline void checkGl(const std::string& what) { checkGlErrors("gl", what); }

}  // namespace sffd::gl
