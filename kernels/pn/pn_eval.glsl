// kernels/pn/pn_eval.glsl: PN triangles with sharp features (Vlachos et al. 2001, "Curved PN
// triangles"; crease handling of Cui & Feng 2015 and Lu & Feng; METHOD.md 3.2). The C++ twin is
// kernels/pn/pn_eval.h; both follow the same operation order (strict variants agree bit for bit).
//
// Every quantity on a shared edge is computed from data ordered canonically (by weld id, and the
// slot normals ordered on the host), so the two triangles of an edge produce identical bits.
#ifndef SFFD_PN_GLSL
#define SFFD_PN_GLSL

// Control point of corner slot s (2, 1, 3, 7, 8, 5; kSlotControlPoint in pn_eval.h) as 4-bit fields of
// a constant: a constant array indexed by a variable is copied into local memory at every use in the
// SPIR-V that glslang emits, which made the Vulkan kernels several times slower than GL on lavapipe.
uint kSlotCp(uint s) { return (0x587312u >> (4u * s)) & 15u; }

// Edge control point next to corner Vc on the edge towards Vo (METHOD.md 3.2). nFirst.w = 1 marks
// a crease: the point is projected onto the crease line t = normalize(nFirst x nSecond).
real3 pnEdgePoint(real3 Vc, real3 Vo, real4 nFirst, real3 nSecond) {
  P real3 d = Vo - Vc;
  if (nFirst.w > real(0.5)) {
    P real3 c = scross(nFirst.xyz, nSecond);
    P real len2 = sdot(c, c);
    if (len2 > real(1e-12)) {
      P real3 t = sdiv(c, ssqrt(len2));
      P real3 r = Vc + t * sdiv(sdot(d, t), real(3));
      return r;
    }
  }
  P real3 n = nFirst.xyz;
  P real3 sum = (Vc + Vc) + Vo - n * sdot(d, n);
  P real3 r = sdiv(sum, real(3));
  return r;
}

// Quadratic normal control point of edge (Pi, Pj): the average normal reflected across the plane
// perpendicular to the edge. Callers pass the edge in weld-id order.
real3 pnEdgeNormal(real3 Pi, real3 Pj, real3 Ni, real3 Nj) {
  P real3 d = Pj - Pi;
  P real3 s = Ni + Nj;
  P real dd = sdot(d, d);
  P real3 r = s;
  if (dd > real(0)) {
    P real ds2 = real(2) * sdot(d, s);
    P real k = sdiv(ds2, dd);
    r = s - d * k;
  }
  P real len2 = sdot(r, r);
  if (!(len2 > real(0))) return Ni;
  P real3 n = sdiv(r, ssqrt(len2));
  return n;
}

// Cubic Bernstein weights of the 10 control points at lam, in the linear index order.
void pnCubicWeights(real3 lam, out real w[10]) {
  P real u = lam.x, v = lam.y, t = lam.z;
  P real uu = u * u, vv = v * v, tt = t * t;
  w[0] = uu * u;
  w[1] = real(3) * uu * v;
  w[2] = real(3) * uu * t;
  w[3] = real(3) * u * vv;
  w[4] = real(6) * u * v * t;
  w[5] = real(3) * u * tt;
  w[6] = vv * v;
  w[7] = real(3) * vv * t;
  w[8] = real(3) * v * tt;
  w[9] = tt * t;
}

// Quadratic Bernstein weights of the 6 normal control points at lam (order 200,110,101,020,011,002).
void pnQuadraticWeights(real3 lam, out real w[6]) {
  P real u = lam.x, v = lam.y, t = lam.z;
  w[0] = u * u;
  w[1] = real(2) * u * v;
  w[2] = real(2) * u * t;
  w[3] = v * v;
  w[4] = real(2) * v * t;
  w[5] = t * t;
}

// The cubic edge curve from A to B with inner control points bA (near A) and bB, at parameter t from A.
real3 pnEdgeCurve(real3 A, real3 bA, real3 bB, real3 B, real t) {
  P real s = real(1) - t;
  P real w0 = s * s * s, w1 = real(3) * s * s * t, w2 = real(3) * s * t * t, w3 = t * t * t;
  P real3 r = ((A * w0 + bA * w1) + bB * w2) + B * w3;
  return r;
}

// The quadratic normal along an edge from A to B (middle control point nAB), normalised.
real3 pnEdgeNormalCurve(real3 nA, real3 nAB, real3 nB, real t) {
  P real s = real(1) - t;
  P real3 r = (nA * (s * s) + nAB * (real(2) * s * t)) + nB * (t * t);
  return snormalize(r);
}

#endif
