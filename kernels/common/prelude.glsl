// kernels/common/prelude.glsl: included first by every kernel.
// Maps the layout words of layout.h onto GLSL and selects the arithmetic variant:
//   SFFD_STRICT 0 (fast): built-in dot/cross/normalize, the compiler may fuse and reorder (in double,
//   a / b and sqrt refined to double precision, which GLSL does not ask of a driver).
//   SFFD_STRICT 1 (strict): every operation `precise`, no fma, a / b and sqrt correctly rounded
//   (correctly_rounded.h), hand-written dot/cross/normalize in a
//   fixed order, so GL, Vulkan and the C++ reference built with -ffp-contract=off agree bit for bit
//   (see docs/ARCHITECTURE.md, "Strict kernels").
#ifndef SFFD_PRELUDE_GLSL
#define SFFD_PRELUDE_GLSL

// The OpenGL ES form (the gles backend; cmake/Kernels.cmake makes it at build time from this source
// with "#version 310 es" as its first line, and GL_ES is then defined): ES 3.1 core only, highp
// everywhere. `precise` is ES 3.2 or OES/EXT_gpu_shader5: taken where the driver has it (the strict
// kernels need it to forbid contraction), left out on a bare ES 3.1 driver (docs/GLES.md).
#ifdef GL_ES
#if defined(GL_OES_gpu_shader5)
#extension GL_OES_gpu_shader5 : enable
#define SFFD_PRECISE precise
#elif defined(GL_EXT_gpu_shader5)
#extension GL_EXT_gpu_shader5 : enable
#define SFFD_PRECISE precise
#else
#define SFFD_PRECISE
#endif
precision highp float;
precision highp int;
#else
#define SFFD_PRECISE precise
#endif

#ifndef SFFD_STRICT
#define SFFD_STRICT 0
#endif
#ifndef SFFD_F64
#define SFFD_F64 0
#endif

// `real` is the kernel's arithmetic type: float, or double in the F64 variant (GL 4.0+ core,
// Vulkan shaderFloat64), used where float32 cannot meet an oracle's tolerance (PyGeM's 1.5e-6).
#if SFFD_F64
#define real double
#define real3 dvec3
#define real4 dvec4
#else
#define real float
#define real3 vec3
#define real4 vec4
#endif

#define SFFD_VEC4 vec4
#define SFFD_UVEC4 uvec4
#define SFFD_IVEC4 ivec4
#define SFFD_STRUCT_BEGIN(name) struct name {
#define SFFD_STRUCT_MEMBER(type, member) type member;
#define SFFD_STRUCT_END(name) };

#include "layout.h"

// Vulkan needs a descriptor set number; OpenGL GLSL forbids the qualifier.
#ifdef VULKAN
#define SFFD_SET set = 0,
#else
#define SFFD_SET
#endif

// P marks a declaration precise in the strict variant (no contraction, no reassociation).
#if SFFD_STRICT
#define P SFFD_PRECISE
#else
#define P
#endif

layout(local_size_x = SFFD_LOCAL_SIZE, local_size_y = 1, local_size_z = 1) in;

// Global thread index of a 1-D job dispatched as a 2-D grid of groups (65535 groups a dimension).
uint sffdThreadIndex() {
  return gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * uint(SFFD_LOCAL_SIZE));
}

// The host's assumptions for this dispatch (layout.h SFFD_ASSUME_*): defined by GL's source and by the
// SPIR-V compiled for one dispatch (cmake/Kernels.cmake), else a specialization constant.
#if defined(VULKAN) && !defined(SFFD_ASSUMPTIONS)
layout(constant_id = SFFD_SPEC_ASSUMPTIONS) const uint sffdAssumptions = 0u;
#else
#ifndef SFFD_ASSUMPTIONS
#define SFFD_ASSUMPTIONS 0u
#endif
const uint sffdAssumptions = SFFD_ASSUMPTIONS;
#endif
bool sffdAssumes(uint bit) { return (sffdAssumptions & bit) != 0u; }

// The trip count of a loop over record accesses. Where the host asks for rolled loops
// (SFFD_ASSUME_ROLLED_LOOPS: llvmpipe and lavapipe of Mesa 23 on, which write a storage access out per
// lane and component and compile unrolled copies for seconds at a kernel's first dispatch), n in a
// form no shader compiler can fold (gl_NumWorkGroups.z is at most 65535, and 1 here), so the loop is
// one copy of its body; not min(n, ...): Mesa 25.0's NIR takes a min's constant as the trip count.
// Elsewhere n itself: Mesa 22.3 compiles unrolled code quickly and runs every iteration of a rolled
// loop at a cost (a few hundred instructions per 8 lanes), and a GPU driver unrolls what pays.
uint sffdRolled(uint n) { return sffdAssumes(SFFD_ASSUME_ROLLED_LOOPS) ? n + (gl_NumWorkGroups.z >> 16u) : n; }
// Whether the host asks for rolled loops. A kernel with two forms of the same operations has for these
// drivers one record access an iteration, each access and the work on it once in the code (what Mesa
// 25.0 compiles fastest, at some warm cost), elsewhere the straight code Mesa 22.3 runs fastest. A
// constant expression rather than a call: where the assumptions are constant (GL, the SPIR-V compiled
// ahead) the compiler drops the other form before the driver sees it (chosen after inlining, the
// forms cost lavapipe 22.3 5 to 25 % more clip_write instructions). The same drivers skip a branch no lane
// takes, which the knot box kept in registers relies on (lattice_eval.glsl SFFD_LATTICE_BOX_CACHE).
const bool sffdRollsLoopsHere = (sffdAssumptions & SFFD_ASSUME_ROLLED_LOOPS) != 0u;
#define sffdRollsLoops() sffdRollsLoopsHere

// v with component i set to x, as one select per component: NVIDIA's GLSL compiler (580) cannot store
// into a double vector at a variable index ("can't find __setVectorIndex"), so no kernel does that.
real3 withComponent(real3 v, uint i, real x) { return real3(i == 0u ? x : v.x, i == 1u ? x : v.y, i == 2u ? x : v.z); }
uvec3 withComponent(uvec3 v, uint i, uint x) { return uvec3(i == 0u ? x : v.x, i == 1u ? x : v.y, i == 2u ? x : v.z); }
// Component i of v, likewise without a variable index.
real componentOf(real3 v, uint i) { return i == 0u ? v.x : (i == 1u ? v.y : v.z); }
uint componentOf(uvec3 v, uint i) { return i == 0u ? v.x : (i == 1u ? v.y : v.z); }

// Whether a vector of squared length len2 has a direction to normalize to (layout.h); snormalize returns
// one without as it is, a zero normal rather than a NaN that no writer accepts.
bool sffdHasDirection(real len2) { return len2 >= real(SFFD_MIN_DIRECTION_LENGTH2); }

// Included once for both uses below (the kernels' sources are inlined with each file once).
#include "correctly_rounded.h"
#if SFFD_STRICT
// a / b and sqrt(x) correctly rounded on every driver, as the C++ twin computes them (the header says why).
// Drivers known to round exactly (forDevice) skip the fix-up, which would cost lavapipe about twice its
// strict deform time (docs/CONFORMANCE.md "Strict kernels").
const bool sffdLooseDivision = (sffdAssumptions & SFFD_ASSUME_LOOSE_DIVISION) != 0u;
real sdiv(real a, real b) {
  P real q = a / b;
  return sffdLooseDivision ? sffdRoundedQuotient(a, b, q) : q;
}
real3 sdiv(real3 v, real s) { return real3(sdiv(v.x, s), sdiv(v.y, s), sdiv(v.z, s)); }
real ssqrt(real x) {
  P real s = sqrt(x);
  return sffdLooseDivision ? sffdRoundedRoot(x, s) : s;
}
real sdot(real3 a, real3 b) {
  P real xy = a.x * b.x + a.y * b.y;
  P real r = xy + a.z * b.z;
  return r;
}
real3 scross(real3 a, real3 b) {
  P real3 r = real3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
  return r;
}
real3 snormalize(real3 v) {
  P real len2 = sdot(v, v);
  if (!sffdHasDirection(len2)) return v;
  P real len = ssqrt(len2);
  P real3 r = sdiv(v, len);
  return r;
}
#elif SFFD_F64
// Fast double: a / b and sqrt to double precision where the driver gives less (the header says why).
real sdiv(real a, real b) {
  real q = a / b;
  return (q == real(0) || isinf(q) || isnan(q)) ? q : sffdRefinedQuotient(a, b, q);
}
real3 sdiv(real3 v, real s) { return real3(sdiv(v.x, s), sdiv(v.y, s), sdiv(v.z, s)); }
real ssqrt(real x) { return x > real(0) && !isinf(x) ? sffdRefinedRoot(x, sqrt(x)) : sqrt(x); }
real sdot(real3 a, real3 b) { return dot(a, b); }
real3 scross(real3 a, real3 b) { return cross(a, b); }
real3 snormalize(real3 v) { return sffdHasDirection(dot(v, v)) ? sdiv(v, ssqrt(dot(v, v))) : v; }
#else
real sdiv(real a, real b) { return a / b; }
real3 sdiv(real3 v, real s) { return v / s; }
real ssqrt(real x) { return sqrt(x); }
real sdot(real3 a, real3 b) { return dot(a, b); }
real3 scross(real3 a, real3 b) { return cross(a, b); }
real3 snormalize(real3 v) { return sffdHasDirection(dot(v, v)) ? normalize(v) : v; }
#endif

#endif
