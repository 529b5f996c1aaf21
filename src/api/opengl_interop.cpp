// <sffd/opengl.h>: a Device on the application's current GL context, and the GL buffers of its output.
#include <sffd/opengl.h>

#include <sffd/error.h>

#include "api/output_chunk_check.h"
#include "backends/backend_select.h"
#include "backends/opengl/gl_backend.h"
#include "backends/opengl/gl_context.h"

namespace sffd::opengl {

Device adoptCurrentContext(GetProcAddress getProc) {
  checkLibraryVariables();
  std::shared_ptr<gl::Context> context = gl::adoptCurrentContext(getProc);
  std::unique_ptr<Backend> backend = gl::createBackendOn(std::move(context));
  std::string label = backend->info().api == "gles" ? "gles-adopted" : "gl-adopted";
  return Device(std::move(label), std::move(backend));
}

unsigned bufferOf(const Deformer& deformer, const OutputChunk& chunk) {
  Device& device = deformer.device();
  const std::string& api = device.info().api;
  checkOutputChunk(deformer, chunk, "sffd::opengl::bufferOf", api == "gl" || api == "gles", "GL");
  unsigned name = gl::glBufferObject(device.backend(), chunk.buffer);
  if (!name) throw Error(ErrorKind::Internal, "sffd::opengl::bufferOf: no GL buffer for an output chunk of the Deformer");
  return name;
}

}  // namespace sffd::opengl
