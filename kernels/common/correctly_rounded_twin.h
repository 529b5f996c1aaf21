// C++ view of kernels/common/correctly_rounded.h: the GLSL built-ins it uses, then the header itself,
// so that a test runs the very code the strict kernels compile.
#pragma once
#include <bit>
#include <cstdint>

namespace sffd::kernels::rounded {
using uint = uint32_t;
struct uvec2 { uint x, y; };
struct uvec4 { uint x, y, z, w; };
inline uint floatBitsToUint(float f) { return std::bit_cast<uint>(f); }
inline float uintBitsToFloat(uint u) { return std::bit_cast<float>(u); }
inline uvec2 unpackDouble2x32(double d) {
  uint64_t u = std::bit_cast<uint64_t>(d);
  return {uint(u), uint(u >> 32)};
}
inline double packDouble2x32(uvec2 v) { return std::bit_cast<double>(uint64_t(v.y) << 32 | v.x); }
inline void umulExtended(uint a, uint b, uint& msb, uint& lsb) {
  uint64_t p = uint64_t(a) * b;
  msb = uint(p >> 32);
  lsb = uint(p);
}
inline uint uaddCarry(uint a, uint b, uint& carry) {
  carry = uint(a + b < a);
  return a + b;
}
#define SFFD_CR_INLINE inline
#define SFFD_CR_PRECISE   // the project builds with -ffp-contract=off
#define SFFD_CR_OPAQUE_ZERO 0u
#include "correctly_rounded.h"
#undef SFFD_CR_INLINE
#undef SFFD_CR_PRECISE
#undef SFFD_CR_OPAQUE_ZERO
}  // namespace sffd::kernels::rounded
