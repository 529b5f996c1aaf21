// Accurate FFD (Feng, Heng & Wong 1998; Feng & Peng 2000; METHOD.md 2): the reference method.
// Every triangle is clipped against the knot boxes (knot_box_clip.h); on each knot-box sub-triangle the
// lattice volume composed with the flat sub-triangle is a polynomial of total degree n = nu+nv+nw, so it
// is exactly a triangular Bezier patch of degree n, found by interpolation at the principal lattice:
// P = A_n^{-1} S, A_n[l][k] = B^n_k(l/n) (linear index order of METHOD.md 0). Each patch is then
// tessellated at level L (patch_output.h).
//
// Kernel kernels/accurate/accurate_patches.comp, three dispatches per chunk: a thread per sample, per
// control point and per tessellation vertex, because llvmpipe ends an invocation after 65535 loop
// iterations in all, which one thread per patch exceeds at --tess 38. Its C++ twin, run by the CPU
// backend, is accurate_patches_cpu.cpp (double is the oracle; float in the strict kernels' order
// matches the strict kernels bit for bit).
//
// Tessellation: interior vertices are B^n(lambda)·P. Boundary vertices are R(x_flat(lambda)), the
// value the patch interpolates exactly there, computed from bits both sub-triangles of a shared edge
// have, so neighbouring patches share bit-identical boundary vertices and a closed input welds into a
// closed output. Normals are the patch's geometric normal P_l1 x P_l2, normalised, computed through
// the identity P_l1 x P_l2 = cof(J) ((c1 - c0) x (c2 - c0)) with the parent's unit face normal (the
// sub-triangle lies in the parent's plane): differencing the control points of the slivers that
// knot-box clipping makes would lose all float precision (0.5 degree on sphere.obj in float). The
// normal keeps the parent's orientation, also where det J < 0. It jumps across sub-triangle edges:
// accurate FFD shades unsmoothly, which is what smooth FFD is for (METHOD.md 2.2).
//
// Exactness: the composition is a polynomial only where the map is one. With OutsideMode::Keep (PyGeM
// lattices), a sub-triangle that straddles the lattice box is not, and there the patch interpolates
// the unmoved/moved samples instead of reproducing the map.
#pragma once
#include <vector>

#include "core/backend.h"
#include "model/lattice.h"
#include "model/lattice_pack.h"
#include "model/mesh.h"
#include "pipelines/patch_output.h"
#include "model/sub_triangles.h"

namespace sffd {

// Number of control points of a triangular Bezier patch of degree n: (n+1)(n+2)/2.
inline int triangleControlPoints(int n) { return (n + 1) * (n + 2) / 2; }
// Multi-index (i, j, k) of linear index `idx` in degree n (METHOD.md 0: i = n..0, then j = n-i..0).
void triangleMultiIndex(int n, int idx, int& i, int& j, int& k);
// B^n_{ijk}(lambda) = n!/(i!j!k!) l0^i l1^j l2^k.
double triangleBernstein(int n, int i, int j, int k, const glm::dvec3& lambda);

// A_n, row-major m x m: A[l][k] = B^n_k(l/n), l and k in linear index order.
std::vector<double> interpolationMatrix(int n);
// A_n^{-1}, row-major: computed once per n (n = 1..SFFD_ACC_MAX_DEGREE) by Gauss-Jordan elimination
// with partial pivoting in long double, rounded to double, and cached. Thread-safe.
const std::vector<double>& interpolationInverse(int n);
// B^n_k(lambda_v) for every tessellation vertex v of level L (rows of m), in double.
std::vector<double> tessellationBasis(int n, int level);

// The input of the accurate kernel.
struct AccurateJob {
  int degree = 0;                     // patch degree n = nu+nv+nw
  int level = 10;                     // tessellation level L
  std::vector<SubTriangle> subs;      // knot-box sub-triangles, each in one knot box
  // Per sub-triangle SFFD_ACC_CORNER_STRIDE x 4 values: the flat corners sum_i lam_i V_i (x, y, z, 0),
  // then the parent's unit face normal.
  std::vector<double> corners;
  size_t count() const { return subs.size(); }
};

// Builds the job from sub-triangles (clipAgainstKnotBoxes(mesh, lattice)); throws an input Error when
// the patch degree exceeds SFFD_ACC_MAX_DEGREE or the level is outside 1..kMaxTessLevel.
AccurateJob makeAccurateJob(const Mesh& mesh, const Lattice& lattice, std::vector<SubTriangle> subs, int level);

// Kernel outputs, widened to double, 4 values per element (x, y, z, 0).
struct AccurateOutput {
  std::vector<double> controlPoints;   // m per sub-triangle
  std::vector<double> positions;       // (L+1)(L+2)/2 per sub-triangle
  std::vector<double> normals;         // the same, unit
  std::vector<DispatchTiming> timings;
  double wallMs = 0;
};

// The kernel on a backend, chunked within the device's binding and group-count limits (`maxChunk`
// patches at most when not 0, to test chunking); everything downloaded. sffd::Deformer keeps its
// output on the device instead (src/pipelines/deformer_accurate.cpp), with the three functions below.
AccurateOutput accurateFfd(Backend& backend, const AccurateJob& job, const PackedLattice& lattice, KernelVariant variant,
                           size_t maxChunk = 0);

// A_n^{-1} transposed (sample-major), as the kernel reads it (after the frame in the lattice frame range).
std::vector<double> accurateKernelMatrix(int n);
// What the kernel reads from the lattice frame binding: the frame's reals, A_n^{-1} (accurateKernelMatrix)
// and the tessellation basis (tessellationBasis), and where the two tables begin (AccurateParams.tables).
struct AccurateFrame {
  std::vector<double> reals;
  uint32_t matrixAt = 0, basisAt = 0;
};
AccurateFrame accurateFrame(const std::vector<double>& latticeFrame, int degree, int level);
// The kernel's parameter block but for the chunk's range, shape and sections: the lattice and the
// frame's tables, and in the float variants the lattice and the tables inline where they fit (layout.h,
// AccurateParams; the same bits either way).
gpu::AccurateParams accurateParamsFor(const PackedLattice& lattice, bool f64, const AccurateFrame& frame);
// Sub-triangles one chunk may hold on the device with reals of `realBytes`; `maxChunk` caps it when not 0.
size_t accurateChunkPatches(const DeviceLimits& limits, const AccurateJob& job, size_t realBytes, size_t maxChunk);
// The three dispatches (samples, control points, tessellation) over `count` sub-triangles, each
// followed by a barrier. The bindings: coefficients, the accurateFrame, the chunk range (positions,
// normals from element `normalsAt`, corners from `cornersAt`) and the scratch range (samples, control
// points from element `patchesAt`); layout.h, AccurateParams.
struct AccurateBindings {
  BufferBinding coeffs, frame, chunk, scratch;
  uint32_t normalsAt = 0, cornersAt = 0, patchesAt = 0;
};
// The kernel variant dispatchAccurateChunk runs (Backend::precompile).
KernelUse accurateKernel(const gpu::AccurateParams& params, KernelVariant variant);
// `params`: accurateParamsFor's block.
void dispatchAccurateChunk(Backend& backend, const gpu::AccurateParams& params, KernelVariant variant, const AccurateJob& job,
                           size_t count, const AccurateBindings& bindings);

// Per patch its parent, per tessellation vertex its pre-image barycentrics in the parent
// (sum_i lambda_i lam_i), its position and normal.
PatchVertices accuratePatchVertices(const AccurateJob& job, const AccurateOutput& out);
// The same, a chunk at a time: sub-triangles [first, first + count) become the patches from `at` on of
// `patches` (level set; resized to at + count patches: PatchVertices::resize), their positions and normals
// (x, y, z, w) a tessellation vertex as the device holds them, widened to double here. `at`: patchCount()
// appends (room reserved by the caller: PatchVertices::reserve), 0 refills a slice.
void writeAccuratePatchVertices(const AccurateJob& job, size_t first, size_t count, const float* positions,
                                const float* normals, size_t at, PatchVertices& patches);
void writeAccuratePatchVertices(const AccurateJob& job, size_t first, size_t count, const double* positions,
                                const double* normals, size_t at, PatchVertices& patches);

struct CpuKernelArgs;
namespace cpu {
// CPU entry of kernel accurate_patches (accurate_patches_cpu.cpp).
void accuratePatches(const CpuKernelArgs& args, uint64_t first, uint64_t last);
}  // namespace cpu

}  // namespace sffd
