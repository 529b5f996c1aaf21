#version 450
// Kernel accurate_patches: accurate FFD (Feng, Heng & Wong 1998; Feng & Peng 2000; ALGORITHM.md 2),
// one thread per knot-box sub-triangle.
//  1. Samples S_l = R(x(l/n)) of the lattice volume at the principal lattice points l/n of the flat
//     sub-triangle (every sample finds its own knot box; the sub-triangle lies in one, so R o x is a
//     polynomial of total degree n = nu+nv+nw).
//  2. The exact triangular Bezier patch P = A_n^{-1} S (A_n^{-1} computed on the host in double, once
//     per n, and uploaded as a storage buffer).
//  3. Tessellation at level L (src/core/patch_output.h layout): interior vertices B^n(lambda)·P;
//     boundary vertices R(x(lambda)) directly, the value the patch interpolates exactly there, computed
//     from bits that both sub-triangles of a shared edge have, so the output welds closed.
//     Normals: the patch's geometric normal P_lambda1 x P_lambda2, normalised, computed through the
//     identity P_lambda1 x P_lambda2 = cof(J) ((c1 - c0) x (c2 - c0)) with the parent's unit face normal
//     (the sub-triangle lies in the parent's plane): differencing the control points of the slivers
//     that knot-box clipping makes loses all float precision. It keeps the parent's orientation (also
//     where det J < 0) and jumps across sub-triangle edges, which is why accurate FFD shades
//     unsmoothly (ALGORITHM.md 2.2, last paragraph).
// The C++ twin is src/core/accurate_ffd.cpp (accurateCpu): the same operations in the same order.
#extension GL_GOOGLE_include_directive : require
#include "common/prelude.glsl"
#include "common/bspline.glsl"

layout(std140, SFFD_SET binding = SFFD_BINDING_PARAMS) uniform AccurateBlock { AccurateParams params; };
layout(std430, SFFD_SET binding = SFFD_BINDING_ACC_MATRIX) readonly buffer AccMatrix { real accMatrix[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_ACC_TESS_BASIS) readonly buffer AccTessBasis { real accTessBasis[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_ACC_CORNERS) readonly buffer AccCorners { real4 accCorners[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_ACC_PATCHES) writeonly buffer AccPatches { real4 accPatches[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_ACC_POSITIONS) writeonly buffer AccPositions { real4 accPositions[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_ACC_NORMALS) writeonly buffer AccNormals { real4 accNormals[]; };

// The point (i, j, k) / d of the flat triangle (c0, c1, c2). Always precise (also in the fast
// variant): on a shared edge one weight is 0 and the sum of the other two terms is the same bits from
// both sides only without contraction into fma.
real3 accFlatPoint(real3 c0, real3 c1, real3 c2, uint i, uint j, uint k, uint d) {
  precise real l0 = real(i) / real(d);
  precise real l1 = real(j) / real(d);
  precise real l2 = real(k) / real(d);
  precise real3 r = (c0 * l0 + c1 * l1) + c2 * l2;
  return r;
}

// The lattice volume at a world point, with the outside rule of classic FFD.
real3 accLatticeValue(real3 x) {
  LatticeSample S = latticeEvaluate(params.lattice, x);
  if (!S.inside && params.lattice.degree.w == SFFD_OUTSIDE_KEEP) return x;
  return S.value;
}

void main() {
  uint t = sffdThreadIndex();
  if (t >= params.range.y) return;
  uint s = params.range.x + t;
  uint n = params.shape.x, m = params.shape.y, L = params.shape.z, nv = params.shape.w;
  uint cs = uint(SFFD_ACC_CORNER_STRIDE) * s;
  real3 c0 = accCorners[cs].xyz, c1 = accCorners[cs + 1u].xyz, c2 = accCorners[cs + 2u].xyz, nf = accCorners[cs + 3u].xyz;

  // Steps 1-2: P[k] = sum over samples l (in linear order) of A^{-1}[k][l] S_l.
  real3 cp[SFFD_ACC_MAX_CP];
  for (uint k = 0u; k < m; ++k) cp[k] = real3(0);
  uint l = 0u;
  for (uint r = 0u; r <= n; ++r) {
    for (uint q = 0u; q <= r; ++q) {
      real3 S = accLatticeValue(accFlatPoint(c0, c1, c2, n - r, r - q, q, n));
      uint row = l * m;
      for (uint k = 0u; k < m; ++k) {
        P real3 v = cp[k] + S * accMatrix[row + k];
        cp[k] = v;
      }
      ++l;
    }
  }
  for (uint k = 0u; k < m; ++k) accPatches[s * m + k] = real4(cp[k], 0);

  // Step 3: tessellation, with B^n at the vertex from the uploaded table.
  for (uint r = 0u; r <= L; ++r) {
    for (uint q = 0u; q <= r; ++q) {
      uint v = r * (r + 1u) / 2u + q;
      uint i = L - r, j = r - q, k = q;
      real3 x = accFlatPoint(c0, c1, c2, i, j, k, L);
      LatticeSample S = latticeEvaluate(params.lattice, x);
      bool keep = !S.inside && params.lattice.degree.w == SFFD_OUTSIDE_KEEP;
      P real3 pos = real3(0);
      uint b = v * m;
      for (uint kk = 0u; kk < m; ++kk) {
        P real3 t = pos + cp[kk] * accTessBasis[b + kk];
        pos = t;
      }
      if (i == 0u || j == 0u || k == 0u) pos = keep ? x : S.value;
      P real3 nrm = keep ? nf : latticeCofactorNormal(S, nf);
      if (!(sdot(nrm, nrm) > real(0))) nrm = nf;   // a singular point of the map
      accPositions[s * nv + v] = real4(pos, 0);
      accNormals[s * nv + v] = real4(snormalize(nrm), 0);
    }
  }
}
