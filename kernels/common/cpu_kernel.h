// kernels/common/cpu_kernel.h: what a kernel's CPU entry sees, the C++ side of a GLSL main(): the
// variant, the parameter block (binding SFFD_BINDING_PARAMS) and the storage ranges bound to slots
// 1..SFFD_MAX_STORAGE_BINDINGS. The CPU backend (src/backends/cpu) calls an entry with slices of the
// thread indices that sffdThreadIndex() gives on a GPU; each entry sits beside its kernel's GLSL in
// kernels/<stage>/ and calls that kernel's C++ twin.
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <type_traits>

#include <sffd/error.h>
#include "core/backend.h"
#include "kernels/common/lattice_eval.h"
#include "kernels/common/shader_layout.h"

namespace sffd {

struct CpuKernelArgs {
  struct Range {
    std::byte* data = nullptr;
    uint64_t bytes = 0;
  };
  std::string_view kernel;
  KernelVariant variant;
  const void* params = nullptr;   // 16-byte aligned, at least the kernel's parameter struct
  Range slots[SFFD_MAX_STORAGE_BINDINGS + 1];

  template <class P>
  const P& paramsAs() const { return *static_cast<const P*>(params); }

  // The range bound at `slot` as elements of T (real4 data: 4 reals an element), at least `count` of
  // them: a GPU reads past a range's end harmlessly, the host would not.
  template <class T>
  std::span<T> array(uint32_t slot, uint64_t count = 0) const {
    const Range& r = slots[slot];
    if (!r.data) fail("slot " + std::to_string(slot) + " is not bound");
    if (r.bytes / sizeof(T) < count)
      fail("slot " + std::to_string(slot) + " holds " + std::to_string(r.bytes / sizeof(T)) + " elements, the dispatch needs " +
           std::to_string(count));
    return {reinterpret_cast<T*>(r.data), size_t(r.bytes / sizeof(T))};
  }

  // An index read from the data (a vertex or parent id) that falls outside its array.
  void check(bool ok, const char* what) const {
    if (!ok) fail(what);
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw Error(ErrorKind::Internal, "cpu: " + std::string(kernel) + ": " + what);
  }
};

// A kernel's CPU entry: runs threads [first, last) of the dispatch, as its GLSL main() would.
using CpuKernelFn = void (*)(const CpuKernelArgs& args, uint64_t first, uint64_t last);

// Whether the CPU entries run their AVX2 copies (withAvx2): on an x86-64 host with AVX2, unless
// SFFD_CPU_AVX2=0 (read at each call, so a test can compare both copies in one process).
bool cpuUsesAvx2();

// Runs Twin, a kernel's twin on threads [first, last), as compiled for AVX2 where the host has it, else as
// compiled for the build's baseline. The copy for AVX2 has every call inlined into it (flatten) so that all
// of it runs with AVX2; what is not inlined is called in its baseline form (a function's target is its
// own), so no other function is compiled for AVX2 (tools/check_avx2_copies.py). Both copies do the same
// operations in the same order, and AVX2 brings no fused multiply-add (that is the "fma" target, and
// -ffp-contract=off forbids it anyway): the same bits. The twins' vectors of eight (LanesOf, rvec.h)
// become one instruction instead of two. Sanitizer builds keep the baseline copy only (CMakeLists.txt).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(SFFD_CPU_BASELINE_ONLY)
#define SFFD_CPU_AVX2_COPIES 1
template <CpuKernelFn Twin>
__attribute__((target("avx2"), flatten)) void runTwinWithAvx2(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  Twin(a, first, last);
}
#endif
template <CpuKernelFn Twin>
void withAvx2(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
#ifdef SFFD_CPU_AVX2_COPIES
  if (cpuUsesAvx2()) return runTwinWithAvx2<Twin>(a, first, last);
#endif
  Twin(a, first, last);
}

// The lattice of bindings 1 and 2, checked against the sizes its parameters imply.
template <class Real>
LatticeEvaluator<Real> boundLattice(const CpuKernelArgs& a, const gpu::LatticeParams& L, const Real* frame = nullptr,
                                    const Real* coeffs = nullptr) {
  const uint32_t deg[3] = {L.degree.x, L.degree.y, L.degree.z}, boxes[3] = {L.boxes.x, L.boxes.y, L.boxes.z},
                 offs[3] = {L.break_offset.x, L.break_offset.y, L.break_offset.z};
  uint64_t frameReals = SFFD_FRAME_BREAKS, perBox = 1;
  for (int k = 0; k < 3; ++k) {
    a.check(deg[k] <= SFFD_MAX_DEGREE && boxes[k] > 0, "lattice degree or box count out of range");
    frameReals = std::max<uint64_t>(frameReals, uint64_t(offs[k]) + boxes[k] + 1);
    perBox *= deg[k] + 1;
  }
  a.check(L.boxes.w >= perBox, "lattice box holds fewer coefficients than its degrees need");
  // Given pointers (the deform kernels' inline lattice) were sized by the host; the bindings are checked.
  if (!frame) frame = a.array<const Real>(SFFD_BINDING_LATTICE_FRAME, frameReals).data();
  if (!coeffs)
    coeffs = a.array<const Real>(SFFD_BINDING_LATTICE_COEFFS, 4ull * boxes[0] * boxes[1] * boxes[2] * L.boxes.w).data();
  return LatticeEvaluator<Real>(L, frame, coeffs);
}

// The reals from vec4 `first` of a parameter block's inline_lattice (layout.h, DeformParams and
// AccurateParams) where the host put them there (`present`, float variants only), else nullptr.
template <class Real>
const Real* blockReals(const gpu::Vec4 (&block)[SFFD_INLINE_LATTICE_VEC4], bool present, uint32_t first) {
  if constexpr (std::is_same_v<Real, float>) return present && first < SFFD_INLINE_LATTICE_VEC4 ? &block[first].x : nullptr;
  return nullptr;
}

// `reals` reals of a kernel's constant table, as latticeTableAt() reads them: from vec4 `inlineAt` of the
// parameter block (0: not there; float variants only), else from real `frameAt` of the lattice frame range.
template <class Real>
const Real* tableReals(const CpuKernelArgs& a, const gpu::Vec4 (&block)[SFFD_INLINE_LATTICE_VEC4], uint32_t inlineAt,
                       uint32_t frameAt, uint64_t reals) {
  a.check(!inlineAt || inlineAt + (reals + 3) / 4 <= SFFD_INLINE_LATTICE_VEC4, "an inline table overruns the parameter block");
  if (const Real* r = blockReals<Real>(block, inlineAt != 0, inlineAt)) return r;
  return a.array<const Real>(SFFD_BINDING_LATTICE_FRAME, uint64_t(frameAt) + reals).data() + frameAt;
}

// The lattice of a parameter block that may carry it (break_offset.w), as lattice_eval.glsl reads it.
template <class Real>
LatticeEvaluator<Real> boundLattice(const CpuKernelArgs& a, const gpu::LatticeParams& L,
                                    const gpu::Vec4 (&block)[SFFD_INLINE_LATTICE_VEC4]) {
  const bool inlined = L.break_offset.w != 0;
  return boundLattice<Real>(a, L, blockReals<Real>(block, inlined, 0), blockReals<Real>(block, inlined, L.break_offset.w));
}

}  // namespace sffd
