// kernels/smooth/smooth_deform.glsl: the steps of the smooth-FFD deform stage (METHOD.md 3.4) as
// functions, shared by the fused kernel deform_smooth and the split kernels deform_step_*; the C++
// twin is kernels/smooth/smooth_deform_cpu.cpp. Both forms call the same functions, so they agree.
//
// Bitwise C0: everything on a sub-edge is computed from that edge's data in an order both patches
// share (sums of two products are commutative; near-corner control points use one expression from the
// corner; boundary tessellation vertices are evaluated on the edge curve from its lexicographically
// smaller corner; crease-line normals are ordered the same way).
#ifndef SFFD_SMOOTH_GLSL
#define SFFD_SMOOTH_GLSL

// Declared before lattice_eval.glsl, which then reads the lattice from the block when the host put it there.
layout(std140, SFFD_SET binding = SFFD_BINDING_PARAMS) uniform DeformBlock { DeformParams params; };
#define SFFD_LATTICE_INLINE 1
#define SFFD_LATTICE_BOX_CACHE 1
#include "../common/lattice_eval.glsl"
#include "../pn/pn_eval.glsl"
// Fit-table reads: from the parameter block when the host put the table there (layout.h), as the
// lattice; else from the lattice frame range, after the frame.
real fitAt(uint i) { return latticeTableAt(params.sections.x, params.sections.y, i); }
layout(std430, SFFD_SET binding = SFFD_BINDING_DEFORM_SUB_RECORDS) readonly buffer SubRecords { real4 subRecords[]; };
// The crease slot bits of sub-triangle st (layout.h: an integer-valued real).
uint smoothCreaseBits(uint st) { return uint(subRecords[SFFD_SUB_STRIDE * st + SFFD_SUB_CREASE_BITS].w); }
// The output range's sections (layout.h, SFFD_BINDING_DEFORM_OUT): tessellation, patches, samples.
// A kernel that only writes it defines SFFD_DEFORM_OUT_ACCESS writeonly before including this file.
#ifndef SFFD_DEFORM_OUT_ACCESS
#define SFFD_DEFORM_OUT_ACCESS
#endif
layout(std430, SFFD_SET binding = SFFD_BINDING_DEFORM_OUT) SFFD_DEFORM_OUT_ACCESS buffer DeformOut { real4 deformOut[]; };
#define tess(i) deformOut[i]
#define patches(i) deformOut[params.sections.z + (i)]
#define samples(i) deformOut[params.sections.w + (i)]

// Control point of corner c (0, 6, 9); kSlotCp (pn_eval.glsl) gives a slot's.
uint kCornerCp(uint c) { return (0x960u >> (4u * c)) & 15u; }

// a before b in the lexicographic order of their coordinates (a total order both patches agree on).
bool lexLess(real3 a, real3 b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

// (-5 q0 + 18 q1 - 9 q2 + 2 q3) / 6: the cubic through q0..q3 at 0, 1/3, 2/3, 1, control point near q0.
real3 nearControlPoint(real3 q0, real3 q1, real3 q2, real3 q3) {
  P real3 sum = ((q0 * real(-5) + q1 * real(18)) + q2 * real(-9)) + q3 * real(2);
  P real3 r = sdiv(sum, real(6));
  return r;
}

// The flat-lifted corners and their linear normals of a sub-triangle, read once for every interior
// sample (each storage-buffer read is costly on SIMD CPU devices).
struct SubCorners {
  real3 x0, x1, x2, n0, n1, n2;
};
// The reads in two forms, as clip_sites.glsl's loadParent: two iterations of three, or where the host
// asks for rolled loops (prelude.glsl sffdRollsLoops) one an iteration; the values through a shift
// register (an array indexed by constants only: registers).
SubCorners smoothSubCorners(uint st) {
  uint rec = SFFD_SUB_STRIDE * st;
  real3 q[6];   // XPN 0..2, then NLIN 0..2
  if (!sffdRollsLoops()) {
    for (uint h = 0u; h < 2u; ++h) {
      for (uint j = 0u; j < 3u; ++j) q[j] = q[j + 3u];
      for (uint j = 0u; j < 3u; ++j) q[3u + j] = subRecords[rec + SFFD_SUB_XPN + (SFFD_SUB_NLIN - SFFD_SUB_XPN) * h + j].xyz;
    }
  } else {
    for (uint i = 0u; i < sffdRolled(6u); ++i) {
      for (uint j = 0u; j < 5u; ++j) q[j] = q[j + 1u];
      q[5] = subRecords[rec + (i < 3u ? SFFD_SUB_XPN : SFFD_SUB_NLIN) + i % 3u].xyz;
    }
  }
  SubCorners C;
  C.x0 = q[0];
  C.x1 = q[1];
  C.x2 = q[2];
  C.n0 = q[3];
  C.n1 = q[4];
  C.n2 = q[5];
  return C;
}

// Step 4 at corner c, from the corner's lattice sample: the adjusting normals of the corner and of its
// two slots (crease slots only). Where the host asks for rolled loops (prelude.glsl sffdRollsLoops), the
// three in a loop: one copy of the read and of the cofactor normal.
void smoothCornerAdjust(LatticeSample S, uint st, uint c, uint creaseBits, out real3 adj, out real3 adjA, out real3 adjB) {
  uint rec = SFFD_SUB_STRIDE * st;
  if (!sffdRollsLoops()) {
    adj = snormalize(latticeCofactorNormal(S, subRecords[rec + SFFD_SUB_NPN + c].xyz));
    adjA = adj;
    adjB = adj;
    if (((creaseBits >> (2u * c)) & 1u) != 0u) adjA = snormalize(latticeCofactorNormal(S, subRecords[rec + SFFD_SUB_NNBR + 2u * c].xyz));
    if (((creaseBits >> (2u * c + 1u)) & 1u) != 0u) adjB = snormalize(latticeCofactorNormal(S, subRecords[rec + SFFD_SUB_NNBR + 2u * c + 1u].xyz));
    return;
  }
  real3 a = real3(0), r[2];   // the corner's, then a shift register of the slots'
  for (uint m = 0u; m < sffdRolled(3u); ++m) {
    uint s = 2u * c + m - 1u;   // the slot, m > 0
    real3 v = a;
    if (m == 0u || ((creaseBits >> s) & 1u) != 0u)
      v = snormalize(latticeCofactorNormal(S, subRecords[rec + (m == 0u ? SFFD_SUB_NPN + c : SFFD_SUB_NNBR + s)].xyz));
    if (m == 0u) a = v;
    r[0] = r[1];
    r[1] = v;
  }
  adj = a;
  adjA = r[0];
  adjB = r[1];
}

// Corner c's lifted point and linear normal (selects, not an indexed array).
real3 subCornerX(SubCorners C, uint c) { return c == 0u ? C.x0 : (c == 1u ? C.x1 : C.x2); }
real3 subCornerN(SubCorners C, uint c) { return c == 0u ? C.n0 : (c == 1u ? C.n1 : C.n2); }

// Edge sample k (E[2e] a third from corner e, E[2e+1] a third from e+1): its point and its normal
// before the deformation.
void smoothEdgePoint(SubCorners C, uint k, out real3 x, out real3 n) {
  P real third = sdiv(real(1), real(3));
  P real twoThirds = sdiv(real(2), real(3));
  uint e = k / 2u, b = e == 2u ? 0u : e + 1u;
  P real wa = k % 2u == 0u ? twoThirds : third;
  P real wb = k % 2u == 0u ? third : twoThirds;
  P real3 xk = subCornerX(C, e) * wa + subCornerX(C, b) * wb;
  P real3 nk = subCornerN(C, e) * wa + subCornerN(C, b) * wb;
  x = xk;
  n = snormalize(nk);
}

// Steps 1 and 2 on the boundary and step 4: at corner c the deformed corner Q[c], its deformed normal
// QN[c] and the adjusting normals (smoothCornerAdjust); at edge sample k the deformed point E[k] and
// normal EN[k]. Loops rather than calls written out: every call inlines a whole lattice evaluation,
// and the kernels' compile time grows with their number. Where the host asks for one sample site
// (SFFD_ASSUME_ONE_SAMPLE_SITE), corners and edge points share one loop and one evaluation: lavapipe 22.3
// translates the kernel in 34 ms instead of 42, and runs it 12 % slower (its arrays then indexed by a
// variable); the same bits. (Mesa 25.0's rolled form tried the same: 45 ms less first dispatch, 11 % more
// deform instructions warm.)
const bool smoothOneSampleSite = (sffdAssumptions & SFFD_ASSUME_ONE_SAMPLE_SITE) != 0u;
void smoothBoundarySamples(uint st, SubCorners C, out real3 Q[3], out real3 QN[3], out real3 adj[3], out real3 adjNbr[6],
                           out real3 E[6], out real3 EN[6]) {
  uint creaseBits = smoothCreaseBits(st);
  if (smoothOneSampleSite) {
    for (uint i = 0u; i < 9u; ++i) {
      real3 x, n;
      if (i < 3u) {
        x = subCornerX(C, i);
        n = subCornerN(C, i);
      } else {
        smoothEdgePoint(C, i - 3u, x, n);
      }
      LatticeSample S = latticeEvaluate(params.lattice, x);
      real3 sampleN = snormalize(latticeCofactorNormal(S, n));
      if (i < 3u) {
        real3 ad, a0, a1;
        smoothCornerAdjust(S, st, i, creaseBits, ad, a0, a1);
        Q[i] = S.value;
        QN[i] = sampleN;
        adj[i] = ad;
        adjNbr[2u * i] = a0;
        adjNbr[2u * i + 1u] = a1;
      } else {
        E[i - 3u] = S.value;
        EN[i - 3u] = sampleN;
      }
    }
    return;
  }
  for (uint c = 0u; c < 3u; ++c) {
    LatticeSample S = latticeEvaluate(params.lattice, subCornerX(C, c));
    real3 ad, a0, a1;
    smoothCornerAdjust(S, st, c, creaseBits, ad, a0, a1);
    Q[c] = S.value;
    QN[c] = snormalize(latticeCofactorNormal(S, subCornerN(C, c)));
    adj[c] = ad;
    adjNbr[2u * c] = a0;
    adjNbr[2u * c + 1u] = a1;
  }
  for (uint k = 0u; k < 6u; ++k) {
    real3 x, n;
    smoothEdgePoint(C, k, x, n);
    LatticeSample S = latticeEvaluate(params.lattice, x);
    E[k] = S.value;
    EN[k] = snormalize(latticeCofactorNormal(S, n));
  }
}

// Step 1 inside: the deformed normal at interior fitting point i (the geometry's centre comes from
// the PN rule after the adjustment, so only the normal patch needs the interior samples).
real3 smoothInteriorNormal(SubCorners C, uint i) {
  uint f = SFFD_FIT_STRIDE * i;
  P real3 lam = real3(fitAt(f), fitAt(f + 1u), fitAt(f + 2u));
  P real3 x = (C.x0 * lam.x + C.x1 * lam.y) + C.x2 * lam.z;
  P real3 n = (C.n0 * lam.x + C.n1 * lam.y) + C.n2 * lam.z;
  LatticeSample S = latticeEvaluate(params.lattice, x);
  P real3 r = snormalize(latticeCofactorNormal(S, snormalize(n)));
  return r;
}

// Step 3: boundary control points by the closed form of the constrained fit.
void smoothBoundaryControlPoints(real3 Q[3], real3 QN[3], real3 E[6], real3 EN[6], out real3 cp[10], out real3 ncp[10]) {
  for (uint c = 0u; c < 3u; ++c) {
    cp[kCornerCp(c)] = Q[c];
    ncp[kCornerCp(c)] = QN[c];
  }
  for (uint s = 0u; s < 6u; ++s) {
    uint c = s / 2u;
    uint o = (s % 2u == 1u) ? (c + 1u) % 3u : (c + 2u) % 3u;
    uint e = (s % 2u == 1u) ? c : o;               // edge index (corner e -> e+1)
    uint nearC = c == e ? 2u * e : 2u * e + 1u;    // the edge sample a third from c
    uint nearO = c == e ? 2u * e + 1u : 2u * e;
    cp[kSlotCp(s)] = nearControlPoint(Q[c], E[nearC], E[nearO], Q[o]);
    ncp[kSlotCp(s)] = nearControlPoint(QN[c], EN[nearC], EN[nearO], QN[o]);
  }
  cp[4] = real3(0);
  ncp[4] = real3(0);
}

// Step 3 inside: one interior sample's share of the normal patch's least-squares centre.
real3 smoothCentreTerm(real3 ncp[10], real3 qn, uint i) {
  uint f = SFFD_FIT_STRIDE * i;
  P real3 r = qn;
  for (uint k = 0u; k < 10u; ++k)
    if (k != 4u) r = r - ncp[k] * fitAt(f + 4u + k);
  P real3 term = r * fitAt(f + 3u);
  return term;
}

// Step 5: edge control points onto the deformed tangent plane, or onto the crease line; centre by the PN rule.
void smoothAdjust(uint creaseBits, real3 adj[3], real3 adjNbr[6], inout real3 cp[10]) {
  for (uint s = 0u; s < 6u; ++s) {
    uint c = s / 2u;
    real3 X = cp[kCornerCp(c)];
    P real3 b = cp[kSlotCp(s)];
    P real3 d = b - X;
    bool adjusted = false;
    if (((creaseBits >> s) & 1u) != 0u) {
      real3 n1 = adj[c], n2 = adjNbr[s];
      if (lexLess(n2, n1)) { real3 x = n1; n1 = n2; n2 = x; }
      P real3 cr = scross(n1, n2);
      P real len2 = sdot(cr, cr);
      if (len2 > real(1e-12)) {
        P real3 t = sdiv(cr, ssqrt(len2));
        b = X + t * sdot(d, t);
        adjusted = true;
      }
    }
    if (!adjusted) b = b - adj[c] * sdot(d, adj[c]);
    cp[kSlotCp(s)] = b;
  }
  P real3 edgeSum = ((((cp[1] + cp[2]) + cp[3]) + cp[5]) + cp[7]) + cp[8];
  P real3 cornerSum = (cp[0] + cp[6]) + cp[9];
  P real3 centre = edgeSum / real(4) - sdiv(cornerSum, real(6));
  cp[4] = centre;
}

// Step 6: the tessellation at level L: vertex (r, t), r = 0..L, t = 0..r, at index r (r + 1) / 2 + t
// of the sub-triangle's positions (from tbase) and normals (from tbase + the vertex count), with
// barycentrics (L - r, r - t, t) / L. Corners exact, edge vertices on the canonical edge curve, the
// rest by the patch. Each kind of vertex has its own loop: llvmpipe and lavapipe run both sides of
// every `if` under a lane mask, so one loop choosing the kind per vertex paid for all three kinds at
// every vertex. Control points are picked by selects or constant indices (a local array indexed by a
// variable lives in memory on lavapipe).
void smoothTessellate(real3 cp[10], real3 ncp[10], uint L, uint tbase) {
  uint nv = (L + 1u) * (L + 2u) / 2u;
  uint lastRow = L * (L + 1u) / 2u;
  // The corners; where the host asks for rolled loops (prelude.glsl sffdRollsLoops), one store an
  // iteration: position, then normal.
  bool oneStore = sffdRollsLoops();
  for (uint i = 0u; i < (oneStore ? sffdRolled(6u) : 3u); ++i) {
    uint c = oneStore ? i / 2u : i;
    uint v = c == 0u ? 0u : (c == 1u ? lastRow : lastRow + L);
    real3 xc = c == 0u ? cp[0] : (c == 1u ? cp[6] : cp[9]);
    real3 nc = c == 0u ? ncp[0] : (c == 1u ? ncp[6] : ncp[9]);
    if (!oneStore) {
      tess(tbase + v) = real4(xc, 0);
      tess(tbase + nv + v) = real4(snormalize(nc), 0);
    } else {
      bool normal = i % 2u == 1u;
      tess(tbase + (normal ? nv : 0u) + v) = real4(normal ? snormalize(nc) : xc, 0);
    }
  }
  // Edge a runs from corner a to a + 1: vertices (s, 0), (L, s), (L - s, L - s) for a = 0, 1, 2, s steps
  // from corner a; its cubic runs through corner a, the control points of slots 2a+1 and 2a+2 and corner
  // a+1 (cp 0,1,3,6 / 6,7,8,9 / 9,5,2,0).
  for (uint a = 0u; a < 3u; ++a) {
    real3 e0 = cp[9], e1 = cp[5], e2 = cp[2], e3 = cp[0], f0 = ncp[9], f1 = ncp[5], f2 = ncp[2], f3 = ncp[0];
    if (a == 0u) {
      e0 = cp[0]; e1 = cp[1]; e2 = cp[3]; e3 = cp[6]; f0 = ncp[0]; f1 = ncp[1]; f2 = ncp[3]; f3 = ncp[6];
    } else if (a == 1u) {
      e0 = cp[6]; e1 = cp[7]; e2 = cp[8]; e3 = cp[9]; f0 = ncp[6]; f1 = ncp[7]; f2 = ncp[8]; f3 = ncp[9];
    }
    // Evaluated from the lexicographically smaller corner, so both patches of the edge agree bit for bit.
    bool reversed = lexLess(e3, e0);
    if (reversed) {
      real3 t0 = e0, t1 = e1, g0 = f0, g1 = f1;
      e0 = e3; e1 = e2; e2 = t1; e3 = t0;
      f0 = f3; f1 = f2; f2 = g1; f3 = g0;
    }
    for (uint s = 1u; s < L; ++s) {
      uint r = a == 0u ? s : (a == 1u ? L : L - s);
      uint t = a == 0u ? 0u : (a == 1u ? s : L - s);
      uint v = r * (r + 1u) / 2u + t;
      uint steps = reversed ? L - s : s;
      P real u = sdiv(real(steps), real(L));
      tess(tbase + v) = real4(pnEdgeCurve(e0, e1, e2, e3, u), 0);
      tess(tbase + nv + v) = real4(snormalize(pnEdgeCurve(f0, f1, f2, f3, u)), 0);
    }
  }
  for (uint r = 2u; r < L; ++r)
    for (uint t = 1u; t < r; ++t) {
      uint v = r * (r + 1u) / 2u + t;
      P real3 lam = sdiv(real3(real(L - r), real(r - t), real(t)), real(L));
      real w[10];
      pnCubicWeights(lam, w);
      P real3 xs = real3(0), ns = real3(0);
      for (uint q = 0u; q < 10u; ++q) {
        xs = xs + cp[q] * w[q];
        ns = ns + ncp[q] * w[q];
      }
      tess(tbase + v) = real4(xs, 0);
      tess(tbase + nv + v) = real4(snormalize(ns), 0);
    }
}

#endif
