// C++ twin of kernels/pn/pn_eval.glsl (PN triangles with sharp features, METHOD.md 3.2), templated
// on the arithmetic type like lattice_eval.h. Keep the two in step, operation for operation.
#pragma once
#include <array>

#include "kernels/common/rvec.h"

namespace sffd {

// Cubic control point of each corner (b300, b030, b003) and of each corner slot (slot 2c: corner c
// towards corner c+2; 2c+1: towards c+1).
inline constexpr std::array<int, 3> kCornerControlPoint = {0, 6, 9};
inline constexpr std::array<int, 6> kSlotControlPoint = {2, 1, 3, 7, 8, 5};
// Quadratic normal control point of each edge e = (corner e, corner e+1): 110, 011, 101.
inline constexpr std::array<int, 3> kEdgeNormalIndex = {1, 4, 2};

template <class Real>
RVec3<Real> pnEdgePoint(RVec3<Real> Vc, RVec3<Real> Vo, RVec3<Real> nFirst, bool crease, RVec3<Real> nSecond) {
  RVec3<Real> d = Vo - Vc;
  if (crease) {
    RVec3<Real> c = scross(nFirst, nSecond);
    Real len2 = sdot(c, c);
    if (len2 > Real(1e-12)) {
      RVec3<Real> t = c / Real(std::sqrt(len2));
      return Vc + t * (sdot(d, t) / Real(3));
    }
  }
  RVec3<Real> n = nFirst;
  return (((Vc + Vc) + Vo) - n * sdot(d, n)) / Real(3);
}

template <class Real>
RVec3<Real> pnEdgeNormal(RVec3<Real> Pi, RVec3<Real> Pj, RVec3<Real> Ni, RVec3<Real> Nj) {
  RVec3<Real> d = Pj - Pi;
  RVec3<Real> s = Ni + Nj;
  Real dd = sdot(d, d);
  RVec3<Real> r = s;
  if (dd > Real(0)) {
    Real k = Real(2) * sdot(d, s) / dd;
    r = s - d * k;
  }
  Real len2 = sdot(r, r);
  if (!(len2 > Real(0))) return Ni;
  return r / Real(std::sqrt(len2));
}

template <class Real>
void pnCubicWeights(RVec3<Real> lam, Real w[10]) {
  Real u = lam.x, v = lam.y, t = lam.z;
  Real uu = u * u, vv = v * v, tt = t * t;
  w[0] = uu * u;
  w[1] = Real(3) * uu * v;
  w[2] = Real(3) * uu * t;
  w[3] = Real(3) * u * vv;
  w[4] = Real(6) * u * v * t;
  w[5] = Real(3) * u * tt;
  w[6] = vv * v;
  w[7] = Real(3) * vv * t;
  w[8] = Real(3) * v * tt;
  w[9] = tt * t;
}

template <class Real>
void pnQuadraticWeights(RVec3<Real> lam, Real w[6]) {
  Real u = lam.x, v = lam.y, t = lam.z;
  w[0] = u * u;
  w[1] = Real(2) * u * v;
  w[2] = Real(2) * u * t;
  w[3] = v * v;
  w[4] = Real(2) * v * t;
  w[5] = t * t;
}

// The cubic Bernstein weights of pnEdgeCurve at t (from A).
template <class Real>
void pnEdgeWeights(Real t, Real w[4]) {
  Real s = Real(1) - t;
  w[0] = s * s * s, w[1] = Real(3) * s * s * t, w[2] = Real(3) * s * t * t, w[3] = t * t * t;
}

template <class Real>
RVec3<Real> pnEdgeCurve(RVec3<Real> A, RVec3<Real> bA, RVec3<Real> bB, RVec3<Real> B, Real t) {
  Real w[4];
  pnEdgeWeights(t, w);
  return ((A * w[0] + bA * w[1]) + bB * w[2]) + B * w[3];
}

template <class Real>
RVec3<Real> pnEdgeNormalCurve(RVec3<Real> nA, RVec3<Real> nAB, RVec3<Real> nB, Real t) {
  Real s = Real(1) - t;
  return snormalize((nA * (s * s) + nAB * (Real(2) * s * t)) + nB * (t * t));
}

// One triangle's PN record: 10 cubic control points then 6 quadratic normal control points.
template <class Real>
struct PnPatchT {
  std::array<RVec3<Real>, 10> cp;
  std::array<RVec3<Real>, 6> n;
};

// Builds the PN record from corners, corner normals, slot normals (first/second per slot, crease
// flags) and the corners' weld ids, as the pn_triangles kernel does.
template <class Real>
PnPatchT<Real> pnBuild(const RVec3<Real> V[3], const RVec3<Real> N[3], const RVec3<Real> first[6],
                       const bool crease[6], const RVec3<Real> second[6], const uint32_t weld[3]) {
  PnPatchT<Real> P;
  P.cp[0] = V[0];
  P.cp[6] = V[1];
  P.cp[9] = V[2];
  RVec3<Real> edgeSum{};
  for (int s = 0; s < 6; ++s) {
    int c = s / 2;
    int other = (s % 2 == 1) ? (c + 1) % 3 : (c + 2) % 3;
    RVec3<Real> b = pnEdgePoint(V[c], V[other], first[s], crease[s], second[s]);
    P.cp[kSlotControlPoint[s]] = b;
    edgeSum = edgeSum + b;
  }
  RVec3<Real> E = edgeSum / Real(6);
  RVec3<Real> Vm = ((V[0] + V[1]) + V[2]) / Real(3);
  P.cp[4] = E + (E - Vm) / Real(2);
  P.n[0] = N[0];
  P.n[3] = N[1];
  P.n[5] = N[2];
  for (int e = 0; e < 3; ++e) {
    int a = e, b = (e + 1) % 3;
    if (weld[b] < weld[a]) std::swap(a, b);
    P.n[kEdgeNormalIndex[e]] = pnEdgeNormal(V[a], V[b], N[a], N[b]);
  }
  return P;
}

}  // namespace sffd
