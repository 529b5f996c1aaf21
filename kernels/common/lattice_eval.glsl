// kernels/common/lattice_eval.glsl: evaluation of the B-spline lattice volume from its per-knot-box
// Bezier form (METHOD.md 1.2-1.4). The C++ twin is kernels/common/lattice_eval.h; both follow the
// same operation order so that the strict variants agree bit for bit.
#ifndef SFFD_BSPLINE_GLSL
#define SFFD_BSPLINE_GLSL

layout(std430, SFFD_SET binding = SFFD_BINDING_LATTICE_COEFFS) readonly buffer LatticeCoeffs { real4 latticeCoeffs[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_LATTICE_FRAME) readonly buffer LatticeFrame { real latticeFrame[]; };

// Lattice reads go through these two functions: from the deform kernels' parameter block when the
// host put the lattice there (layout.h, DeformParams), else from the storage buffers above. An `if`
// rather than a select, so that the storage-buffer read is skipped, not merely discarded; with the
// host's assumption (layout.h SFFD_ASSUME_*) the other read is not compiled at all.
#if defined(SFFD_LATTICE_INLINE) && !SFFD_F64
bool latticeInParams() {
  return sffdAssumes(SFFD_ASSUME_LATTICE_IN_PARAMS) ||
         (!sffdAssumes(SFFD_ASSUME_LATTICE_IN_STORAGE) && params.lattice.break_offset.w != 0u);
}
real latticeFrameAt(uint i) {
  real v;
  if (latticeInParams()) v = params.inline_lattice[i >> 2u][i & 3u];
  else v = latticeFrame[i];
  return v;
}
real3 latticeCoeffAt(uint c) {
  real3 v;
  if (latticeInParams()) v = params.inline_lattice[params.lattice.break_offset.w + c].xyz;
  else v = latticeCoeffs[c].xyz;
  return v;
}
// Real i of a kernel's constant table (smooth: the fit table; accurate: A_n^{-1}, the tessellation
// basis): from vec4 inlineAt of the parameter block where the host put it there (0: not there), else
// from real frameAt of the lattice frame range.
real latticeTableAt(uint inlineAt, uint frameAt, uint i) {
  real v;
  bool inParams = sffdAssumes(SFFD_ASSUME_FIT_IN_PARAMS) || (!sffdAssumes(SFFD_ASSUME_FIT_IN_STORAGE) && inlineAt != 0u);
  if (inParams) v = params.inline_lattice[inlineAt + (i >> 2u)][i & 3u];
  else v = latticeFrame[frameAt + i];
  return v;
}
#else
real latticeFrameAt(uint i) { return latticeFrame[i]; }
real3 latticeCoeffAt(uint c) { return latticeCoeffs[c].xyz; }
real latticeTableAt(uint inlineAt, uint frameAt, uint i) { return latticeFrame[frameAt + i]; }
#endif

// Value and derivative of the B-spline volume at a lattice parameter, plus whether it is inside the box.
struct LatticeSample {
  real3 value;
  real3 du, dv, dw;   // derivatives with respect to the local box coordinates s (not yet divided by h)
  real3 h;            // knot-box size on each axis
  bool inside;
};

// Knot box of parameter t on one axis: the largest i with breaks[i] <= t, clamped to [0, n-1]. A
// count over the breaks rather than a bisection: the trip count is the same in every lane (no
// divergence on SIMD devices such as llvmpipe) and the result is the same integer.
uint latticeSpan(uint first, uint n, real t) {
  uint span = 0u;
  for (uint i = 1u; i < n; ++i) span += latticeFrameAt(first + i) <= t ? 1u : 0u;
  return span;
}

// Bernstein basis of degree n at s and its derivative, by the de Casteljau recurrence.
void latticeBernstein(uint n, real s, out real b[SFFD_MAX_DEGREE + 1], out real db[SFFD_MAX_DEGREE + 1]) {
  P real t = real(1) - s;
  for (uint i = 0u; i <= uint(SFFD_MAX_DEGREE); ++i) { b[i] = real(0); db[i] = real(0); }
  b[0] = real(1);
  for (uint k = 1u; k <= n; ++k) {
    if (k == n) {
      // derivative of degree n from the degree n-1 basis: n * (B[p-1] - B[p])
      for (uint p = 0u; p <= n; ++p) {
        // Indices clamped so that no lane reads outside the array, even where a select evaluates both sides.
        P real lower = p > 0u ? b[p > 0u ? p - 1u : 0u] : real(0);
        P real upper = p < n ? b[min(p, uint(SFFD_MAX_DEGREE))] : real(0);
        P real d = real(n) * (lower - upper);
        db[p] = d;
      }
    }
    // Raise the degree in place: b[j] <- t*b[j] + s*b[j-1] (b[k] was 0, b[-1] is taken as 0).
    P real prev = real(0);
    for (uint j = 0u; j <= k; ++j) {
      P real cur = b[j];
      P real v = t * cur + s * prev;
      b[j] = v;
      prev = cur;
    }
  }
}

// Degree 2 on every axis (the paper's lattices and the default): the operations of latticeBernstein
// and of the general sum in latticeEvaluate, in the same order, written out so that no local array
// is indexed by a variable: llvmpipe/lavapipe keep such arrays in memory, which made evaluation
// about twice as slow. Results are bit-identical to the general path in the strict variant.
void latticeBernstein2(real s, out real3 b, out real3 db) {
  P real t = real(1) - s;
  P real b0 = t * real(1) + s * real(0);   // degree 1
  P real b1 = t * real(0) + s * real(1);
  P real d0 = real(2) * (real(0) - b0);    // derivative of degree 2 from the degree-1 basis
  P real d1 = real(2) * (b0 - b1);
  P real d2 = real(2) * (b1 - real(0));
  P real c0 = t * b0 + s * real(0);        // degree 2
  P real c1 = t * b1 + s * b0;
  P real c2 = t * real(0) + s * b1;
  b = real3(c0, c1, c2);
  db = real3(d0, d1, d2);
}

// The knot box whose 27 coefficients a sub-triangle's evaluations read, held in registers. A kernel that
// evaluates the lattice many times per invocation defines SFFD_LATTICE_BOX_CACHE; where the host asks for
// the rolled form (prelude.glsl sffdRollsLoops: llvmpipe and lavapipe of Mesa 23 on, whose reads at an
// index that differs between lanes are a load per lane and component, and whose code skips a branch no
// lane takes) each evaluation reads the coefficients from here and refills it only when its box differs
// from the last one's, which for a small sub-triangle is rare: the 19 evaluations of a smooth sub-triangle
// read 81 values instead of 1,539 (Mesa 25.0: 24 % of deform_smooth's instructions were those reads).
// The same values in the same order, so the same bits. Elsewhere (Mesa 22.3 runs both sides of every
// branch; GPUs) every read goes to the lattice.
#ifdef SFFD_LATTICE_BOX_CACHE
real3 latticeCachedBox[27];
uint latticeCachedBase = 0xffffffffu;
// Rows written out: a loop might stay rolled, and an array indexed by a variable lives in memory.
void latticeCacheRow(uint base, uint k) {
  latticeCachedBox[k] = latticeCoeffAt(base + k);
  latticeCachedBox[k + 1u] = latticeCoeffAt(base + k + 1u);
  latticeCachedBox[k + 2u] = latticeCoeffAt(base + k + 2u);
}
void latticeCacheBox(uint base) {
  if (base != latticeCachedBase) {
    latticeCacheRow(base, 0u);
    latticeCacheRow(base, 3u);
    latticeCacheRow(base, 6u);
    latticeCacheRow(base, 9u);
    latticeCacheRow(base, 12u);
    latticeCacheRow(base, 15u);
    latticeCacheRow(base, 18u);
    latticeCacheRow(base, 21u);
    latticeCacheRow(base, 24u);
    latticeCachedBase = base;
  }
}
#endif

// Coefficient k (0..26, a constant after inlining) of the knot box whose first is `base`.
real3 latticeBoxCoeff(uint base, uint k) {
#ifdef SFFD_LATTICE_BOX_CACHE
  if (sffdRollsLoops()) return latticeCachedBox[k];
#endif
  return latticeCoeffAt(base + k);
}

// One row of three coefficients along w (from coefficient k of the box at `base`): the value and the
// w-derivative sums.
void latticeRow2(uint base, uint k, real3 bw, real3 dbw, out real3 q, out real3 qw) {
  real3 p0 = latticeBoxCoeff(base, k), p1 = latticeBoxCoeff(base, k + 1u), p2 = latticeBoxCoeff(base, k + 2u);
  P real3 r = ((real3(0) + p0 * bw.x) + p1 * bw.y) + p2 * bw.z;
  P real3 rw = ((real3(0) + p0 * dbw.x) + p1 * dbw.y) + p2 * dbw.z;
  q = r;
  qw = rw;
}

// One slab of nine coefficients (fixed u index): sums over v and w.
void latticeSlab2(uint base, uint k, real3 bv, real3 dbv, real3 bw, real3 dbw, out real3 sp, out real3 spv, out real3 spw) {
  real3 q0, q0w, q1, q1w, q2, q2w;
  latticeRow2(base, k, bw, dbw, q0, q0w);
  latticeRow2(base, k + 3u, bw, dbw, q1, q1w);
  latticeRow2(base, k + 6u, bw, dbw, q2, q2w);
  P real3 a = ((real3(0) + q0 * bv.x) + q1 * bv.y) + q2 * bv.z;
  P real3 av = ((real3(0) + q0 * dbv.x) + q1 * dbv.y) + q2 * dbv.z;
  P real3 aw = ((real3(0) + q0w * bv.x) + q1w * bv.y) + q2w * bv.z;
  sp = a;
  spv = av;
  spw = aw;
}

// The Bezier volume of one knot box (27 coefficients from `base`) and its derivatives at s.
void latticeVolume2(uint base, real su, real sv, real sw, out real3 R, out real3 Ru, out real3 Rv, out real3 Rw) {
  real3 bu, dbu, bv, dbv, bw, dbw;
  latticeBernstein2(su, bu, dbu);
  latticeBernstein2(sv, bv, dbv);
  latticeBernstein2(sw, bw, dbw);
  real3 s0, s0v, s0w, s1, s1v, s1w, s2, s2v, s2w;
  latticeSlab2(base, 0u, bv, dbv, bw, dbw, s0, s0v, s0w);
  latticeSlab2(base, 9u, bv, dbv, bw, dbw, s1, s1v, s1w);
  latticeSlab2(base, 18u, bv, dbv, bw, dbw, s2, s2v, s2w);
  P real3 r = ((real3(0) + s0 * bu.x) + s1 * bu.y) + s2 * bu.z;
  P real3 ru = ((real3(0) + s0 * dbu.x) + s1 * dbu.y) + s2 * dbu.z;
  P real3 rv = ((real3(0) + s0v * bu.x) + s1v * bu.y) + s2v * bu.z;
  P real3 rw = ((real3(0) + s0w * bu.x) + s1w * bu.y) + s2w * bu.z;
  R = r;
  Ru = ru;
  Rv = rv;
  Rw = rw;
}

// With SFFD_LATTICE_BOX_CACHE in the rolled form (above), the last span on each axis and its breaks are
// kept too: p's span is the kept one exactly when p lies in [k0, k1) of it (no lower bound for the first,
// no upper for the last; the breaks ascend, so the count in latticeSpan gives the same), and then neither
// that count nor the two reads at the span (each a read per lane there) run.
#ifdef SFFD_LATTICE_BOX_CACHE
uvec3 latticeCachedSpan = uvec3(0xffffffffu);
real3 latticeCachedK0 = real3(0), latticeCachedK1 = real3(0);
#endif

// One axis of latticeEvaluate: the knot box of parameter p, the local coordinate in it and its size.
void latticeAxis(uint axis, uint first, uint n, real p, inout bool inside, out uint span, out real s, out real h) {
  real lo = latticeFrameAt(first), hi = latticeFrameAt(first + n);
  if (p < lo || p > hi) inside = false;
  real k0, k1;
  bool kept = false;
#ifdef SFFD_LATTICE_BOX_CACHE
  if (sffdRollsLoops()) {
    uint ks = componentOf(latticeCachedSpan, axis);
    k0 = componentOf(latticeCachedK0, axis);
    k1 = componentOf(latticeCachedK1, axis);
    span = ks;
    kept = ks != 0xffffffffu && (ks == 0u || k0 <= p) && (ks == n - 1u || p < k1);
  }
#endif
  if (!kept) {
    span = latticeSpan(first, n, p);
    k0 = latticeFrameAt(first + span);
    k1 = latticeFrameAt(first + span + 1u);
#ifdef SFFD_LATTICE_BOX_CACHE
    if (sffdRollsLoops()) {
      latticeCachedSpan = withComponent(latticeCachedSpan, axis, span);
      latticeCachedK0 = withComponent(latticeCachedK0, axis, k0);
      latticeCachedK1 = withComponent(latticeCachedK1, axis, k1);
    }
#endif
  }
  P real hh = k1 - k0;
  P real pk = p - k0;
  P real sa = sdiv(pk, hh);
  s = sa;
  h = hh;
}

// One row of the world -> parameter map: row . (x, 1), in the twin's order.
real latticeAffineRow(uint r, real3 x) {
  uint o = SFFD_FRAME_AFFINE + 4u * r;
  P real xy = latticeFrameAt(o) * x.x + latticeFrameAt(o + 1u) * x.y;
  P real xyz = xy + latticeFrameAt(o + 2u) * x.z;
  P real pr = xyz + latticeFrameAt(o + 3u);
  return pr;
}

// Evaluates the volume at world point x: lattice parameter p = A x + c, then the knot box's Bezier
// volume. Per-axis work is written out (no local arrays indexed by the axis: see latticeVolume2).
LatticeSample latticeEvaluate(LatticeParams L, real3 x) {
  LatticeSample S;
  S.inside = true;
  uint span0, span1, span2;
  real s0, s1, s2, h0, h1, h2;
  latticeAxis(0u, L.break_offset.x, L.boxes.x, latticeAffineRow(0u, x), S.inside, span0, s0, h0);
  latticeAxis(1u, L.break_offset.y, L.boxes.y, latticeAffineRow(1u, x), S.inside, span1, s1, h1);
  latticeAxis(2u, L.break_offset.z, L.boxes.z, latticeAffineRow(2u, x), S.inside, span2, s2, h2);
  S.h = real3(h0, h1, h2);
  uint box = (span0 * L.boxes.y + span1) * L.boxes.z + span2;
  uint base = box * L.boxes.w;
  P real3 R = real3(0), Ru = real3(0), Rv = real3(0), Rw = real3(0);
  bool degree2 = sffdAssumes(SFFD_ASSUME_DEGREE2) || (!sffdAssumes(SFFD_ASSUME_GENERAL_DEGREE) && L.degree.xyz == uvec3(2u));
  if (degree2) {
#ifdef SFFD_LATTICE_BOX_CACHE
    if (sffdRollsLoops()) latticeCacheBox(base);
#endif
    latticeVolume2(base, s0, s1, s2, R, Ru, Rv, Rw);
  } else {
    real bu[SFFD_MAX_DEGREE + 1], dbu[SFFD_MAX_DEGREE + 1];
    real bv[SFFD_MAX_DEGREE + 1], dbv[SFFD_MAX_DEGREE + 1];
    real bw[SFFD_MAX_DEGREE + 1], dbw[SFFD_MAX_DEGREE + 1];
    latticeBernstein(L.degree.x, s0, bu, dbu);
    latticeBernstein(L.degree.y, s1, bv, dbv);
    latticeBernstein(L.degree.z, s2, bw, dbw);
    uint c = base;
    for (uint i = 0u; i <= L.degree.x; ++i) {
      P real3 Sp = real3(0), Spv = real3(0), Spw = real3(0);
      for (uint j = 0u; j <= L.degree.y; ++j) {
        P real3 Sq = real3(0), Sqw = real3(0);
        for (uint k = 0u; k <= L.degree.z; ++k) {
          real3 cp = latticeCoeffAt(c);
          ++c;
          Sq = Sq + cp * bw[k];
          Sqw = Sqw + cp * dbw[k];
        }
        Sp = Sp + Sq * bv[j];
        Spv = Spv + Sq * dbv[j];
        Spw = Spw + Sqw * bv[j];
      }
      R = R + Sp * bu[i];
      Ru = Ru + Sp * dbu[i];
      Rv = Rv + Spv * bu[i];
      Rw = Rw + Spw * bu[i];
    }
  }
  S.value = R;
  S.du = Ru;
  S.dv = Rv;
  S.dw = Rw;
  return S;
}

// Deformed normal direction of a world-space normal n at the sample: cof(J_R) cof(A) n, up to a
// positive factor (METHOD.md 1.4). Not normalised.
real latticeCofactorRow(uint r, real3 n) {
  uint o = SFFD_FRAME_COF_AFFINE + 4u * r;
  P real xy = latticeFrameAt(o) * n.x + latticeFrameAt(o + 1u) * n.y;
  P real xyz = xy + latticeFrameAt(o + 2u) * n.z;
  return xyz;
}

real3 latticeCofactorNormal(LatticeSample S, real3 n) {
  P real3 q = real3(latticeCofactorRow(0u, n), latticeCofactorRow(1u, n), latticeCofactorRow(2u, n));
  P real3 cu = scross(S.dv, S.dw) * (S.h.x * q.x);
  P real3 cv = scross(S.dw, S.du) * (S.h.y * q.y);
  P real3 cw = scross(S.du, S.dv) * (S.h.z * q.z);
  P real3 r = (cu + cv) + cw;
  return r;
}

#endif
