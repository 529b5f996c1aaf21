// The kernels embedded in the binary at build time (tools/embed_kernels.cpp writes the table):
// SPIR-V for Vulkan in each variant, and the GLSL source with its #includes inlined for OpenGL.
// Nothing is loaded from a path at run time.
#pragma once
#include <cstddef>
#include <cstdint>
#include <chrono>
#include <span>
#include <string>
#include <string_view>

#include "core/backend.h"
#include "kernels/common/shader_layout.h"

namespace sffd {

// SPIR-V compiled for one set of assumptions (cmake/Kernels.cmake SFFD_SPECIALIZED_<kernel>).
struct SpecializedSpirv {
  uint32_t assumptions;
  const uint32_t* spirv[4];         // index variantIndex()
  size_t spirvWords[4];
};

struct EmbeddedKernel {
  const char* name;
  const char* glsl;                 // inlined source without variant defines
  const char* gles;                 // the same as OpenGL ES 3.1 ("#version 310 es"; f32 variants only)
  const uint32_t* spirv[4];         // index variantIndex(): strict + 2 * f64; assumptions a specialization constant
  size_t spirvWords[4];
  std::span<const SpecializedSpirv> specialized;
};

// The SPIR-V of a variant.
inline int variantIndex(KernelVariant v) { return (v.strict ? 1 : 0) + (v.f64 ? 2 : 0); }
// The SPIR-V a Vulkan pipeline of `variant` is made from: the module compiled for exactly its assumptions
// where the build made one (faster for lavapipe to translate), else the general one, whose specialization
// constant SFFD_SPEC_ASSUMPTIONS takes them. Empty if the kernel has no SPIR-V for the variant.
std::span<const uint32_t> spirvFor(const EmbeddedKernel& kernel, KernelVariant variant);
// One compiled pipeline or program per key.
inline uint64_t variantKey(KernelVariant v) { return uint64_t(variantIndex(v)) + 4 * uint64_t(v.assumptions); }
// "strict f32", "fast f64 assuming 0x5", ...: for messages and traces.
std::string variantName(KernelVariant v);
// The variant a lattice-evaluating kernel is dispatched with: assuming the lattice's degrees
// (SFFD_ASSUME_DEGREE2 or _GENERAL_DEGREE) and, given the deform or accurate kernels' parameter block,
// where the lattice and the kernel's constant tables are read from.
KernelVariant forLattice(KernelVariant v, const gpu::LatticeParams& lattice);
KernelVariant forLattice(KernelVariant v, const gpu::DeformParams& params);
KernelVariant forLattice(KernelVariant v, const gpu::AccurateParams& params);
// The variant a backend compiles for `device`: with SFFD_ASSUME_ROLLED_LOOPS on llvmpipe and lavapipe of
// Mesa 23 and later (prelude.glsl sffdRolled; measured on 22.3, which is left without, and 25.0); strict
// variants with SFFD_ASSUME_LOOSE_DIVISION on every driver but llvmpipe and lavapipe, whose a / b and sqrt
// are correctly rounded (SFFD_STRICT_ROUNDING=fixup or =driver in the environment forces it on or off);
// SFFD_ASSUME_ONE_SAMPLE_SITE, which a small one-shot job asks for, kept only on lavapipe below Mesa 23.
KernelVariant forDevice(KernelVariant v, const DeviceInfo& device);
// An input Error when SFFD_STRICT_ROUNDING is set to anything but fixup or driver (checked before any work:
// checkLibraryVariables, backend_select.h; forDevice() would take another value as unset).
void checkStrictRoundingVariable();

std::span<const EmbeddedKernel> embeddedKernels();
// nullptr when no kernel has that name.
const EmbeddedKernel* findKernel(std::string_view name);
// GLSL source of a variant for an OpenGL (es: OpenGL ES) driver: the variant defines follow the #version line.
std::string glslForVariant(const EmbeddedKernel& kernel, KernelVariant variant, bool es = false);

// Whether SFFD_TRACE_COMPILE is 1 (read once).
bool compileTraceOn();
// An input Error when SFFD_TRACE_COMPILE is set to anything but 0 or 1.
void checkTraceCompileVariable();
// With tracing on, the device time of the first dispatch of each label in the process, one line
// `sffd: first dispatch LABEL: MS ms`: on llvmpipe and lavapipe it includes the code generation.
void traceFirstDispatch(std::string_view label, double deviceMs);

// The creation of one kernel variant by a backend (Vulkan pipeline, GL program), from construction to
// destruction. With SFFD_TRACE_COMPILE=1 in the environment it prints one line `sffd: compile BACKEND
// KERNEL VARIANT: MS ms` to stderr at the end: which variants a run compiles and what creating each costs
// (llvmpipe and lavapipe generate the machine code later, at the first dispatch: docs/performance/kernels.md
// "Two Mesa generations and the cold start"). Always, it counts as a compile in flight
// (oldestCompileInFlightSeconds), so that a watchdog can tell a driver that is compiling from one that is
// hung: NVIDIA's GL compiler takes 75 s over the strict double clip_write (docs/CONFORMANCE.md "Statuses").
class CompileScope {
 public:
  CompileScope(std::string_view backend, std::string_view kernel, KernelVariant variant);
  ~CompileScope();
  CompileScope(const CompileScope&) = delete;
  CompileScope& operator=(const CompileScope&) = delete;
  // Adds a few words to the trace line ("from the shader cache").
  void note(std::string_view words);

 private:
  std::string what_;   // empty: tracing is off
  std::chrono::steady_clock::time_point start_;
};

// How long the oldest CompileScope alive in this process has been; a negative number when none is.
double oldestCompileInFlightSeconds();

}  // namespace sffd
