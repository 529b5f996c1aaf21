// kernels/common/correctly_rounded.h: IEEE-754 round-to-nearest quotients and square roots from a
// driver's approximate ones, for the strict kernels (the fast double ones take only the Newton steps
// below). Valid GLSL (included by prelude.glsl) and C++
// (after correctly_rounded_twin.h, which correctly_rounded_test.cc runs on perturbed approximations).
//
// Why: GLSL and SPIR-V ask only +, - and * to be correctly rounded; a / b may be off by 2.5 ulp and
// sqrt by its inversesqrt's error. Mesa's llvmpipe and lavapipe round them exactly, NVIDIA's GL and
// Vulkan compilers do not (1 to 2 ulp, measured on an H200, driver 580), so the strict kernels lost
// their bit identity with the C++ twin there. The fix-up checks the driver's result q against the
// midpoints to its neighbours in exact integer arithmetic (the products of the significands fit
// umulExtended's 64 bits for float, four of them for double) and steps q by one ulp until the exact
// value lies between them. Ties cannot occur: a quotient or root of floats is never a midpoint.
// Zero, infinite, NaN and subnormal operands or results, where the exact value is what any driver
// gives or where drivers may flush, are returned as the driver computed them.
#ifndef SFFD_CORRECTLY_ROUNDED_H
#define SFFD_CORRECTLY_ROUNDED_H

#ifndef SFFD_CR_INLINE
#define SFFD_CR_INLINE
#endif
#ifndef SFFD_CR_PRECISE
#define SFFD_CR_PRECISE SFFD_PRECISE
#endif
// 0, in a form no shader compiler can fold (gl_NumWorkGroups.z is at most 65535), so that the stepping
// loops below stay loops: each iteration is one exact check of some sixty integer operations, a kernel
// divides in dozens of places, and unrolled (two checks an iteration, four iterations) they were most of
// what NVIDIA's compilers spent minutes on (docs/CONFORMANCE.md "Strict kernels").
#ifndef SFFD_CR_OPAQUE_ZERO
#define SFFD_CR_OPAQUE_ZERO (gl_NumWorkGroups.z >> 16u)
#endif
// The most iterations of a stepping loop: one check, then one a step, four steps either way.
#define SFFD_CR_CHECKS 6

// A stepping loop's state: 0 at first, 1 stepped up, -1 looking down, -2 stepped down, 2 done. Up while
// the exact value lies above m's upper midpoint; if it never did, down while it lies below m's lower
// one (the upper midpoint of m - 1). `above`: whether it lies above the midpoint probed, m's upper one
// in states 0 and 1, its lower one in -1 and -2.
SFFD_CR_INLINE int sffdStepState(int state, bool above) {
  if (state >= 0) return above ? 1 : (state == 0 ? -1 : 2);
  return above ? 2 : -2;
}

// Whether m * 2^d > M for a significand m (< 2^24) and a 64-bit M (hi, lo) >= 2^47.
SFFD_CR_INLINE bool sffdShiftedAbove(uint m, int d, uint hi, uint lo) {
  if (d < 0) return false;
  if (d >= 40) return true;
  uint sh = d >= 32 ? m << uint(d - 32) : (d == 0 ? 0u : m >> uint(32 - d));
  uint sl = d >= 32 ? 0u : m << uint(d);
  return sh > hi || (sh == hi && sl > lo);
}

SFFD_CR_INLINE uint sffdSignificand(uint bits) { return (bits & 0x7fffffu) | 0x800000u; }
SFFD_CR_INLINE int sffdExponent(uint bits) { return int((bits >> 23u) & 255u); }

// Whether |a| / |b| lies above x + ulp(x) / 2, x the positive normal float with bits m:
// A 2^(ea-150) > (2X + 1) 2^(ex-151) B 2^(eb-150).
SFFD_CR_INLINE bool sffdQuotientAbove(uint ua, uint ub, uint m) {
  uint hi, lo;
  umulExtended(2u * sffdSignificand(m) + 1u, sffdSignificand(ub), hi, lo);
  return sffdShiftedAbove(sffdSignificand(ua), sffdExponent(ua) - sffdExponent(ub) - sffdExponent(m) + 151, hi, lo);
}

// Whether x lies above (s + ulp(s) / 2)^2, s the positive normal float with bits m:
// X 2^(ex-150) > (2S + 1)^2 2^(2 es - 302).
SFFD_CR_INLINE bool sffdRootAbove(uint ux, uint m) {
  uint hi, lo;
  uint s2 = 2u * sffdSignificand(m) + 1u;
  umulExtended(s2, s2, hi, lo);
  return sffdShiftedAbove(sffdSignificand(ux), sffdExponent(ux) - 2 * sffdExponent(m) + 152, hi, lo);
}

// a / b rounded to nearest, from the driver's q = a / b.
SFFD_CR_INLINE float sffdRoundedQuotient(float a, float b, float q) {
  uint ua = floatBitsToUint(a), ub = floatBitsToUint(b), uq = floatBitsToUint(q);
  int ea = sffdExponent(ua), eb = sffdExponent(ub), eq = sffdExponent(uq);
  if (ea == 0 || ea == 255 || eb == 0 || eb == 255 || eq < 2 || eq > 253) return q;
  uint m = uq & 0x7fffffffu;
  for (int i = 0, state = 0; i < SFFD_CR_CHECKS + int(SFFD_CR_OPAQUE_ZERO); ++i) {
    state = sffdStepState(state, sffdQuotientAbove(ua, ub, state < 0 ? m - 1u : m));
    if (state == 2) break;
    m = state == 1 ? m + 1u : (state == -2 ? m - 1u : m);
  }
  return uintBitsToFloat(((ua ^ ub) & 0x80000000u) | m);
}

// sqrt(x) rounded to nearest, from the driver's s = sqrt(x).
SFFD_CR_INLINE float sffdRoundedRoot(float x, float s) {
  uint ux = floatBitsToUint(x), us = floatBitsToUint(s);
  int es = sffdExponent(us);
  if (ux >= 0x7f800000u || ux < 0x00800000u || us >= 0x80000000u || es < 2 || es > 253) return s;
  uint m = us;
  for (int i = 0, state = 0; i < SFFD_CR_CHECKS + int(SFFD_CR_OPAQUE_ZERO); ++i) {
    state = sffdStepState(state, sffdRootAbove(ux, state < 0 ? m - 1u : m));
    if (state == 2) break;
    m = state == 1 ? m + 1u : (state == -2 ? m - 1u : m);
  }
  return uintBitsToFloat(m);
}

#if defined(__cplusplus) || SFFD_F64
// The same for double: 53-bit significands as (lo, hi) pairs, their products in 128 bits (x lowest).
SFFD_CR_INLINE uvec2 sffdSignificand64(uvec2 bits) { return uvec2(bits.x, (bits.y & 0xfffffu) | 0x100000u); }
SFFD_CR_INLINE int sffdExponent64(uvec2 bits) { return int((bits.y >> 20u) & 2047u); }

// 2 m + 1 for a 53-bit m: below 2^54, so no carry leaves y.
SFFD_CR_INLINE uvec2 sffdOddAbove(uvec2 m) { return uvec2((m.x << 1u) | 1u, (m.y << 1u) | (m.x >> 31u)); }

// The 128-bit product of two values below 2^64.
SFFD_CR_INLINE uvec4 sffdMul64(uvec2 a, uvec2 b) {
  uint h0, l0, h1, l1, h2, l2, h3, l3, c0, c1, c2;
  umulExtended(a.x, b.x, h0, l0);
  umulExtended(a.x, b.y, h1, l1);
  umulExtended(a.y, b.x, h2, l2);
  umulExtended(a.y, b.y, h3, l3);
  uint w1 = uaddCarry(h0, l1, c0);
  w1 = uaddCarry(w1, l2, c1);
  uint w2 = uaddCarry(h1, h2, c2);
  uint c3, c4;
  w2 = uaddCarry(w2, l3, c3);
  w2 = uaddCarry(w2, c0 + c1, c4);
  return uvec4(l0, w1, w2, h3 + c2 + c3 + c4);
}

// Whether m * 2^d > M for a 53-bit m and a 128-bit M >= 2^105.
SFFD_CR_INLINE bool sffdShiftedAbove64(uvec2 m, int d, uvec4 M) {
  if (d < 0) return false;
  if (d >= 75) return true;
  uint w[4];
  for (int i = 0; i < 4; ++i) {
    int lo = 32 * i - d;  // bit of m that lands on bit 0 of word i
    uint v = 0u;
    for (int k = 0; k < 2; ++k) {
      uint part = k == 0 ? m.x : m.y;
      int off = lo - 32 * k;  // bit of part that lands on bit 0 of word i
      if (off <= -32 || off >= 32) continue;
      v |= off >= 0 ? part >> uint(off) : part << uint(-off);
    }
    w[i] = v;
  }
  uint Mw[4];
  Mw[0] = M.x;
  Mw[1] = M.y;
  Mw[2] = M.z;
  Mw[3] = M.w;
  for (int i = 3; i >= 0; --i)
    if (w[i] != Mw[i]) return w[i] > Mw[i];
  return false;
}

// Adjacent doubles are adjacent 64-bit integers.
SFFD_CR_INLINE uvec2 sffdNext64(uvec2 m) { return uvec2(m.x + 1u, m.y + (m.x == 0xffffffffu ? 1u : 0u)); }
SFFD_CR_INLINE uvec2 sffdPrev64(uvec2 m) { return uvec2(m.x - 1u, m.y - (m.x == 0u ? 1u : 0u)); }

// A 2^(ea-1075) > (2X + 1) 2^(ex-1076) B 2^(eb-1075).
SFFD_CR_INLINE bool sffdQuotientAbove64(uvec2 ua, uvec2 ub, uvec2 m) {
  uvec4 M = sffdMul64(sffdOddAbove(sffdSignificand64(m)), sffdSignificand64(ub));
  return sffdShiftedAbove64(sffdSignificand64(ua), sffdExponent64(ua) - sffdExponent64(ub) - sffdExponent64(m) + 1076, M);
}

// X 2^(ex-1075) > (2S + 1)^2 2^(2 es - 2152).
SFFD_CR_INLINE bool sffdRootAbove64(uvec2 ux, uvec2 m) {
  uvec2 s2 = sffdOddAbove(sffdSignificand64(m));
  return sffdShiftedAbove64(sffdSignificand64(ux), sffdExponent64(ux) - 2 * sffdExponent64(m) + 1077, sffdMul64(s2, s2));
}

// GLSL asks double division and sqrt to be only as precise as float's, and NVIDIA's GL is not much
// better (PyGeM's sphere missed its 1.5e-6 by 7e-6, strict f64 by 1e-9 to 1e-5): two Newton steps take
// such a q to within an ulp or two (r = a - q b is within half an ulp of a). The fast double kernels
// use these alone, the strict ones before the exact check.
SFFD_CR_INLINE double sffdRefinedQuotient(double a, double b, double q) {
  for (int i = 0; i < 2; ++i) {
    SFFD_CR_PRECISE double r = a - q * b;
    SFFD_CR_PRECISE double n = q + r / b;
    q = n;
  }
  return q;
}

SFFD_CR_INLINE double sffdRefinedRoot(double x, double s) {
  for (int i = 0; i < 2; ++i) {
    SFFD_CR_PRECISE double r = x - s * s;
    SFFD_CR_PRECISE double n = s + r / (s + s);
    s = n;
  }
  return s;
}

SFFD_CR_INLINE double sffdRoundedQuotient(double a, double b, double q) {
  uvec2 ua = unpackDouble2x32(a), ub = unpackDouble2x32(b);
  int ea = sffdExponent64(ua), eb = sffdExponent64(ub);
  if (ea == 0 || ea == 2047 || eb == 0 || eb == 2047) return q;
  // sffdRefinedQuotient's Newton steps with one division, not two: each step multiplies q's relative
  // error by 1 - b rb, rb the driver's 1 / b, about as small as q's first error. For |b| >= 2^1022,
  // whose reciprocal would be subnormal (and flushed by some drivers), by way of b 2^-64 (exact).
  SFFD_CR_PRECISE double scale = eb >= 2045 ? 5.421010862427522e-20 : 1.0;   // 2^-64
  SFFD_CR_PRECISE double rb = 1.0 / (b * scale);
  for (int i = 0; i < 2; ++i) {
    SFFD_CR_PRECISE double r = a - q * b;
    SFFD_CR_PRECISE double n = q + (r * rb) * scale;
    q = n;
  }
  uvec2 uq = unpackDouble2x32(q);
  int eq = sffdExponent64(uq);
  if (eq < 2 || eq > 2045) return q;
  uvec2 m = uvec2(uq.x, uq.y & 0x7fffffffu);
  for (int i = 0, state = 0; i < SFFD_CR_CHECKS + int(SFFD_CR_OPAQUE_ZERO); ++i) {
    state = sffdStepState(state, sffdQuotientAbove64(ua, ub, state < 0 ? sffdPrev64(m) : m));
    if (state == 2) break;
    m = state == 1 ? sffdNext64(m) : (state == -2 ? sffdPrev64(m) : m);
  }
  return packDouble2x32(uvec2(m.x, ((ua.y ^ ub.y) & 0x80000000u) | m.y));
}

SFFD_CR_INLINE double sffdRoundedRoot(double x, double s) {
  uvec2 ux = unpackDouble2x32(x);
  if (ux.y >= 0x7ff00000u || ux.y < 0x00100000u || !(s > 0.0)) return s;
  SFFD_CR_PRECISE double h = 0.5 / s;   // sffdRefinedRoot's steps with one division, as above
  for (int i = 0; i < 2; ++i) {
    SFFD_CR_PRECISE double r = x - s * s;
    SFFD_CR_PRECISE double n = s + r * h;
    s = n;
  }
  uvec2 us = unpackDouble2x32(s);
  int es = sffdExponent64(us);
  if (us.y >= 0x80000000u || es < 2 || es > 2045) return s;
  uvec2 m = us;
  for (int i = 0, state = 0; i < SFFD_CR_CHECKS + int(SFFD_CR_OPAQUE_ZERO); ++i) {
    state = sffdStepState(state, sffdRootAbove64(ux, state < 0 ? sffdPrev64(m) : m));
    if (state == 2) break;
    m = state == 1 ? sffdNext64(m) : (state == -2 ? sffdPrev64(m) : m);
  }
  return packDouble2x32(m);
}
#endif

#endif
