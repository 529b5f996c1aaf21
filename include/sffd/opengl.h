// sffd/opengl.h: sffd on the application's own OpenGL context (interop).
//
// The context must be OpenGL 4.3 core or later, or OpenGL ES 3.1 or later (the kernels' ES form, held
// to the ES 3.1 minimum limits unless SFFD_GLES_LIMITS=device; docs/GLES.md), and current on the calling thread whenever an sffd
// call that uses the device runs (opening, Deformer construction, deform(), result(), the
// destructors). sffd never switches contexts on an adopted device, and every call restores the
// state it changes: the current program, the storage, uniform, copy and pixel buffer bindings (the
// indexed ones too), and the bound VAO. Buffers it creates are its own and are deleted with it.
//
//   sffd::Device gl = sffd::opengl::adoptCurrentContext(
//       reinterpret_cast<sffd::opengl::GetProcAddress>(glfwGetProcAddress));
//   sffd::Deformer deformer(gl, mesh, lattice);
//   deformer.deform(lattice);
//   GLuint vbo = sffd::opengl::bufferOf(deformer, deformer.deviceOutput()[0]);   // draw from it
#pragma once
#include <sffd/deformer.h>
#include <sffd/device.h>

namespace sffd::opengl {

using Proc = void (*)();
using GetProcAddress = Proc (*)(const char* name);

// A Device on the context current on this thread, its GL entry points loaded through `getProc`
// (glfwGetProcAddress, eglGetProcAddress, ...). Its label is "gl-adopted", or "gles-adopted" on an
// OpenGL ES context. Throws a device Error when no context is current or it is older than OpenGL 4.3
// core (ES: 3.1).
Device adoptCurrentContext(GetProcAddress getProc);

// The GL buffer object holding a chunk of a Deformer's device output (its bytes from chunk.offset),
// valid until the next deform() or the Deformer's end; the writes are complete for later GL commands
// (a glMemoryBarrier(GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT | ...) has been issued).
unsigned bufferOf(const Deformer& deformer, const OutputChunk& chunk);

}  // namespace sffd::opengl
