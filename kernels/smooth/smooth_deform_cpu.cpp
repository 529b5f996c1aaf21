// The CPU entries of the deform kernels (deform_smooth and the split deform_step_*): the C++ twin of
// smooth_deform.glsl, one function per step as there, reading the bound ranges (or the lattice and fit
// table inline in the parameter block) as the kernels do.
#include <algorithm>
#include <cmath>
#include <optional>
#include <span>

#include "kernels/common/cpu_kernel.h"
#include "kernels/pn/pn_eval.h"
#include "kernels/smooth/smooth_deform.h"
#include "kernels/smooth/smooth_tessellate_cpu.h"

namespace sffd {
namespace {

template <class Real>
RVec3<Real> nearControlPoint(RVec3<Real> q0, RVec3<Real> q1, RVec3<Real> q2, RVec3<Real> q3) {
  return (((q0 * Real(-5) + q1 * Real(18)) + q2 * Real(-9)) + q3 * Real(2)) / Real(6);
}

// What every deform kernel reads: its parameters, the lattice, the fit table, the sub-triangle inputs.
template <class Real>
struct DeformTwin {
  const gpu::DeformParams& p;
  LatticeEvaluator<Real> L;
  const Real* fit;   // SFFD_FIT_STRIDE per interior fitting point
  const Real* records;
  int fitPoints, level;

  // float variants: the lattice and the fit table from the parameter block where the host put them
  // there (layout.h, DeformParams), else the lattice bindings and the frame range after the frame, as
  // lattice_eval.glsl and fitAt() read them.
  DeformTwin(const CpuKernelArgs& a, uint64_t n)
      : p(a.paramsAs<gpu::DeformParams>()),
        L(boundLattice<Real>(a, p.lattice, p.inline_lattice)),
        fit(tableReals<Real>(a, p.inline_lattice, p.sections.x, p.sections.y, uint64_t(SFFD_FIT_STRIDE) * p.range.z)),
        records(a.array<const Real>(SFFD_BINDING_DEFORM_SUB_RECORDS, 4 * SFFD_SUB_STRIDE * n).data()),
        fitPoints(int(p.range.z)),
        level(int(p.range.w)) {
    a.check(p.range.z <= SFFD_MAX_FIT_POINTS && p.range.w >= 1, "deform: fitting points or tessellation level out of range");
  }

  // The crease slot bits carried in the record (layout.h, SFFD_SUB_CREASE_BITS), as smoothCreaseBits().
  uint32_t creaseBitsOf(size_t st) const { return uint32_t(records[4 * (SFFD_SUB_STRIDE * st + SFFD_SUB_CREASE_BITS) + 3]); }
  RVec3<Real> at(size_t st, int slot) const {
    const Real* r = &records[4 * (SFFD_SUB_STRIDE * st + slot)];
    return {r[0], r[1], r[2]};
  }
  // The lifted corners and their linear normals, read once per sub-triangle (smoothSubCorners).
  struct Corners {
    RVec3<Real> x[3], n[3];
  };
  Corners corners(size_t st) const {
    Corners C;
    for (int c = 0; c < 3; ++c) C.x[c] = at(st, SFFD_SUB_XPN + c), C.n[c] = at(st, SFFD_SUB_NLIN + c);
    return C;
  }
  RVec3<Real> cofN(const LatticeSampleT<Real>& S, RVec3<Real> n) const { return snormalize(L.cofactorNormal(S, n)); }

  // Steps 1, 2 and 4 at the corners (smoothBoundarySamples).
  void cornerSamples(size_t st, const Corners& C, RVec3<Real> Q[3], RVec3<Real> QN[3], RVec3<Real> adj[3],
                     RVec3<Real> adjNbr[6]) const {
    const uint32_t creaseBits = creaseBitsOf(st);
    for (int c = 0; c < 3; ++c) {
      auto S = L.evaluate(C.x[c]);
      Q[c] = S.value;
      QN[c] = cofN(S, C.n[c]);
      adj[c] = cofN(S, at(st, SFFD_SUB_NPN + c));
      for (int h = 0; h < 2; ++h) {
        int s = 2 * c + h;
        adjNbr[s] = ((creaseBits >> s) & 1u) ? cofN(S, at(st, SFFD_SUB_NNBR + s)) : adj[c];
      }
    }
  }

  // Step 2 on the edges (smoothBoundarySamples, smoothEdgePoint): E[2e] a third from corner e, E[2e+1] a third from e+1.
  void edgeSamples(const Corners& C, RVec3<Real> E[6], RVec3<Real> EN[6]) const {
    const Real third = Real(1) / Real(3), twoThirds = Real(2) / Real(3);
    for (int e = 0; e < 3; ++e) {
      int a = e, b = (e + 1) % 3;
      for (int h = 0; h < 2; ++h) {
        Real wa = h == 0 ? twoThirds : third, wb = h == 0 ? third : twoThirds;
        RVec3<Real> x = C.x[a] * wa + C.x[b] * wb;
        RVec3<Real> n = C.n[a] * wa + C.n[b] * wb;
        auto S = L.evaluate(x);
        E[2 * e + h] = S.value;
        EN[2 * e + h] = cofN(S, snormalize(n));
      }
    }
  }

  // Step 1 inside: the deformed normal at interior fitting point i (smoothInteriorNormal).
  RVec3<Real> interiorNormal(const Corners& C, int i) const {
    const Real* f = &fit[SFFD_FIT_STRIDE * i];
    RVec3<Real> x = (C.x[0] * f[0] + C.x[1] * f[1]) + C.x[2] * f[2];
    RVec3<Real> n = (C.n[0] * f[0] + C.n[1] * f[1]) + C.n[2] * f[2];
    return cofN(L.evaluate(x), snormalize(n));
  }

  // Step 3 inside: one interior sample's share of the normal patch's centre (smoothCentreTerm).
  RVec3<Real> centreTerm(const RVec3<Real> ncp[10], RVec3<Real> qn, int i) const {
    const Real* f = &fit[SFFD_FIT_STRIDE * i];
    RVec3<Real> r = qn;
    for (int k = 0; k < 10; ++k)
      if (k != 4) r = r - ncp[k] * f[4 + k];
    return r * f[3];
  }
};

// Step 3: boundary control points by the closed form of the constrained fit (smoothBoundaryControlPoints).
template <class Real>
void boundaryControlPoints(const RVec3<Real> Q[3], const RVec3<Real> QN[3], const RVec3<Real> E[6], const RVec3<Real> EN[6],
                           RVec3<Real> cp[10], RVec3<Real> ncp[10]) {
  for (int c = 0; c < 3; ++c) cp[kCornerControlPoint[c]] = Q[c], ncp[kCornerControlPoint[c]] = QN[c];
  for (int s = 0; s < 6; ++s) {
    int c = s / 2;
    int o = (s % 2 == 1) ? (c + 1) % 3 : (c + 2) % 3;
    int e = (s % 2 == 1) ? c : o;
    int nearC = c == e ? 2 * e : 2 * e + 1, nearO = c == e ? 2 * e + 1 : 2 * e;
    cp[kSlotControlPoint[s]] = nearControlPoint(Q[c], E[nearC], E[nearO], Q[o]);
    ncp[kSlotControlPoint[s]] = nearControlPoint(QN[c], EN[nearC], EN[nearO], QN[o]);
  }
  cp[4] = ncp[4] = RVec3<Real>{};
}

// Step 5: edge control points onto the tangent plane or the crease line; centre by the PN rule (smoothAdjust).
template <class Real>
void adjust(uint32_t creaseBits, const RVec3<Real> adj[3], const RVec3<Real> adjNbr[6], RVec3<Real> cp[10]) {
  for (int s = 0; s < 6; ++s) {
    int c = s / 2;
    RVec3<Real> X = cp[kCornerControlPoint[c]], b = cp[kSlotControlPoint[s]];
    RVec3<Real> d = b - X;
    bool adjusted = false;
    if ((creaseBits >> s) & 1u) {
      RVec3<Real> n1 = adj[c], n2 = adjNbr[s];
      if (lexLess(n2, n1)) std::swap(n1, n2);
      RVec3<Real> cr = scross(n1, n2);
      Real len2 = sdot(cr, cr);
      if (len2 > Real(1e-12)) {
        RVec3<Real> t = cr / Real(std::sqrt(len2));
        b = X + t * sdot(d, t);
        adjusted = true;
      }
    }
    if (!adjusted) b = b - adj[c] * sdot(d, adj[c]);
    cp[kSlotControlPoint[s]] = b;
  }
  RVec3<Real> edgeSum = ((((cp[1] + cp[2]) + cp[3]) + cp[5]) + cp[7]) + cp[8];
  RVec3<Real> cornerSum = (cp[0] + cp[6]) + cp[9];
  cp[4] = edgeSum / Real(4) - cornerSum / Real(6);
}

template <class Real>
void putPatch(Real* o, const RVec3<Real> cp[10], const RVec3<Real> ncp[10]) {
  for (int k = 0; k < 10; ++k) {
    Real* a = o + 4 * k;
    Real* b = o + 4 * (10 + k);
    a[0] = cp[k].x, a[1] = cp[k].y, a[2] = cp[k].z, a[3] = 0;
    b[0] = ncp[k].x, b[1] = ncp[k].y, b[2] = ncp[k].z, b[3] = 0;
  }
}

template <class Real>
RVec3<Real> get(const Real* r) { return {r[0], r[1], r[2]}; }

// The kernels. Each loops over its threads' sub-triangles st = range.x + t, t < range.y.
enum class Step { Fused, Sample, Fit, Adjust, Tessellate };

template <class Real, Step K>
void deformThreads(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  const auto& p = a.paramsAs<gpu::DeformParams>();
  const uint64_t n = uint64_t(p.range.x) + p.range.y;
  const DeformTwin<Real> D(a, n);
  const uint64_t nv = (uint64_t(p.range.w) + 1) * (p.range.w + 2) / 2, sampleStride = SFFD_SAMPLE_FIXED + p.range.z;
  // The output range's sections (layout.h): tessellation from element 0, patches from sections.z, samples from sections.w.
  std::span<Real> patches, tess, samples;
  auto section = [&](uint64_t firstElement, uint64_t elements) {
    return a.array<Real>(SFFD_BINDING_DEFORM_OUT, 4 * (firstElement + elements)).subspan(4 * firstElement, 4 * elements);
  };
  if constexpr (K != Step::Sample) patches = section(p.sections.z, SFFD_PATCH_STRIDE * n);
  if constexpr (K == Step::Fused || K == Step::Tessellate) tess = section(0, 2 * nv * n);
  if constexpr (K != Step::Fused && K != Step::Tessellate) samples = section(p.sections.w, sampleStride * n);
  // Step 6's weights, once for the slice of threads (as the kernel's, per vertex: the same bits).
  std::optional<SmoothTessellation<Real>> tessellation;
  if constexpr (K == Step::Fused || K == Step::Tessellate) tessellation.emplace(D.level);
  RVec3<Real> Q[3], QN[3], adj[3], adjNbr[6], E[6], EN[6], cp[10], ncp[10];
  for (uint64_t t = first; t < std::min<uint64_t>(last, p.range.y); ++t) {
    const size_t st = p.range.x + uint32_t(t);
    Real* patch = K == Step::Sample ? nullptr : &patches[4 * SFFD_PATCH_STRIDE * st];
    Real* smp = samples.empty() ? nullptr : &samples[4 * sampleStride * st];
    auto sample = [&](int i) { return get(smp + 4 * i); };
    if constexpr (K == Step::Fused) {
      const auto C = D.corners(st);
      D.cornerSamples(st, C, Q, QN, adj, adjNbr);
      D.edgeSamples(C, E, EN);
      boundaryControlPoints(Q, QN, E, EN, cp, ncp);
      RVec3<Real> centreN{};
      for (int i = 0; i < D.fitPoints; ++i) centreN = centreN + D.centreTerm(ncp, D.interiorNormal(C, i), i);
      ncp[4] = centreN;
      adjust(D.creaseBitsOf(st), adj, adjNbr, cp);
      putPatch(patch, cp, ncp);
    } else if constexpr (K == Step::Sample) {
      const auto C = D.corners(st);
      D.cornerSamples(st, C, Q, QN, adj, adjNbr);
      D.edgeSamples(C, E, EN);
      auto put = [&](int i, RVec3<Real> v) { Real* o = smp + 4 * i; o[0] = v.x, o[1] = v.y, o[2] = v.z, o[3] = 0; };
      for (int c = 0; c < 3; ++c) put(c, Q[c]), put(3 + c, QN[c]), put(18 + c, adj[c]);
      for (int e = 0; e < 6; ++e) put(6 + e, E[e]), put(12 + e, EN[e]), put(21 + e, adjNbr[e]);
      for (int i = 0; i < D.fitPoints; ++i) put(SFFD_SAMPLE_FIXED + i, D.interiorNormal(C, i));
    } else if constexpr (K == Step::Fit) {
      for (int c = 0; c < 3; ++c) Q[c] = sample(c), QN[c] = sample(3 + c);
      for (int e = 0; e < 6; ++e) E[e] = sample(6 + e), EN[e] = sample(12 + e);
      boundaryControlPoints(Q, QN, E, EN, cp, ncp);
      RVec3<Real> centreN{};
      for (int i = 0; i < D.fitPoints; ++i) centreN = centreN + D.centreTerm(ncp, sample(SFFD_SAMPLE_FIXED + i), i);
      ncp[4] = centreN;
      putPatch(patch, cp, ncp);
    } else if constexpr (K == Step::Adjust) {
      for (int c = 0; c < 3; ++c) adj[c] = sample(18 + c);
      for (int e = 0; e < 6; ++e) adjNbr[e] = sample(21 + e);
      for (int k = 0; k < 10; ++k) cp[k] = get(patch + 4 * k), ncp[k] = get(patch + 4 * (10 + k));
      adjust(D.creaseBitsOf(st), adj, adjNbr, cp);
      putPatch(patch, cp, ncp);
    } else {
      for (int k = 0; k < 10; ++k) cp[k] = get(patch + 4 * k), ncp[k] = get(patch + 4 * (10 + k));
    }
    if constexpr (K == Step::Fused || K == Step::Tessellate) tessellation->run(cp, ncp, &tess[8 * nv * st]);
  }
}

// The fused kernel also as compiled for AVX2 (withAvx2), in float and double; the split steps (per-step
// timings) as they are: each copy costs seconds of every build.
template <Step K>
void deformEntry(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  if constexpr (K == Step::Fused)
    a.variant.f64 ? withAvx2<deformThreads<double, K>>(a, first, last) : withAvx2<deformThreads<float, K>>(a, first, last);
  else
    a.variant.f64 ? deformThreads<double, K>(a, first, last) : deformThreads<float, K>(a, first, last);
}

}  // namespace

void cpu::deformSmooth(const CpuKernelArgs& a, uint64_t first, uint64_t last) { deformEntry<Step::Fused>(a, first, last); }
void cpu::deformStepSample(const CpuKernelArgs& a, uint64_t first, uint64_t last) { deformEntry<Step::Sample>(a, first, last); }
void cpu::deformStepFit(const CpuKernelArgs& a, uint64_t first, uint64_t last) { deformEntry<Step::Fit>(a, first, last); }
void cpu::deformStepAdjust(const CpuKernelArgs& a, uint64_t first, uint64_t last) { deformEntry<Step::Adjust>(a, first, last); }
void cpu::deformStepTessellate(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  deformEntry<Step::Tessellate>(a, first, last);
}

}  // namespace sffd
