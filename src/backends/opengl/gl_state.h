// Saves the GL bindings an entry point of the GL backend is about to change and restores them when
// it returns (or throws), so that sffd can share a context with the application that owns it: the
// current program and the generic and indexed buffer bindings. Each is read once, on first use.
#pragma once
#include <glad/gl.h>

#include <cstdint>

namespace sffd::gl {

class StateGuard {
 public:
  StateGuard() = default;
  StateGuard(const StateGuard&) = delete;
  StateGuard& operator=(const StateGuard&) = delete;
  ~StateGuard() {
    // Indexed bindings first: binding one also sets the generic binding of its target.
    for (int i = indexedCount_ - 1; i >= 0; --i) {
      const Indexed& s = indexed_[i];
      if (s.buffer == 0 || s.size == 0)
        glBindBufferBase(s.target, s.index, s.buffer);
      else
        glBindBufferRange(s.target, s.index, s.buffer, s.start, s.size);
    }
    for (int i = genericCount_ - 1; i >= 0; --i) glBindBuffer(generic_[i].target, generic_[i].buffer);
    if (programSaved_) glUseProgram(program_);
  }

  void program() {
    if (programSaved_) return;
    GLint p = 0;
    glGetIntegerv(GL_CURRENT_PROGRAM, &p);
    program_ = GLuint(p);
    programSaved_ = true;
  }
  // GL_COPY_READ_BUFFER, GL_UNIFORM_BUFFER, ...
  void buffer(GLenum target) {
    for (int i = 0; i < genericCount_; ++i)
      if (generic_[i].target == target) return;
    if (genericCount_ == kMax) return;
    GLint b = 0;
    glGetIntegerv(bindingQuery(target), &b);
    generic_[genericCount_++] = {target, GLuint(b)};
  }
  // An indexed binding (GL_SHADER_STORAGE_BUFFER or GL_UNIFORM_BUFFER) and its target's generic one.
  void indexed(GLenum target, GLuint index) {
    buffer(target);
    for (int i = 0; i < indexedCount_; ++i)
      if (indexed_[i].target == target && indexed_[i].index == index) return;
    if (indexedCount_ == kMax) return;
    bool ssbo = target == GL_SHADER_STORAGE_BUFFER;
    GLint b = 0;
    GLint64 start = 0, size = 0;
    glGetIntegeri_v(bindingQuery(target), index, &b);
    glGetInteger64i_v(ssbo ? GL_SHADER_STORAGE_BUFFER_START : GL_UNIFORM_BUFFER_START, index, &start);
    glGetInteger64i_v(ssbo ? GL_SHADER_STORAGE_BUFFER_SIZE : GL_UNIFORM_BUFFER_SIZE, index, &size);
    indexed_[indexedCount_++] = {target, index, GLuint(b), GLintptr(start), GLsizeiptr(size)};
  }

 private:
  static GLenum bindingQuery(GLenum target) {
    switch (target) {
      case GL_SHADER_STORAGE_BUFFER: return GL_SHADER_STORAGE_BUFFER_BINDING;
      case GL_UNIFORM_BUFFER: return GL_UNIFORM_BUFFER_BINDING;
      case GL_COPY_READ_BUFFER: return GL_COPY_READ_BUFFER_BINDING;
      case GL_COPY_WRITE_BUFFER: return GL_COPY_WRITE_BUFFER_BINDING;
      case GL_PIXEL_PACK_BUFFER: return GL_PIXEL_PACK_BUFFER_BINDING;
      case GL_PIXEL_UNPACK_BUFFER: return GL_PIXEL_UNPACK_BUFFER_BINDING;
      case GL_DISPATCH_INDIRECT_BUFFER: return GL_DISPATCH_INDIRECT_BUFFER_BINDING;
      default: return GL_ARRAY_BUFFER_BINDING;
    }
  }
  struct Generic {
    GLenum target;
    GLuint buffer;
  };
  struct Indexed {
    GLenum target;
    GLuint index, buffer;
    GLintptr start;
    GLsizeiptr size;
  };
  static constexpr int kMax = 24;   // more than the kernels' storage bindings (layout.h) plus the rest
  Generic generic_[kMax];
  Indexed indexed_[kMax];
  int genericCount_ = 0, indexedCount_ = 0;
  GLuint program_ = 0;
  bool programSaved_ = false;
};

}  // namespace sffd::gl
