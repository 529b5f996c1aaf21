#version 450
// Kernel accurate_patches: accurate FFD (Feng, Heng & Wong 1998; Feng & Peng 2000; ALGORITHM.md 2),
// one thread per knot-box sub-triangle.
//  1. Samples S_l = R(x(l/n)) of the lattice volume at the principal lattice points l/n of the flat
//     sub-triangle (every sample finds its own knot box; the sub-triangle lies in one, so R o x is a
//     polynomial of total degree n = nu+nv+nw).
//  2. The exact triangular Bezier patch P = A_n^{-1} S (A_n^{-1} computed on the host in double, once
//     per n, and uploaded as a storage buffer).
//  3. Tessellation at level L (src/core/patch_output.h layout): interior vertices B^n(lambda)·P,
//     boundary vertices R(x(lambda)) directly (the value the patch interpolates exactly there, computed
//     from bits that both sub-triangles of a shared edge have, so the output welds closed), normals the
//     patch's geometric normal P_lambda1 x P_lambda2 normalised. That normal is parallel to
//     cof(J) n_face and keeps the parent's orientation; it jumps across sub-triangle edges, which is
//     why accurate FFD shades unsmoothly (ALGORITHM.md 2.2, last paragraph).
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
  real3 c0 = accCorners[3u * s].xyz, c1 = accCorners[3u * s + 1u].xyz, c2 = accCorners[3u * s + 2u].xyz;

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

  // Step 3: tessellation. With B^{n-1} at the vertex (uploaded table), the last de Casteljau step gives
  // the point, and the differences P_{kappa+e1} - P_{kappa+e0}, P_{kappa+e2} - P_{kappa+e0} the
  // derivatives along lambda1 and lambda2 (up to the common factor n).
  uint nb = n * (n + 1u) / 2u;
  uint cA = 0u, cB = n * (n + 1u) / 2u, cC = m - 1u;   // control points of the corners (n,0,0), (0,n,0), (0,0,n)
  for (uint r = 0u; r <= L; ++r) {
    for (uint q = 0u; q <= r; ++q) {
      uint v = r * (r + 1u) / 2u + q;
      uint i = L - r, j = r - q, k = q;
      P real l0 = real(i) / real(L);
      P real l1 = real(j) / real(L);
      P real l2 = real(k) / real(L);
      P real3 pos = real3(0), d1 = real3(0), d2 = real3(0);
      uint b = v * nb;
      for (uint rr = 0u; rr < n; ++rr) {
        uint a0 = rr * (rr + 1u) / 2u, a1 = (rr + 1u) * (rr + 2u) / 2u;
        for (uint tt = 0u; tt <= rr; ++tt) {
          real w = accTessBasis[b];
          ++b;
          real3 p0 = cp[a0 + tt], p1 = cp[a1 + tt], p2 = cp[a1 + tt + 1u];
          P real3 e = (p0 * l0 + p1 * l1) + p2 * l2;
          pos = pos + e * w;
          d1 = d1 + (p1 - p0) * w;
          d2 = d2 + (p2 - p0) * w;
        }
      }
      if (i == 0u || j == 0u || k == 0u) pos = accLatticeValue(accFlatPoint(c0, c1, c2, i, j, k, L));
      P real3 nrm = scross(d1, d2);
      if (!(sdot(nrm, nrm) > real(0))) {
        // A singular point of the patch: the normal of its corner triangle, else +z.
        P real3 f = scross(cp[cB] - cp[cA], cp[cC] - cp[cA]);
        nrm = sdot(f, f) > real(0) ? f : real3(0, 0, 1);
      }
      accPositions[s * nv + v] = real4(pos, 0);
      accNormals[s * nv + v] = real4(snormalize(nrm), 0);
    }
  }
}
