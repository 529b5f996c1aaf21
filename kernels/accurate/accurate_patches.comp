#version 450
// Kernel accurate_patches: accurate FFD (Feng, Heng & Wong 1998; Feng & Peng 2000; METHOD.md 2) of
// knot-box sub-triangles, in three dispatches per chunk (params.range.z, layout.h):
//  stage 0, a thread per (sub-triangle, sample l): S_l = R(x(l/n)), the lattice volume at the principal
//     lattice points l/n of the flat sub-triangle (every sample finds its own knot box; the sub-triangle
//     lies in one, so R o x is a polynomial of total degree n = nu+nv+nw);
//  stage 1, a thread per sub-triangle: the exact triangular Bezier patch P = A_n^{-1} S (A_n^{-1}
//     computed on the host in double, once per n, in the parameter block where it fits): the lanes read
//     the same entry of A_n^{-1} at a time, a scalar read, where a thread per control point made every
//     read of it a gather (lavapipe 22.3 gathers lane by lane);
//  stage 2, a thread per (sub-triangle, tessellation vertex) at level L (src/pipelines/patch_output.h
//     layout): interior vertices B^n(lambda)·P; boundary vertices R(x(lambda)) directly, the value the
//     patch interpolates exactly there, computed from bits that both sub-triangles of a shared edge
//     have, so the output welds closed.
//     Normals: the patch's geometric normal P_lambda1 x P_lambda2, normalised, computed through the
//     identity P_lambda1 x P_lambda2 = cof(J) ((c1 - c0) x (c2 - c0)) with the parent's unit face normal
//     (the sub-triangle lies in the parent's plane): differencing the control points of the slivers
//     that knot-box clipping makes loses all float precision. It keeps the parent's orientation (also
//     where det J < 0) and jumps across sub-triangle edges, which is why accurate FFD shades
//     unsmoothly (METHOD.md 2.2, last paragraph).
// Why not one thread per sub-triangle throughout: llvmpipe and lavapipe end an invocation after 65535 loop
// iterations in all (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS, shared by every loop of the shader), which a
// whole patch at --tess 38 already exceeds; stage 1's m^2 is 18,496 at the largest degree (n = 15).
// The C++ twin is kernels/accurate/accurate_patches_cpu.cpp: the same operations in the same order.
#extension GL_GOOGLE_include_directive : require
#include "../common/prelude.glsl"
// Declared before lattice_eval.glsl, which then reads the lattice from the block when the host put it
// there (layout.h, AccurateParams): storage-buffer reads are what made these kernels slow on lavapipe.
layout(std140, SFFD_SET binding = SFFD_BINDING_PARAMS) uniform AccurateBlock { AccurateParams params; };
#define SFFD_LATTICE_INLINE 1
#include "../common/lattice_eval.glsl"

layout(std430, SFFD_SET binding = SFFD_BINDING_ACC_CHUNK) buffer AccChunk { real4 accChunk[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_ACC_SCRATCH) buffer AccScratch { real4 accScratch[]; };
// The sections of layout.h's ranges, by what they hold.
#define accCorners(i) accChunk[params.sections.y + (i)]
#define accNormals(i) accChunk[params.sections.x + (i)]
#define accPositions(i) accChunk[i]
#define accSamples(i) accScratch[i]
#define accPatches(i) accScratch[params.sections.z + (i)]
// The two constant tables, from the parameter block where each fits (layout.h, AccurateParams.tables).
#define accMatrix(i) latticeTableAt(params.tables.z, params.tables.x, i)
#define accTessBasis(i) latticeTableAt(params.tables.w, params.tables.y, i)

// The point (i, j, k) / d of the flat triangle (c0, c1, c2). Always precise (also in the fast
// variant): on a shared edge one weight is 0 and the sum of the other two terms is the same bits from
// both sides only without contraction into fma.
real3 accFlatPoint(real3 c0, real3 c1, real3 c2, uint i, uint j, uint k, uint d) {
  SFFD_PRECISE real l0 = sdiv(real(i), real(d));
  SFFD_PRECISE real l1 = sdiv(real(j), real(d));
  SFFD_PRECISE real l2 = sdiv(real(k), real(d));
  SFFD_PRECISE real3 r = (c0 * l0 + c1 * l1) + c2 * l2;
  return r;
}

// Row r of linear index idx in the triangular layout (index r(r+1)/2 + t, t <= r).
uint accRow(uint idx) {
  uint r = 0u;
  while ((r + 1u) * (r + 2u) / 2u <= idx) ++r;
  return r;
}

void main() {
  uint t = sffdThreadIndex();
  uint n = params.shape.x, m = params.shape.y, L = params.shape.z, nv = params.shape.w;
  uint stage = params.range.z;
  uint per = SFFD_ACC_THREADS_PER_SUB(stage, m, nv);
  uint local = t / per;
  if (local >= params.range.y) return;
  uint e = t - local * per;
  uint s = params.range.x + local;
  uint cs = uint(SFFD_ACC_CORNER_STRIDE) * s;
  real3 c0 = accCorners(cs).xyz, c1 = accCorners(cs + 1u).xyz, c2 = accCorners(cs + 2u).xyz;

  if (stage == SFFD_ACC_STAGE_SAMPLES) {
    uint r = accRow(e), q = e - r * (r + 1u) / 2u;
    real3 x = accFlatPoint(c0, c1, c2, n - r, r - q, q, n);
    LatticeSample S = latticeEvaluate(params.lattice, x);
    bool keep = !S.inside && params.lattice.degree.w == SFFD_OUTSIDE_KEEP;
    accSamples(s * m + e) = real4(keep ? x : S.value, 0);
    return;
  }

  if (stage == SFFD_ACC_STAGE_PATCHES) {
    for (uint k = 0u; k < m; ++k) {
      P real3 cp = real3(0);
      for (uint l = 0u; l < m; ++l) {
        P real3 v = cp + accSamples(s * m + l).xyz * accMatrix(l * m + k);
        cp = v;
      }
      accPatches(s * m + k) = real4(cp, 0);
    }
    return;
  }

  // Tessellation vertex e: row r, position q; barycentrics (L - r, r - q, q) / L.
  real3 nf = accCorners(cs + 3u).xyz;
  uint r = accRow(e), q = e - r * (r + 1u) / 2u;
  uint i = L - r, j = r - q, k = q;
  real3 x = accFlatPoint(c0, c1, c2, i, j, k, L);
  LatticeSample S = latticeEvaluate(params.lattice, x);
  bool keep = !S.inside && params.lattice.degree.w == SFFD_OUTSIDE_KEEP;
  P real3 pos = real3(0);
  if (i == 0u || j == 0u || k == 0u) {
    pos = keep ? x : S.value;
  } else {
    uint b = e * m;
    for (uint kk = 0u; kk < m; ++kk) {
      P real3 v = pos + accPatches(s * m + kk).xyz * accTessBasis(b + kk);
      pos = v;
    }
  }
  P real3 nrm = keep ? nf : latticeCofactorNormal(S, nf);
  if (!(sdot(nrm, nrm) > real(0))) nrm = nf;   // a singular point of the map
  accPositions(s * nv + e) = real4(pos, 0);
  accNormals(s * nv + e) = real4(snormalize(nrm), 0);
}
