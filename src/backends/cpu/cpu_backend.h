// The CPU backend: the Backend interface on host memory. Buffers are byte arrays; a dispatch runs the
// kernel's CPU entry (its C++ twin, kernels/<stage>/, found in cpu_kernels.cpp) over the dispatch's
// thread grid, split across the host's cores, before dispatch() returns. Strict and fast variants are
// the same arithmetic here: the strict kernels' operations in their order, in float or double, so in
// strict mode every GPU backend gives these bits. It is the reference the GPU backends are tested against.
//
// Timings: gpuMs is the dispatch's host wall time (a dispatch runs to completion inside dispatch(), so
// that is its device time), and limits.timestamps is true.
#pragma once
#include <memory>
#include <string_view>

#include "core/backend.h"
#include "kernels/common/cpu_kernel.h"

namespace sffd {

// Threads a dispatch runs on: every core (at most 256), or SFFD_CPU_THREADS where it is an integer 1..256
// (more than the cores is allowed: the tests split work as a larger machine would).
unsigned cpuThreadCount();
// An input Error when SFFD_CPU_THREADS is set to anything else (checked before any work: checkLibraryVariables,
// backend_select.h; cpuThreadCount() would take every core instead).
void checkCpuThreadsVariable();
// An input Error when SFFD_CPU_AVX2 is set to anything but 0 (the baseline copy) or 1 (the AVX2 copy where
// the processor has it, as when unset); cpuUsesAvx2() would take any other value as 1.
void checkCpuAvx2Variable();

namespace cpu {

struct Kernel {
  const char* name;     // the kernel's stem, as in cmake/Kernels.cmake
  size_t paramsSize;    // its parameter struct (kernels/common/layout.h)
  CpuKernelFn run;
};
// The CPU entry of a kernel; null when there is none.
const Kernel* findKernel(std::string_view name);

DeviceInfo deviceInfo();
std::unique_ptr<Backend> createBackend();

}  // namespace cpu
}  // namespace sffd
