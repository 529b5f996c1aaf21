// The GL backend's check of glGetError after its calls, shared by the backend and its programs.
#pragma once
#include <glad/gl.h>

#include <cstdio>
#include <string>

#include <sffd/error.h>

namespace sffd::gl {

// Throws an Error naming the operation when GL reports an error (all pending ones are drained): a device
// Error for GL_OUT_OF_MEMORY, an internal one for the others.
inline void checkGl(const char* what) {
  GLenum first = glGetError();
  if (first == GL_NO_ERROR) return;
  for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) {}
  if (first == GL_OUT_OF_MEMORY) throw deviceError(std::string("gl: out of memory in ") + what);
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", first);
  throw Error(ErrorKind::Internal, std::string("gl: error ") + code + " in " + what);
}

}  // namespace sffd::gl
