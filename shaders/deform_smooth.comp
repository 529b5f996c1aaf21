#version 450
// Kernel deform_smooth (K3 of ALGORITHM.md 3.4, fused): per sub-triangle, (1) sampling and (2)
// constraint points by exact FFD, (3) control points by the constrained least-squares fit, the normal
// patch by the same fit on cofactor-deformed normals, (4) adjusting normals, (5) adjustment of the edge
// control points (tangent plane, or crease line on crease slots) and the PN centre rule, (6)
// tessellation at level L. The C++ twin is src/core/smooth_deform.cpp.
//
// Bitwise C0: everything on a sub-edge is computed from that edge's data in an order both patches
// share (sums of two products are commutative; near-corner control points use one expression from the
// corner; boundary tessellation vertices are evaluated on the edge curve from its lexicographically
// smaller corner; crease-line normals are ordered the same way).
#extension GL_GOOGLE_include_directive : require
#include "common/prelude.glsl"
#include "common/bspline.glsl"
#include "common/pn.glsl"

layout(std140, SFFD_SET binding = SFFD_BINDING_PARAMS) uniform DeformBlock { DeformParams params; };
layout(std430, SFFD_SET binding = SFFD_BINDING_DEFORM_FIT) readonly buffer Fit { real fit[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_DEFORM_SUB_HEADERS) readonly buffer SubHeaders { uvec4 subHeaders[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_DEFORM_SUB_RECORDS) readonly buffer SubRecords { real4 subRecords[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_DEFORM_PATCHES) writeonly buffer Patches { real4 patches[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_DEFORM_TESS) writeonly buffer Tess { real4 tess[]; };

const uint kSlotCp[6] = uint[6](2u, 1u, 3u, 7u, 8u, 5u);
const uint kCornerCp[3] = uint[3](0u, 6u, 9u);

// a before b in the lexicographic order of their coordinates (a total order both patches agree on).
bool lexLess(real3 a, real3 b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

// (-5 q0 + 18 q1 - 9 q2 + 2 q3) / 6: the cubic through q0..q3 at 0, 1/3, 2/3, 1, control point near q0.
real3 nearControlPoint(real3 q0, real3 q1, real3 q2, real3 q3) {
  P real3 r = (((q0 * real(-5) + q1 * real(18)) + q2 * real(-9)) + q3 * real(2)) / real(6);
  return r;
}

void main() {
  uint tid = sffdThreadIndex();
  if (tid >= params.range.y) return;
  uint st = params.range.x + tid;
  uint rec = SFFD_SUB_STRIDE * st;
  uint creaseBits = subHeaders[st].y;
  real3 xpn[3], nlin[3];
  for (uint c = 0u; c < 3u; ++c) {
    xpn[c] = subRecords[rec + SFFD_SUB_XPN + c].xyz;
    nlin[c] = subRecords[rec + SFFD_SUB_NLIN + c].xyz;
  }
  P real third = real(1) / real(3);
  P real twoThirds = real(2) / real(3);

  // Steps 1, 2, 4: corner samples, with the adjusting normals of the corners and crease slots.
  real3 Q[3], QN[3], adj[3], adjNbr[6];
  for (uint c = 0u; c < 3u; ++c) {
    LatticeSample S = latticeEvaluate(params.lattice, xpn[c]);
    Q[c] = S.value;
    QN[c] = snormalize(latticeCofactorNormal(S, nlin[c]));
    adj[c] = snormalize(latticeCofactorNormal(S, subRecords[rec + SFFD_SUB_NPN + c].xyz));
    for (uint h = 0u; h < 2u; ++h) {
      uint s = 2u * c + h;
      adjNbr[s] = ((creaseBits >> s) & 1u) != 0u ? snormalize(latticeCofactorNormal(S, subRecords[rec + SFFD_SUB_NNBR + s].xyz)) : adj[c];
    }
  }
  // Edge samples at one third from each end: E[2e] near corner e, E[2e+1] near corner e+1.
  real3 E[6], EN[6];
  for (uint e = 0u; e < 3u; ++e) {
    uint a = e, b = (e + 1u) % 3u;
    for (uint h = 0u; h < 2u; ++h) {
      P real wa = h == 0u ? twoThirds : third;
      P real wb = h == 0u ? third : twoThirds;
      P real3 x = xpn[a] * wa + xpn[b] * wb;
      P real3 n = nlin[a] * wa + nlin[b] * wb;
      LatticeSample S = latticeEvaluate(params.lattice, x);
      E[2u * e + h] = S.value;
      EN[2u * e + h] = snormalize(latticeCofactorNormal(S, snormalize(n)));
    }
  }

  // Step 3: boundary control points by the closed form of the constrained fit.
  real3 cp[10], ncp[10];
  for (uint c = 0u; c < 3u; ++c) {
    cp[kCornerCp[c]] = Q[c];
    ncp[kCornerCp[c]] = QN[c];
  }
  for (uint s = 0u; s < 6u; ++s) {
    uint c = s / 2u;
    uint o = (s % 2u == 1u) ? (c + 1u) % 3u : (c + 2u) % 3u;
    uint e = (s % 2u == 1u) ? c : o;               // edge index (corner e -> e+1)
    uint nearC = c == e ? 2u * e : 2u * e + 1u;    // the edge sample a third from c
    uint nearO = c == e ? 2u * e + 1u : 2u * e;
    cp[kSlotCp[s]] = nearControlPoint(Q[c], E[nearC], E[nearO], Q[o]);
    ncp[kSlotCp[s]] = nearControlPoint(QN[c], EN[nearC], EN[nearO], QN[o]);
  }
  // The normal patch's centre by least squares on the interior fitting points.
  P real3 centreN = real3(0);
  for (uint i = 0u; i < params.range.z; ++i) {
    uint f = SFFD_FIT_STRIDE * i;
    P real3 lam = real3(fit[f], fit[f + 1u], fit[f + 2u]);
    P real3 x = (xpn[0] * lam.x + xpn[1] * lam.y) + xpn[2] * lam.z;
    P real3 n = (nlin[0] * lam.x + nlin[1] * lam.y) + nlin[2] * lam.z;
    LatticeSample S = latticeEvaluate(params.lattice, x);
    P real3 r = snormalize(latticeCofactorNormal(S, snormalize(n)));
    for (uint k = 0u; k < 10u; ++k)
      if (k != 4u) r = r - ncp[k] * fit[f + 4u + k];
    centreN = centreN + r * fit[f + 3u];
  }
  ncp[4] = centreN;

  // Step 5: edge control points onto the deformed tangent plane, or onto the crease line.
  for (uint s = 0u; s < 6u; ++s) {
    uint c = s / 2u;
    real3 X = Q[c];
    P real3 b = cp[kSlotCp[s]];
    P real3 d = b - X;
    bool adjusted = false;
    if (((creaseBits >> s) & 1u) != 0u) {
      real3 n1 = adj[c], n2 = adjNbr[s];
      if (lexLess(n2, n1)) { real3 x = n1; n1 = n2; n2 = x; }
      P real3 cr = scross(n1, n2);
      P real len2 = sdot(cr, cr);
      if (len2 > real(1e-12)) {
        P real3 t = cr / sqrt(len2);
        b = X + t * sdot(d, t);
        adjusted = true;
      }
    }
    if (!adjusted) b = b - adj[c] * sdot(d, adj[c]);
    cp[kSlotCp[s]] = b;
  }
  P real3 edgeSum = ((((cp[1] + cp[2]) + cp[3]) + cp[5]) + cp[7]) + cp[8];
  P real3 cornerSum = (cp[0] + cp[6]) + cp[9];
  P real3 centre = edgeSum / real(4) - cornerSum / real(6);
  cp[4] = centre;

  uint pbase = SFFD_PATCH_STRIDE * st;
  for (uint k = 0u; k < 10u; ++k) {
    patches[pbase + k] = real4(cp[k], 0);
    patches[pbase + 10u + k] = real4(ncp[k], 0);
  }

  // Step 6: tessellation. Corners exact, edge vertices on the canonical edge curve, the rest by the patch.
  uint L = params.range.w;
  uint nv = (L + 1u) * (L + 2u) / 2u;
  uint tbase = 2u * nv * st;
  for (uint r = 0u; r <= L; ++r)
    for (uint t = 0u; t <= r; ++t) {
      uint i = L - r, j = r - t, k = t;
      uint v = r * (r + 1u) / 2u + t;
      real3 x, n;
      if (i == L || j == L || k == L) {
        uint c = i == L ? 0u : (j == L ? 1u : 2u);
        x = cp[kCornerCp[c]];
        n = snormalize(ncp[kCornerCp[c]]);
      } else if (i == 0u || j == 0u || k == 0u) {
        // Edge (a, b) = (0,1) when k == 0, (1,2) when i == 0, (2,0) when j == 0; steps from a.
        uint a = k == 0u ? 0u : (i == 0u ? 1u : 2u), b = (a + 1u) % 3u;
        uint stepsFromA = a == 0u ? j : (a == 1u ? k : i);
        uint sa = 2u * a + 1u, sb = 2u * b;   // slots of a and b on edge e
        uint lo = a, hi = b, steps = stepsFromA, slo = sa, shi = sb;
        if (lexLess(cp[kCornerCp[b]], cp[kCornerCp[a]])) { lo = b; hi = a; steps = L - stepsFromA; slo = sb; shi = sa; }
        P real u = real(steps) / real(L);
        x = pnEdgeCurve(cp[kCornerCp[lo]], cp[kSlotCp[slo]], cp[kSlotCp[shi]], cp[kCornerCp[hi]], u);
        n = snormalize(pnEdgeCurve(ncp[kCornerCp[lo]], ncp[kSlotCp[slo]], ncp[kSlotCp[shi]], ncp[kCornerCp[hi]], u));
      } else {
        P real3 lam = real3(real(i), real(j), real(k)) / real(L);
        real w[10];
        pnCubicWeights(lam, w);
        P real3 xs = real3(0), ns = real3(0);
        for (uint q = 0u; q < 10u; ++q) {
          xs = xs + cp[q] * w[q];
          ns = ns + ncp[q] * w[q];
        }
        x = xs;
        n = snormalize(ns);
      }
      tess[tbase + v] = real4(x, 0);
      tess[tbase + nv + v] = real4(n, 0);
    }
}
