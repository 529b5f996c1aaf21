// Small vector type of the C++ twins of the kernels (lattice_eval.h, pn_eval.h): the GLSL
// operations the strict kernels use, one rounding each, in the same order. With -ffp-contract=off
// the float instantiation matches the strict kernels bit for bit.
#pragma once
#include <cmath>

#include <glm/glm.hpp>

#include "kernels/common/shader_layout.h"

namespace sffd {

template <class Real>
struct RVec3 {
  Real x = 0, y = 0, z = 0;
  Real& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  Real operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  static RVec3 from(const glm::dvec3& v) { return {Real(v.x), Real(v.y), Real(v.z)}; }
  glm::dvec3 glm() const { return {double(x), double(y), double(z)}; }
};
// x, y, z (and an unused fourth) in the lanes of one GCC / Clang vector, for the CPU twins' hot loops:
// lane by lane the operations RVec3's would do, in the same order, so the same bits.
template <class Real>
struct Lanes4 {
  typedef Real type __attribute__((vector_size(4 * sizeof(Real))));
};
// N reals in the lanes of one vector (one AVX register of floats at 8; pairs or halves without AVX), for
// the twins' loops across vertices: each lane the operations of one, in its order.
template <class Real, int N>
struct LanesOf {
  typedef Real type __attribute__((vector_size(N * sizeof(Real))));
};

template <class Real> RVec3<Real> operator+(RVec3<Real> a, RVec3<Real> b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
template <class Real> RVec3<Real> operator-(RVec3<Real> a, RVec3<Real> b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
template <class Real> RVec3<Real> operator*(RVec3<Real> a, Real s) { return {a.x * s, a.y * s, a.z * s}; }
template <class Real> RVec3<Real> operator/(RVec3<Real> a, Real s) { return {a.x / s, a.y / s, a.z / s}; }
template <class Real> Real sdot(RVec3<Real> a, RVec3<Real> b) {
  Real xy = a.x * b.x + a.y * b.y;
  return xy + a.z * b.z;
}
template <class Real> RVec3<Real> scross(RVec3<Real> a, RVec3<Real> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// Whether a is lexicographically before b (smooth_deform.glsl's lexLess).
template <class Real> bool lexLess(RVec3<Real> a, RVec3<Real> b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}
// Whether a vector of squared length len2 has a direction to normalize to (layout.h, prelude.glsl's
// sffdHasDirection).
template <class Real> bool hasDirection(Real len2) { return len2 >= Real(SFFD_MIN_DIRECTION_LENGTH2); }
// The unit vector of v, or v itself where it has none (hasDirection), as the kernels' snormalize.
template <class Real> RVec3<Real> snormalize(RVec3<Real> v) {
  const Real len2 = sdot(v, v);
  if (!hasDirection(len2)) return v;
  Real len = std::sqrt(len2);
  return {v.x / len, v.y / len, v.z / len};
}

}  // namespace sffd
