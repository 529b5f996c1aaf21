// C++ twin of the site evaluation in shaders/common/clip.glsl: a point of a parent triangle (a corner,
// a point of an edge at a parameter from its lower-weld endpoint, or an interior point) evaluated on
// the parent's PN patch. Templated on the arithmetic type; keep in step with the GLSL.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "pn_eval.h"
#include "shader_layout.h"

namespace sffd {

template <class Real>
struct SiteT {
  uint32_t kind = 6;   // 0..2 corner, 3..5 on edge kind-3, 6 inside
  Real t = 0;
  RVec3<Real> lam;
};

template <class Real>
struct SiteValueT {
  RVec3<Real> lam, xpn, xflat, nlin, npn;
};

// The packed mesh and PN buffers of one parent triangle, as the kernels read them.
template <class Real>
struct ParentT {
  uint32_t id = 0;
  uint32_t verts[3]{}, welds[3]{};
  RVec3<Real> V[3], N[3];
  const Real* pn = nullptr;     // SFFD_PN_STRIDE * 4 values
  const Real* slot = nullptr;   // SFFD_SLOT_NORMAL_STRIDE * 4 values

  RVec3<Real> pnAt(int i) const { return {pn[4 * i], pn[4 * i + 1], pn[4 * i + 2]}; }
  RVec3<Real> slotAt(int i) const { return {slot[4 * i], slot[4 * i + 1], slot[4 * i + 2]}; }
  Real slotW(int i) const { return slot[4 * i + 3]; }

  void edgeEnds(int e, int& lo, int& hi) const {
    lo = e;
    hi = (e + 1) % 3;
    if (welds[hi] < welds[lo]) std::swap(lo, hi);
  }
  static int slotOf(int corner, int e) { return corner == e ? 2 * corner + 1 : 2 * corner; }

  SiteValueT<Real> evaluate(const SiteT<Real>& s) const {
    SiteValueT<Real> r;
    if (s.kind < 3) {
      int k = int(s.kind);
      r.lam = {};
      r.lam[k] = Real(1);
      r.xpn = r.xflat = V[k];
      r.nlin = r.npn = N[k];
    } else if (s.kind < 6) {
      int e = int(s.kind) - 3, lo, hi;
      edgeEnds(e, lo, hi);
      Real t = s.t, u = Real(1) - t;
      r.lam = {};
      r.lam[lo] = u;
      r.lam[hi] = t;
      RVec3<Real> bLo = pnAt(kSlotControlPoint[slotOf(lo, e)]), bHi = pnAt(kSlotControlPoint[slotOf(hi, e)]);
      r.xpn = pnEdgeCurve(V[lo], bLo, bHi, V[hi], t);
      r.xflat = V[lo] + (V[hi] - V[lo]) * t;
      r.nlin = snormalize(N[lo] * u + N[hi] * t);
      r.npn = pnEdgeNormalCurve(N[lo], pnAt(SFFD_PN_NORMALS + kEdgeNormalIndex[e]), N[hi], t);
    } else {
      RVec3<Real> l = s.lam;
      r.lam = l;
      Real w[10];
      pnCubicWeights(l, w);
      RVec3<Real> x{};
      for (int i = 0; i < 10; ++i) x = x + pnAt(i) * w[i];
      r.xpn = x;
      r.xflat = (V[0] * l.x + V[1] * l.y) + V[2] * l.z;
      r.nlin = snormalize((N[0] * l.x + N[1] * l.y) + N[2] * l.z);
      Real q[6];
      pnQuadraticWeights(l, q);
      RVec3<Real> nn{};
      for (int i = 0; i < 6; ++i) nn = nn + pnAt(SFFD_PN_NORMALS + i) * q[i];
      r.npn = snormalize(nn);
    }
    return r;
  }

  Real paramOnEdge(const SiteT<Real>& s, int e) const {
    int lo, hi;
    edgeEnds(e, lo, hi);
    if (s.kind < 3) return int(s.kind) == lo ? Real(0) : Real(1);
    return s.t;
  }

  // The neighbour's PN normal at parameter t of edge e, w = 1 where the edge is a crease (else all 0).
  std::array<Real, 4> neighbourNormal(int e, Real t) const {
    int lo, hi;
    edgeEnds(e, lo, hi);
    int sLo = 2 * slotOf(lo, e), sHi = 2 * slotOf(hi, e);
    if (slotW(sLo) < Real(0.5) && slotW(sHi) < Real(0.5)) return {0, 0, 0, 0};
    RVec3<Real> nLo = slotW(sLo + 1) > Real(0.5) ? slotAt(sLo + 1) : slotAt(sLo);
    RVec3<Real> nHi = slotW(sHi + 1) > Real(0.5) ? slotAt(sHi + 1) : slotAt(sHi);
    if (t == Real(0)) return {nLo.x, nLo.y, nLo.z, Real(1)};
    if (t == Real(1)) return {nHi.x, nHi.y, nHi.z, Real(1)};
    RVec3<Real> nMid = pnEdgeNormal(V[lo], V[hi], nLo, nHi);
    RVec3<Real> n = pnEdgeNormalCurve(nLo, nMid, nHi, t);
    return {n.x, n.y, n.z, Real(1)};
  }
};

}  // namespace sffd
