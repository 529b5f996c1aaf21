// <sffd/opengl.h>: a Device on the application's current GL context, and the GL buffers of its output.
#include <sffd/opengl.h>

#include <sffd/error.h>
#include "backends/opengl/gl_backend.h"
#include "backends/opengl/gl_context.h"

namespace sffd::opengl {

Device adoptCurrentContext(GetProcAddress getProc) {
  std::shared_ptr<gl::Context> context = gl::adoptCurrentContext(getProc);
  std::unique_ptr<Backend> backend = gl::createBackendOn(std::move(context));
  std::string label = backend->info().api == "gles" ? "gles-adopted" : "gl-adopted";
  return Device(std::move(label), std::move(backend));
}

unsigned bufferOf(const Deformer& deformer, const OutputChunk& chunk) {
  Device& device = deformer.device();
  const std::string& api = device.info().api;
  unsigned name = api == "gl" || api == "gles" ? gl::glBufferObject(device.backend(), chunk.buffer) : 0;
  if (!name)
    throw Error(ErrorKind::Input, "sffd::opengl::bufferOf: the Deformer runs on " + device.label() +
                                      ", not on a GL device, or the chunk is not its output");
  return name;
}

}  // namespace sffd::opengl
