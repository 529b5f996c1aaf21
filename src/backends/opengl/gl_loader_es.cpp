// The OpenGL ES 3.1 loader: glad's gles2 API, generated beside the GL one (cmake/Glad.cmake) so that
// it fills the same entry-point table. Kept in a file of its own: glad/gl.h and glad/gles2.h declare
// the same GL types and cannot share a translation unit.
#include <glad/gles2.h>

#include "backends/opengl/gl_context.h"

// Two pointers of the GL table (glad/gl.h, with the sffd_ prefix of cmake/GladPrefix.cmake) that ES
// core lacks; the types are the extension's, which have the same signatures.
extern "C" {
extern PFNGLQUERYCOUNTEREXTPROC sffd_glad_glQueryCounter;
extern PFNGLGETQUERYOBJECTUI64VEXTPROC sffd_glad_glGetQueryObjectui64v;
}

namespace sffd::gl {

int loadGlesEntryPoints(GLProc (*load)(void* user, const char* name), void* user) {
  int version = gladLoadGLES2UserPtr(reinterpret_cast<GLADuserptrloadfunc>(load), user);
  if (version == 0) return 0;
  // ES 3.1 has no timestamp queries in core; EXT_disjoint_timer_query has them under EXT names. The
  // driver code calls the core names, so they point at the extension's (the same signatures).
  const bool timer = GLAD_GL_EXT_disjoint_timer_query;
  sffd_glad_glQueryCounter = timer ? glad_glQueryCounterEXT : nullptr;
  sffd_glad_glGetQueryObjectui64v = timer ? glad_glGetQueryObjectui64vEXT : nullptr;
  return GLAD_VERSION_MAJOR(version) * 10 + GLAD_VERSION_MINOR(version);
}

}  // namespace sffd::gl
