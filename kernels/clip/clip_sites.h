// C++ twin of the site evaluation in kernels/clip/clip_sites.glsl: a point of a parent triangle (a corner,
// a point of an edge at a parameter from its lower-weld endpoint, or an interior point) evaluated on
// the parent's PN patch. Templated on the arithmetic type; keep in step with the GLSL.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "kernels/pn/pn_eval.h"
#include "kernels/common/shader_layout.h"

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

// Writes one sub-triangle record (kernels/common/layout.h, SFFD_SUB_*) and its header. Slot 2c is
// corner c on the sub-edge towards corner c+2, slot 2c+1 towards c+1; `parentEdgeOf(c, d)` gives the
// parent edge the sub-edge (c, d) lies on, or -1. Where that parent edge is a crease, the slot holds
// the neighbour's PN normal (w = 1); elsewhere the corner's own PN normal (w = 0). The crease bits
// go in the header and in the record (SFFD_SUB_CREASE_BITS).
// `Out`: the record's storage type (Real in a kernel's buffer, double on the host).
template <class Real, class Out, class ParentEdgeOf>
void storeSubTriangle(const ParentT<Real>& par, const SiteT<Real> site[3], const SiteValueT<Real> val[3],
                      ParentEdgeOf parentEdgeOf, Out* rec, uint32_t* hdr) {
  auto put = [&](int slot, RVec3<Real> v, Real w) {
    rec[4 * slot] = v.x, rec[4 * slot + 1] = v.y, rec[4 * slot + 2] = v.z, rec[4 * slot + 3] = w;
  };
  uint32_t creaseBits = 0;
  for (int c = 0; c < 3; ++c) {
    put(SFFD_SUB_LAM + c, val[c].lam, 0);
    put(SFFD_SUB_XPN + c, val[c].xpn, 0);
    put(SFFD_SUB_XFLAT + c, val[c].xflat, 0);
    put(SFFD_SUB_NLIN + c, val[c].nlin, 0);
    put(SFFD_SUB_NPN + c, val[c].npn, 0);
    for (int h = 0; h < 2; ++h) {
      int d = h == 0 ? (c + 2) % 3 : (c + 1) % 3;
      RVec3<Real> nn = val[c].npn;
      Real nw = 0;
      int e = parentEdgeOf(c, d);
      if (e >= 0) {
        auto nb = par.neighbourNormal(e, par.paramOnEdge(site[c], e));
        if (nb[3] > Real(0.5)) {
          nn = {nb[0], nb[1], nb[2]};
          nw = 1;
          creaseBits |= 1u << (2 * c + h);
        }
      }
      put(SFFD_SUB_NNBR + 2 * c + h, nn, nw);
    }
  }
  put(SFFD_SUB_CREASE_BITS, val[0].lam, Real(creaseBits));
  hdr[0] = par.id, hdr[1] = creaseBits, hdr[2] = 0, hdr[3] = 0;
}

}  // namespace sffd
