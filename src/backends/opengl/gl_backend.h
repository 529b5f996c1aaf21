// OpenGL 4.3+ core and OpenGL ES 3.1 compute driver: implements sffd::Backend on a current GL context
// obtained from one of the context providers (gl_context.h): EGL surfaceless (GL or ES), OSMesa, or a
// GLFW window. On ES it holds itself to the ES 3.1 minimum limits (gl_es_limits.h) unless asked not to.
#pragma once
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/backend.h"
#include "backends/opengl/gl_context.h"   // Provider

namespace sffd::gl {

struct Options {
  Provider provider = Provider::Auto;   // Auto: SFFD_GL_PROVIDER if set, else EGL surfaceless, then OSMesa
  std::string deviceSubstring;          // refuse a context whose GL_RENDERER does not contain it (case-insensitive)
  bool deviceLimits = false;            // ES: the device's own limits, not the ES 3.1 minima (also SFFD_GLES_LIMITS=device)
};

// What a compiled kernel program uses, as GL reports it (glGetProgramInterfaceiv/glGetProgramResourceiv).
struct ProgramResources {
  int storageBlocks = 0;          // active shader storage blocks
  int maxStorageBinding = -1;     // highest binding index of them
  int maxUniformBlockBytes = 0;   // largest active uniform block (GL_BUFFER_DATA_SIZE)
  int groupSize[3] = {0, 0, 0};   // GL_COMPUTE_WORK_GROUP_SIZE
};

// Whether a GL driver of this GL_VENDOR rounds doubles to float inside the kernels (NVIDIA's: see
// gl_backend.cpp), so that its devices report no float64.
bool doublesLoseBits(std::string_view vendor);
// One entry per headless provider that gives a GL 4.3+ core context. Throws a device Error when none does.
std::vector<DeviceInfo> listDevices();
std::unique_ptr<Backend> createBackend(const Options& options);
// An input Error when SFFD_GLES_LIMITS is set to anything but minimum (the default) or device.
void checkGlesLimitsVariable();
// A backend on a context the caller made (the viewer's visible GLFW window); the backend activates it
// before its GL calls and keeps it alive. Throws a device Error when it is not GL 4.3+ core.
std::unique_ptr<Backend> createBackendOn(std::shared_ptr<Context> context);
// The GL buffer object behind a buffer of a GL backend, for drawing from it in the same context
// (0 when `backend` is not a GL backend or has no such buffer).
unsigned glBufferObject(const Backend& backend, BufferId buffer);
// The resources of a kernel variant's program on a GL or GLES backend (compiled on first use).
const ProgramResources& programResources(Backend& backend, std::string_view kernel, KernelVariant variant);

}  // namespace sffd::gl
