// <sffd/opengl.h>: a Device on the application's current GL context.
#include <sffd/opengl.h>

#include "backends/opengl/gl_backend.h"
#include "backends/opengl/gl_context.h"

namespace sffd::opengl {

Device adoptCurrentContext(GetProcAddress getProc) {
  std::shared_ptr<gl::Context> context = gl::adoptCurrentContext(getProc);
  return Device("gl-adopted", gl::createBackendOn(std::move(context)));
}

}  // namespace sffd::opengl
