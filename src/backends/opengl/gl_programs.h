// The GL backend's compute programs of the embedded kernels, one per (kernel, variant) on one context:
// the GLSL of the variant the device should run (forDevice), its "#version" fitted to the context,
// compiled and linked on first use or issued ahead (precompile) where the driver compiles on threads of
// its own (KHR_parallel_shader_compile), its resources read back and, on an ES context held to the ES 3.1
// minimum limits, checked against them. The Vulkan backend's counterpart is vk_kernels.h.
// Every method expects the context current (the backend activates it first).
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "backends/opengl/gl_backend.h"   // ProgramResources
#include "core/kernel_registry.h"

namespace sffd::gl {

struct Program {
  unsigned name = 0;               // the GL program object
  int paramsBlockSize = -1;        // GL_UNIFORM_BLOCK_DATA_SIZE of the block at binding 0 (-1: none)
  ProgramResources resources;
};

class Programs {
 public:
  // `device` is the backend's, outliving this; `glVersion` the context's (43 for 4.3); `parallelCompile`:
  // the driver compiles on threads of its own, so builds issued ahead do not block the caller.
  Programs(const DeviceInfo& device, int glVersion, bool es, bool heldToEsMinimum, bool parallelCompile);
  Programs(const Programs&) = delete;
  Programs& operator=(const Programs&) = delete;

  // The linked program of `variant` (forDevice's), built now if it was neither built nor issued.
  // Throws an internal Error when the driver refuses the source, a device Error when the device lacks
  // float64 for it or (held to the ES minima) the program is past them.
  const Program& get(const EmbeddedKernel& kernel, KernelVariant variant);
  // Issues the compile and link of each use where the driver compiles on its own threads; a no-op elsewhere
  // (a compile would block the caller: each is then built at its first use).
  void precompile(const std::vector<KernelUse>& uses);
  // Ends the compile scope of each build issued ahead that the driver has finished, so that an unused
  // one (a job that failed before its dispatch) is not taken for a compile in flight.
  void settle();
  // Deletes every program and pending build (the context current); without it they are left to the
  // context's end, as for a backend whose device may still use them.
  void release();

 private:
  // A program whose compile and link are issued and not yet checked: with KHR_parallel_shader_compile the
  // driver works on it on its own threads until the first dispatch asks for its status. It counts as a
  // compile in flight (and SFFD_TRACE_COMPILE times it) from its issue until settle() sees it done
  // (GL_COMPLETION_STATUS_KHR) or it is first used.
  struct Build {
    unsigned shader = 0, program = 0;
    std::unique_ptr<CompileScope> compiling;
  };
  using Key = std::pair<const EmbeddedKernel*, uint64_t>;
  void start(const EmbeddedKernel& kernel, KernelVariant variant);
  Program finish(const EmbeddedKernel& kernel, KernelVariant variant, Build b);

  const DeviceInfo& device_;
  int glVersion_;
  bool es_, heldToEsMinimum_, parallelCompile_;
  std::map<Key, Program> programs_;
  std::map<Key, Build> builds_;   // issued ahead, not yet asked for
};

}  // namespace sffd::gl
