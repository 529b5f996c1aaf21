// Classic FFD (Sederberg & Parry 1986; PyGeM, Blender): every vertex and its normal through the lattice
// volume, nothing else (METHOD.md 6). Kernel kernels/classic/classic_ffd.comp; its C++ twin is
// lattice_eval.h, run by the CPU backend through cpu::classicFfd.
#pragma once
#include <string>
#include <vector>

#include "core/backend.h"
#include "model/lattice_pack.h"
#include "model/mesh.h"

namespace sffd {

// Output buffers as the kernel writes them, widened to double: 4 values per vertex.
struct ClassicOutput {
  std::vector<double> positions;   // x, y, z, inside (1 or 0)
  std::vector<double> normals;     // x, y, z, 0 (unit)
  std::vector<DispatchTiming> timings;
  double wallMs = 0;
};

// The kernel on a backend, chunked within the device's binding and group-count limits (`maxChunk`
// vertices at most when not 0, to test chunking); everything downloaded. sffd::Deformer keeps its
// output on the device instead (src/pipelines/deformer_classic.cpp), with the two functions below.
ClassicOutput classicFfd(Backend& backend, const Mesh& mesh, const PackedLattice& lattice, KernelVariant variant,
                         size_t maxChunk = 0);

// Vertices one dispatch may cover on the device with reals of `realBytes`; `maxChunk` caps it when not 0.
size_t classicChunkVertices(const DeviceLimits& limits, size_t vertices, size_t realBytes, size_t maxChunk);

// One dispatch of the kernel over `count` vertices (4 reals each: positions with w = 1, normals w = 0),
// followed by a barrier. `in` and `out` each hold the positions, then from element `normalsAt` of the
// bound range the normals (layout.h, ClassicParams).
struct ClassicBindings {
  BufferBinding coeffs, frame, in, out;
};
// The kernel variant dispatchClassicFfd runs (Backend::precompile).
KernelUse classicKernel(const gpu::LatticeParams& lattice, KernelVariant variant);
void dispatchClassicFfd(Backend& backend, const gpu::LatticeParams& lattice, KernelVariant variant, size_t count,
                        const ClassicBindings& bindings, size_t normalsAt);

struct CpuKernelArgs;
namespace cpu {
// CPU entry of kernel classic_ffd (kernels/common/cpu_kernel.h).
void classicFfd(const CpuKernelArgs& args, uint64_t first, uint64_t last);
}  // namespace cpu

// Copies the deformed positions and normals into a mesh with the input's vertex order and connectivity.
Mesh applyClassicOutput(const Mesh& input, const ClassicOutput& out);

}  // namespace sffd
