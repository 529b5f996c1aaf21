// Kernel K3 "deform" of smooth FFD (Cui & Feng 2015, improved by Lu & Feng; METHOD.md 3.4): each
// sub-triangle becomes a cubic triangular Bezier patch fitted to the exactly deformed surface, with a
// cubic normal patch, creases kept sharp, tessellated at level L. Kernels kernels/smooth/deform_smooth.comp
// (fused) and deform_step_*.comp (split); their C++ twin and CPU entries are smooth_deform_cpu.cpp.
#pragma once
#include <vector>

#include "core/backend.h"
#include "model/lattice_pack.h"
#include "pipelines/patch_output.h"
#include "kernels/clip/regular_clip.h"
#include "kernels/common/shader_layout.h"

namespace sffd {

// The interior fitting points of the degree-s sampling lattice with their centre-fit weights
// (closed form of the constrained least squares, METHOD.md 3.4 step 3): SFFD_FIT_STRIDE values each.
struct FitTable {
  int s = 6;
  int points = 0;
  std::vector<double> data;
};
FitTable makeFitTable(int s);

struct SmoothOutput {
  std::vector<double> patches;   // SFFD_PATCH_STRIDE * 4 per sub-triangle
  std::vector<double> tess;      // 2 * tessVertexCount(level) * 4 per sub-triangle: positions, then normals
  int level = 10;
  std::vector<DispatchTiming> timings;
  double wallMs = 0;
};

// The deform stage on a backend, chunked within its limits. split: one dispatch per step (deform.sample:
// steps 1, 2, 4; deform.fit: 3; deform.adjust: 5; deform.tessellate: 6), for per-step timings; the same
// output as the fused kernel.
// `maxChunk` (not 0) caps the sub-triangles of one chunk, to test chunking.
SmoothOutput smoothDeform(Backend& backend, const PackedLattice& lattice, const SubTriangleRecords& subs,
                          const FitTable& fit, int level, KernelVariant variant, bool split = false, size_t maxChunk = 0);

// The deform stage's dispatches over `count` sub-triangles (params.range set by the caller): the
// fused kernel, or with `split` the four step kernels (the output range's samples then hold their
// intermediate data).
// Shared by smoothDeform and DeformSession.
// frame: deformFrameRange (the lattice frame, then the fit table); out: the sections deformOutSections lays out.
struct DeformBuffers {
  BufferId coeffs = 0, frame = 0, records = 0, out = 0;
};
// The output range of a chunk of `count` sub-triangles (layout.h, SFFD_BINDING_DEFORM_OUT): sets
// params.sections.z (patches) and .w (samples, with `split`); returns the range's real4 elements.
uint64_t deformOutSections(gpu::DeformParams& params, uint64_t count, int level, int fitPoints, bool split);
// The kernel variants dispatchDeform runs for `params`, in order (Backend::precompile).
std::vector<KernelUse> deformKernels(const gpu::DeformParams& params, KernelVariant variant, bool split);
void dispatchDeform(Backend& backend, const gpu::DeformParams& params, const DeformBuffers& buffers, size_t count,
                    KernelVariant variant, bool split);

// What the patch vertices need of the sub-triangle records: each one's parent and its corners'
// barycentrics there (76 bytes a sub-triangle instead of the records' 688).
struct SubTrianglePreImages {
  std::vector<uint32_t> parent;   // per sub-triangle
  std::vector<double> lam;        // 9 per sub-triangle: corner c's barycentrics from 3c
  size_t size() const { return parent.size(); }
  // Appends `count` sub-triangles from their headers (4 words each) and records (SFFD_SUB_STRIDE real4 each).
  template <class Real>
  void append(const uint32_t* headers, const Real* records, size_t count) {
    for (size_t s = 0; s < count; ++s) {
      parent.push_back(headers[4 * s]);
      for (int c = 0; c < 3; ++c)
        for (int a = 0; a < 3; ++a) lam.push_back(double(records[(s * SFFD_SUB_STRIDE + SFFD_SUB_LAM + c) * 4 + a]));
    }
  }
};

// The tessellation with each vertex's pre-image in its parent triangle (for the writers and the
// error analysis).
PatchVertices patchVerticesOf(const SubTriangleRecords& subs, const SmoothOutput& out);
// The same, a chunk at a time: sub-triangles [first, first + count) become the patches from `at` on of
// `patches` (level set; resized to at + count patches: PatchVertices::resize), their tessellation at `tess`
// as the device holds it (2 nv (x, y, z, w) a sub-triangle: positions, then normals), widened to double
// here. `at`: patchCount() appends (room reserved by the caller: PatchVertices::reserve), 0 refills a slice.
void writePatchVertices(const SubTrianglePreImages& subs, size_t first, size_t count, const float* tess, size_t at,
                        PatchVertices& patches);
void writePatchVertices(const SubTrianglePreImages& subs, size_t first, size_t count, const double* tess, size_t at,
                        PatchVertices& patches);

struct CpuKernelArgs;
namespace cpu {
// CPU entries of the deform kernels (smooth_deform_cpu.cpp).
void deformSmooth(const CpuKernelArgs& args, uint64_t first, uint64_t last);
void deformStepSample(const CpuKernelArgs& args, uint64_t first, uint64_t last);
void deformStepFit(const CpuKernelArgs& args, uint64_t first, uint64_t last);
void deformStepAdjust(const CpuKernelArgs& args, uint64_t first, uint64_t last);
void deformStepTessellate(const CpuKernelArgs& args, uint64_t first, uint64_t last);
}  // namespace cpu

}  // namespace sffd
