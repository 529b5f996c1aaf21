// shaders/common/bspline.glsl: evaluation of the B-spline lattice volume from its per-knot-box
// Bezier form (ALGORITHM.md 1.2-1.4). The C++ twin is src/core/lattice_eval.h; both follow the
// same operation order so that the strict variants agree bit for bit.
#ifndef SFFD_BSPLINE_GLSL
#define SFFD_BSPLINE_GLSL

layout(std430, SFFD_SET binding = SFFD_BINDING_LATTICE_COEFFS) readonly buffer LatticeCoeffs { real4 latticeCoeffs[]; };
layout(std430, SFFD_SET binding = SFFD_BINDING_LATTICE_FRAME) readonly buffer LatticeFrame { real latticeFrame[]; };

// Value and derivative of the B-spline volume at a lattice parameter, plus whether it is inside the box.
struct LatticeSample {
  real3 value;
  real3 du, dv, dw;   // derivatives with respect to the local box coordinates s (not yet divided by h)
  real3 h;            // knot-box size on each axis
  bool inside;
};

// Knot box of parameter t on one axis: the largest i with breaks[i] <= t, clamped to [0, n-1].
uint latticeSpan(uint first, uint n, real t) {
  uint lo = 0u, hi = n - 1u;
  while (lo < hi) {
    uint mid = (lo + hi + 1u) / 2u;
    if (latticeFrame[first + mid] <= t) lo = mid; else hi = mid - 1u;
  }
  return lo;
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

// Evaluates the volume at world point x: lattice parameter p = A x + c, then the knot box's Bezier volume.
LatticeSample latticeEvaluate(LatticeParams L, real3 x) {
  LatticeSample S;
  real4 rows[3];
  for (uint r = 0u; r < 3u; ++r)
    rows[r] = real4(latticeFrame[SFFD_FRAME_AFFINE + 4u * r], latticeFrame[SFFD_FRAME_AFFINE + 4u * r + 1u],
                    latticeFrame[SFFD_FRAME_AFFINE + 4u * r + 2u], latticeFrame[SFFD_FRAME_AFFINE + 4u * r + 3u]);
  P real3 p;
  for (uint r = 0u; r < 3u; ++r) {
    P real xy = rows[r].x * x.x + rows[r].y * x.y;
    P real xyz = xy + rows[r].z * x.z;
    P real pr = xyz + rows[r].w;
    p[r] = pr;
  }
  uint span[3];
  real s[3];
  S.inside = true;
  for (uint a = 0u; a < 3u; ++a) {
    uint first = L.break_offset[a], n = L.boxes[a];
    real lo = latticeFrame[first], hi = latticeFrame[first + n];
    if (p[a] < lo || p[a] > hi) S.inside = false;
    span[a] = latticeSpan(first, n, p[a]);
    real k0 = latticeFrame[first + span[a]], k1 = latticeFrame[first + span[a] + 1u];
    P real h = k1 - k0;
    P real sa = (p[a] - k0) / h;
    s[a] = sa;
    S.h[a] = h;
  }
  real bu[SFFD_MAX_DEGREE + 1], dbu[SFFD_MAX_DEGREE + 1];
  real bv[SFFD_MAX_DEGREE + 1], dbv[SFFD_MAX_DEGREE + 1];
  real bw[SFFD_MAX_DEGREE + 1], dbw[SFFD_MAX_DEGREE + 1];
  latticeBernstein(L.degree.x, s[0], bu, dbu);
  latticeBernstein(L.degree.y, s[1], bv, dbv);
  latticeBernstein(L.degree.z, s[2], bw, dbw);

  uint box = (span[0] * L.boxes.y + span[1]) * L.boxes.z + span[2];
  uint base = box * L.boxes.w;
  P real3 R = real3(0), Ru = real3(0), Rv = real3(0), Rw = real3(0);
  uint c = base;
  for (uint i = 0u; i <= L.degree.x; ++i) {
    P real3 Sp = real3(0), Spv = real3(0), Spw = real3(0);
    for (uint j = 0u; j <= L.degree.y; ++j) {
      P real3 Sq = real3(0), Sqw = real3(0);
      for (uint k = 0u; k <= L.degree.z; ++k) {
        real3 cp = latticeCoeffs[c].xyz;
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
  S.value = R;
  S.du = Ru;
  S.dv = Rv;
  S.dw = Rw;
  return S;
}

// Deformed normal direction of a world-space normal n at the sample: cof(J_R) cof(A) n, up to a
// positive factor (ALGORITHM.md 1.4). Not normalised.
real3 latticeCofactorNormal(LatticeSample S, real3 n) {
  P real3 q;
  for (uint r = 0u; r < 3u; ++r) {
    P real xy = latticeFrame[SFFD_FRAME_COF_AFFINE + 4u * r] * n.x + latticeFrame[SFFD_FRAME_COF_AFFINE + 4u * r + 1u] * n.y;
    P real xyz = xy + latticeFrame[SFFD_FRAME_COF_AFFINE + 4u * r + 2u] * n.z;
    q[r] = xyz;
  }
  P real3 cu = scross(S.dv, S.dw) * (S.h.x * q.x);
  P real3 cv = scross(S.dw, S.du) * (S.h.y * q.y);
  P real3 cw = scross(S.du, S.dv) * (S.h.z * q.z);
  P real3 r = (cu + cv) + cw;
  return r;
}

#endif
