// C++ twin of kernels/common/lattice_eval.glsl, templated on the arithmetic type: in double it is the
// CPU reference (the oracle); in float, compiled with -ffp-contract=off, it performs the operations
// of the strict kernels in the same order and so matches them bit for bit. Keep the two in step.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include "kernels/common/rvec.h"
#include "kernels/common/shader_layout.h"

namespace sffd {

template <class Real>
struct LatticeSampleT {
  RVec3<Real> value, du, dv, dw, h;
  bool inside = true;
};

template <class Real>
class LatticeEvaluator {
 public:
  static constexpr int kMax = SFFD_MAX_DEGREE + 1;

  // frame: the lattice frame buffer's reals; coeffs: 4 reals per Bezier coefficient (layout.h).
  LatticeEvaluator(const gpu::LatticeParams& params, const Real* frame, const Real* coeffs)
      : L_(params), frame_(frame), coeffs_(coeffs) {}
  LatticeEvaluator(const gpu::LatticeParams& params, const std::vector<Real>& frame, const std::vector<Real>& coeffs)
      : LatticeEvaluator(params, frame.data(), coeffs.data()) {}

  // The largest i with breaks[i] <= t, clamped to [0, n-1] (counted, as the kernels do).
  uint32_t span(uint32_t first, uint32_t n, Real t) const {
    uint32_t s = 0;
    for (uint32_t i = 1; i < n; ++i) s += frame_[first + i] <= t ? 1u : 0u;
    return s;
  }

  static void bernstein(uint32_t n, Real s, Real b[kMax], Real db[kMax]) { bernsteinOf(n, s, b, db); }

  // The common degrees run with the loop bounds known to the compiler: the same operations in the same
  // order (same bits), unrolled, about twice as fast as the general loops.
  LatticeSampleT<Real> evaluate(RVec3<Real> x) const {
    const auto d = L_.degree;
    if (d.x == 2 && d.y == 2 && d.z == 2) return evaluateOf(x, Degree<2>{}, Degree<2>{}, Degree<2>{});
    if (d.x == 3 && d.y == 3 && d.z == 3) return evaluateOf(x, Degree<3>{}, Degree<3>{}, Degree<3>{});
    return evaluateOf(x, d.x, d.y, d.z);
  }

  // cof(J_R) cof(A) n up to a positive factor; not normalised (METHOD.md 1.4).
  RVec3<Real> cofactorNormal(const LatticeSampleT<Real>& S, RVec3<Real> n) const {
    RVec3<Real> q;
    for (int r = 0; r < 3; ++r) {
      const Real* row = &frame_[SFFD_FRAME_COF_AFFINE + 4 * r];
      Real xy = row[0] * n.x + row[1] * n.y;
      q[r] = xy + row[2] * n.z;
    }
    RVec3<Real> cu = scross(S.dv, S.dw) * (S.h.x * q.x);
    RVec3<Real> cv = scross(S.dw, S.du) * (S.h.y * q.y);
    RVec3<Real> cw = scross(S.du, S.dv) * (S.h.z * q.z);
    return (cu + cv) + cw;
  }

  const gpu::LatticeParams& params() const { return L_; }

 private:
  template <uint32_t N>
  using Degree = std::integral_constant<uint32_t, N>;
  using Lanes = typename Lanes4<Real>::type;   // four reals a coefficient (layout.h)
  // Written out where used, not as functions: a double vector without AVX has no agreed calling
  // convention (GCC warns), and nothing here needs one.
#define SFFD_SPLAT(r) (Lanes{(r), (r), (r), (r)})

  // Bernstein values and derivatives of degree n at s; N is uint32_t or a Degree<n>.
  template <class N>
  static void bernsteinOf(N n, Real s, Real b[kMax], Real db[kMax]) {
    Real t = Real(1) - s;
    for (int i = 0; i < kMax; ++i) b[i] = db[i] = Real(0);
    b[0] = Real(1);
    for (uint32_t k = 1; k <= n; ++k) {
      if (k == n)
        for (uint32_t p = 0; p <= n; ++p) {
          Real lower = p > 0 ? b[p - 1] : Real(0);
          Real upper = p < n ? b[p] : Real(0);
          db[p] = Real(n) * (lower - upper);
        }
      // Raise the degree in place: b[j] <- t*b[j] + s*b[j-1] (b[k] was 0, b[-1] is taken as 0).
      Real prev = Real(0);
      for (uint32_t j = 0; j <= k; ++j) {
        Real cur = b[j];
        b[j] = t * cur + s * prev;
        prev = cur;
      }
    }
  }

  template <class DX, class DY, class DZ>
  LatticeSampleT<Real> evaluateOf(RVec3<Real> x, DX dx, DY dy, DZ dz) const {
    LatticeSampleT<Real> S;
    RVec3<Real> p;
    for (int r = 0; r < 3; ++r) {
      const Real* row = &frame_[SFFD_FRAME_AFFINE + 4 * r];
      Real xy = row[0] * x.x + row[1] * x.y;
      Real xyz = xy + row[2] * x.z;
      p[r] = xyz + row[3];
    }
    uint32_t sp[3];
    Real s[3] = {Real(0), Real(0), Real(0)};   // set per axis below; initialised for GCC's flow analysis
    const uint32_t offs[3] = {L_.break_offset.x, L_.break_offset.y, L_.break_offset.z};
    const uint32_t boxes[3] = {L_.boxes.x, L_.boxes.y, L_.boxes.z};
    for (int a = 0; a < 3; ++a) {
      uint32_t first = offs[a], n = boxes[a];
      Real lo = frame_[first], hi = frame_[first + n];
      if (p[a] < lo || p[a] > hi) S.inside = false;
      sp[a] = span(first, n, p[a]);
      Real k0 = frame_[first + sp[a]], k1 = frame_[first + sp[a] + 1];
      Real h = k1 - k0;
      s[a] = (p[a] - k0) / h;
      S.h[a] = h;
    }
    Real bu[kMax], dbu[kMax], bv[kMax], dbv[kMax], bw[kMax], dbw[kMax];
    bernsteinOf(dx, s[0], bu, dbu);
    bernsteinOf(dy, s[1], bv, dbv);
    bernsteinOf(dz, s[2], bw, dbw);
    uint32_t box = (sp[0] * L_.boxes.y + sp[1]) * L_.boxes.z + sp[2];
    const Real* cp = coeffs_ + 4 * size_t(box) * L_.boxes.w;
    // x, y, z (and the unused w) of each sum in the lanes of one vector: per lane the operations of
    // the scalar form, in its order.
    Lanes R{}, Ru{}, Rv{}, Rw{};
    for (uint32_t i = 0; i <= dx; ++i) {
      Lanes Sp{}, Spv{}, Spw{};
      for (uint32_t j = 0; j <= dy; ++j) {
        Lanes Sq{}, Sqw{};
        for (uint32_t k = 0; k <= dz; ++k, cp += 4) {
          Lanes c;
          std::memcpy(&c, cp, sizeof c);
          Sq = Sq + c * SFFD_SPLAT(bw[k]);
          Sqw = Sqw + c * SFFD_SPLAT(dbw[k]);
        }
        Sp = Sp + Sq * SFFD_SPLAT(bv[j]);
        Spv = Spv + Sq * SFFD_SPLAT(dbv[j]);
        Spw = Spw + Sqw * SFFD_SPLAT(bv[j]);
      }
      R = R + Sp * SFFD_SPLAT(bu[i]);
      Ru = Ru + Sp * SFFD_SPLAT(dbu[i]);
      Rv = Rv + Spv * SFFD_SPLAT(bu[i]);
      Rw = Rw + Spw * SFFD_SPLAT(bu[i]);
    }
    S.value = {R[0], R[1], R[2]};
    S.du = {Ru[0], Ru[1], Ru[2]};
    S.dv = {Rv[0], Rv[1], Rv[2]};
    S.dw = {Rw[0], Rw[1], Rw[2]};
    return S;
  }

#undef SFFD_SPLAT

  gpu::LatticeParams L_;
  const Real* frame_;
  const Real* coeffs_;
};

}  // namespace sffd
