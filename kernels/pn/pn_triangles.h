// Kernel K1 "PN triangles" (Vlachos et al. 2001 with the sharp-feature rule of Cui & Feng 2015;
// METHOD.md 3.2): per original triangle, the cubic PN geometry patch and quadratic normal patch.
// Runs on a GPU backend (kernels/pn/pn_triangles.comp) or on the CPU reference (pn_eval.h).
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

PnOutput pnTrianglesCpu(const PreparedMesh& mesh, KernelVariant variant);
// `maxChunk` (not 0) caps the triangles of one dispatch, to test chunking.
PnOutput pnTrianglesGpu(Backend& backend, const PreparedMesh& mesh, KernelVariant variant, size_t maxChunk = 0);

}  // namespace sffd
