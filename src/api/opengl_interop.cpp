// <sffd/opengl.h>: a Device on the application's current GL context, and the GL buffers of its output.
#include <sffd/opengl.h>

#include <sffd/error.h>
#include "backends/opengl/gl_backend.h"
#include "backends/opengl/gl_context.h"

namespace sffd::opengl {

Device adoptCurrentContext(GetProcAddress getProc) {
  std::shared_ptr<gl::Context> context = gl::adoptCurrentContext(getProc);
  return Device("gl-adopted", gl::createBackendOn(std::move(context)));
}

unsigned bufferOf(const Deformer& deformer, const OutputChunk& chunk) {
  Device& device = deformer.device();
  unsigned name = device.info().api == "gl" ? gl::glBufferObject(device.backend(), chunk.buffer) : 0;
  if (!name)
    throw Error(ErrorKind::Input, "sffd::opengl::bufferOf: the Deformer runs on " + device.label() +
                                      ", not on a GL device, or the chunk is not its output");
  return name;
}

}  // namespace sffd::opengl
