// Kernel K1 "PN triangles" (Vlachos et al. 2001 with the sharp-feature rule of Cui & Feng 2015;
// METHOD.md 3.2): per original triangle, the cubic PN geometry patch and quadratic normal patch.
// Kernel kernels/pn/pn_triangles.comp; its C++ twin is pn_eval.h, run by the CPU backend through cpu::pnTriangles.
#pragma once
#include <vector>

#include "core/backend.h"
#include "model/prepared_mesh.h"

namespace sffd {

struct PnOutput {
  std::vector<double> records;   // SFFD_PN_STRIDE * 4 values per triangle (x, y, z, 0)
  std::vector<DispatchTiming> timings;
  double wallMs = 0;
};

// The mesh vertices' range as the pre-compute kernels read it (SFFD_BINDING_MESH_VERTICES): the
// positions, then the normals from element mesh.positions.size() / 4 (PnParams/ClipParams range.z).
std::vector<double> meshVertexRange(const PreparedMesh& mesh);

// `maxChunk` (not 0) caps the triangles of one dispatch, to test chunking.
PnOutput pnTriangles(Backend& backend, const PreparedMesh& mesh, KernelVariant variant, size_t maxChunk = 0);

struct CpuKernelArgs;
namespace cpu {
// CPU entry of kernel pn_triangles (kernels/common/cpu_kernel.h).
void pnTriangles(const CpuKernelArgs& args, uint64_t first, uint64_t last);
}  // namespace cpu

}  // namespace sffd
