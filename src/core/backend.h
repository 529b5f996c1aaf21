// The backend interface: the small surface every compute backend implements (src/backends/vulkan,
// opengl, and cpu, which runs the kernels' C++ entries on the host). Plain buffers, named kernels from the
// embedded registry, explicit barriers and per-dispatch timestamps. Pipelines (kernels/<stage>/*.cpp,
// src/pipelines) are written once against this interface; backend_contract_test.cc checks it.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <sffd/device.h>
#include <sffd/error.h>

namespace sffd {

// Variant of a kernel (see kernels/common/prelude.glsl).
struct KernelVariant {
  bool strict = false;   // every operation precise, fixed order: bit-identical across APIs
  bool f64 = false;      // double-precision arithmetic and storage
  // SFFD_ASSUME_* bits (kernels/common/layout.h): what a lattice-evaluating kernel is compiled to
  // assume about its lattice, so the driver compiles less code (docs/performance/kernels.md).
  // 0: nothing, decided at run time. The same results either way.
  uint32_t assumptions = 0;
  bool operator==(const KernelVariant&) const = default;
};

using BufferId = uint32_t;

// A storage buffer range bound at a binding slot of the kernel (slot numbers from kernels/common/layout.h).
struct BufferBinding {
  uint32_t slot = 0;
  BufferId buffer = 0;
  uint64_t offset = 0;
  uint64_t size = 0;   // 0: from offset to the end of the buffer
};

struct Dispatch {
  std::string_view kernel;                  // name in the kernel registry (the .comp file's stem)
  KernelVariant variant;
  const void* params = nullptr;             // the kernel's parameter block (binding SFFD_BINDING_PARAMS)
  size_t paramsSize = 0;
  std::vector<BufferBinding> buffers;
  uint32_t groups[3] = {1, 1, 1};
  std::string_view label;                   // names the timing record; defaults to the kernel name
};

// A kernel variant a job is going to dispatch (Backend::precompile).
struct KernelUse {
  std::string_view kernel;   // name in the kernel registry
  KernelVariant variant;
};

struct DispatchTiming {
  std::string label;
  double gpuMs = -1;   // from timestamp queries (the CPU backend: the dispatch's wall time); -1 when the device has none
};

class Backend {
 public:
  virtual ~Backend() = default;
  virtual const DeviceInfo& info() const = 0;

  virtual BufferId createBuffer(uint64_t bytes) = 0;
  // Called by destructors: never throws for a buffer the backend made.
  virtual void destroyBuffer(BufferId buffer) = 0;
  virtual void upload(BufferId buffer, uint64_t offset, const void* data, uint64_t bytes) = 0;
  // Waits for all work that writes the buffer, then copies it out.
  virtual void download(BufferId buffer, uint64_t offset, void* data, uint64_t bytes) = 0;

  // Records (or issues) one dispatch; compiles the kernel variant on first use, or waits for its
  // build that precompile started.
  virtual void dispatch(const Dispatch& d) = 0;
  // A hint, in the order of first use: starts building these variants where the backend can do so
  // away from the calling thread (Vulkan: pipelines on other threads while the caller prepares its
  // inputs and runs the earlier kernels). A build's error surfaces at the dispatch that needs it.
  virtual void precompile(const std::vector<KernelUse>& kernels) { (void)kernels; }
  // Makes the writes of earlier dispatches visible to later dispatches and transfers.
  virtual void barrier() = 0;
  // Submits everything recorded and waits for it.
  virtual void finish() = 0;
  // Timings of the dispatches finished since the last call, in dispatch order.
  virtual std::vector<DispatchTiming> takeTimings() = 0;
  // The end of a call of the public API (Device::open, a Deformer's calls and destruction): a backend
  // bound to the calling thread meanwhile (GL: sffd's own EGL or OSMesa context) lets go of it, so that
  // the next call may come from another thread. Never throws.
  virtual void endCall() noexcept {}
};

// Splits a 1-D job of `threads` threads into a grid within the device's group-count limits
// (SFFD_LOCAL_SIZE threads a group; kernels rebuild the index with sffdThreadIndex()).
void gridFor(uint64_t threads, const DeviceLimits& limits, uint32_t groups[3]);

// The error for a double-precision run the device cannot do: a usage error (exit 2) on OpenGL ES,
// which has no doubles at all, a device error (exit 3) on a device that lacks the feature.
Error noFloat64Error(const DeviceInfo& info);

}  // namespace sffd
