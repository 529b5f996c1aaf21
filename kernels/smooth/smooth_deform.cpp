#include "kernels/smooth/smooth_deform.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <thread>

#include <sffd/error.h>
#include "kernels/common/lattice_eval.h"
#include "kernels/pn/pn_eval.h"
#include "kernels/common/shader_layout.h"
#include "core/wall_clock.h"

namespace sffd {

FitTable makeFitTable(int s) {
  if (s < 3 || s > 15) throw Error(ErrorKind::Input, "the sampling density s must be in 3..15");
  FitTable F;
  F.s = s;
  std::vector<std::array<double, 3>> pts;
  for (int i = s; i >= 0; --i)
    for (int j = s - i; j >= 0; --j) {
      int k = s - i - j;
      if (i > 0 && j > 0 && k > 0) pts.push_back({double(i) / s, double(j) / s, double(k) / s});
    }
  double norm = 0;
  for (auto& p : pts) norm += std::pow(6 * p[0] * p[1] * p[2], 2);
  for (auto& p : pts) {
    double w[10];
    pnCubicWeights(RVec3<double>{p[0], p[1], p[2]}, w);
    F.data.insert(F.data.end(), {p[0], p[1], p[2], 6 * p[0] * p[1] * p[2] / norm});
    F.data.insert(F.data.end(), w, w + 10);
  }
  F.points = int(pts.size());
  return F;
}

namespace {

constexpr int kCornerCp[3] = {0, 6, 9};

template <class Real>
bool lexLess(RVec3<Real> a, RVec3<Real> b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

template <class Real>
RVec3<Real> nearControlPoint(RVec3<Real> q0, RVec3<Real> q1, RVec3<Real> q2, RVec3<Real> q3) {
  return (((q0 * Real(-5) + q1 * Real(18)) + q2 * Real(-9)) + q3 * Real(2)) / Real(6);
}

// The twin of deform_smooth.comp's main() for one sub-triangle.
template <class Real>
void deformOne(const LatticeEvaluator<Real>& L, const std::vector<Real>& fit, int fitPoints, const uint32_t* header,
               const Real* rec, int level, Real* patchOut, Real* tessOut) {
  auto at = [&](int slot) { return RVec3<Real>{rec[4 * slot], rec[4 * slot + 1], rec[4 * slot + 2]}; };
  auto cofN = [&](const LatticeSampleT<Real>& S, RVec3<Real> n) { return snormalize(L.cofactorNormal(S, n)); };
  uint32_t creaseBits = header[1];
  RVec3<Real> xpn[3], nlin[3];
  for (int c = 0; c < 3; ++c) xpn[c] = at(SFFD_SUB_XPN + c), nlin[c] = at(SFFD_SUB_NLIN + c);
  Real third = Real(1) / Real(3), twoThirds = Real(2) / Real(3);

  RVec3<Real> Q[3], QN[3], adj[3], adjNbr[6];
  for (int c = 0; c < 3; ++c) {
    auto S = L.evaluate(xpn[c]);
    Q[c] = S.value;
    QN[c] = cofN(S, nlin[c]);
    adj[c] = cofN(S, at(SFFD_SUB_NPN + c));
    for (int h = 0; h < 2; ++h) {
      int s = 2 * c + h;
      adjNbr[s] = ((creaseBits >> s) & 1u) ? cofN(S, at(SFFD_SUB_NNBR + s)) : adj[c];
    }
  }
  RVec3<Real> E[6], EN[6];
  for (int e = 0; e < 3; ++e) {
    int a = e, b = (e + 1) % 3;
    for (int h = 0; h < 2; ++h) {
      Real wa = h == 0 ? twoThirds : third, wb = h == 0 ? third : twoThirds;
      RVec3<Real> x = xpn[a] * wa + xpn[b] * wb;
      RVec3<Real> n = nlin[a] * wa + nlin[b] * wb;
      auto S = L.evaluate(x);
      E[2 * e + h] = S.value;
      EN[2 * e + h] = cofN(S, snormalize(n));
    }
  }
  RVec3<Real> cp[10], ncp[10];
  for (int c = 0; c < 3; ++c) cp[kCornerCp[c]] = Q[c], ncp[kCornerCp[c]] = QN[c];
  for (int s = 0; s < 6; ++s) {
    int c = s / 2;
    int o = (s % 2 == 1) ? (c + 1) % 3 : (c + 2) % 3;
    int e = (s % 2 == 1) ? c : o;
    int nearC = c == e ? 2 * e : 2 * e + 1, nearO = c == e ? 2 * e + 1 : 2 * e;
    cp[kSlotControlPoint[s]] = nearControlPoint(Q[c], E[nearC], E[nearO], Q[o]);
    ncp[kSlotControlPoint[s]] = nearControlPoint(QN[c], EN[nearC], EN[nearO], QN[o]);
  }
  RVec3<Real> centreN{};
  for (int i = 0; i < fitPoints; ++i) {
    const Real* f = &fit[SFFD_FIT_STRIDE * i];
    RVec3<Real> lam{f[0], f[1], f[2]};
    RVec3<Real> x = (xpn[0] * lam.x + xpn[1] * lam.y) + xpn[2] * lam.z;
    RVec3<Real> n = (nlin[0] * lam.x + nlin[1] * lam.y) + nlin[2] * lam.z;
    auto S = L.evaluate(x);
    RVec3<Real> r = cofN(S, snormalize(n));
    for (int k = 0; k < 10; ++k)
      if (k != 4) r = r - ncp[k] * f[4 + k];
    centreN = centreN + r * f[3];
  }
  ncp[4] = centreN;

  for (int s = 0; s < 6; ++s) {
    int c = s / 2;
    RVec3<Real> X = Q[c], b = cp[kSlotControlPoint[s]];
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

  auto put = [](Real* o, RVec3<Real> v) { o[0] = v.x, o[1] = v.y, o[2] = v.z, o[3] = 0; };
  for (int k = 0; k < 10; ++k) put(patchOut + 4 * k, cp[k]), put(patchOut + 4 * (10 + k), ncp[k]);

  const int Lv = level, nv = (Lv + 1) * (Lv + 2) / 2;
  for (int r = 0; r <= Lv; ++r)
    for (int t = 0; t <= r; ++t) {
      int i = Lv - r, j = r - t, k = t;
      int v = r * (r + 1) / 2 + t;
      RVec3<Real> x, n;
      if (i == Lv || j == Lv || k == Lv) {
        int c = i == Lv ? 0 : (j == Lv ? 1 : 2);
        x = cp[kCornerCp[c]];
        n = snormalize(ncp[kCornerCp[c]]);
      } else if (i == 0 || j == 0 || k == 0) {
        int a = k == 0 ? 0 : (i == 0 ? 1 : 2), b = (a + 1) % 3;
        int stepsFromA = a == 0 ? j : (a == 1 ? k : i);
        int sa = 2 * a + 1, sb = 2 * b;
        int lo = a, hi = b, steps = stepsFromA, slo = sa, shi = sb;
        if (lexLess(cp[kCornerCp[b]], cp[kCornerCp[a]])) lo = b, hi = a, steps = Lv - stepsFromA, slo = sb, shi = sa;
        Real u = Real(steps) / Real(Lv);
        x = pnEdgeCurve(cp[kCornerCp[lo]], cp[kSlotControlPoint[slo]], cp[kSlotControlPoint[shi]], cp[kCornerCp[hi]], u);
        n = snormalize(pnEdgeCurve(ncp[kCornerCp[lo]], ncp[kSlotControlPoint[slo]], ncp[kSlotControlPoint[shi]], ncp[kCornerCp[hi]], u));
      } else {
        RVec3<Real> lam = RVec3<Real>{Real(i), Real(j), Real(k)} / Real(Lv);
        Real w[10];
        pnCubicWeights(lam, w);
        RVec3<Real> xs{}, ns{};
        for (int q = 0; q < 10; ++q) xs = xs + cp[q] * w[q], ns = ns + ncp[q] * w[q];
        x = xs;
        n = snormalize(ns);
      }
      put(tessOut + 4 * v, x);
      put(tessOut + 4 * (nv + v), n);
    }
}

// The CPU reference runs the sub-triangles on every core (SFFD_CPU_THREADS caps the count): each
// sub-triangle is independent and writes its own output range, so the result does not depend on the
// number of threads.
unsigned cpuThreads(size_t work) { return unsigned(std::min<size_t>(cpuThreadCount(), std::max<size_t>(1, work / 64))); }

template <class Real>
void deformCpu(const PackedLattice& P, const SubTriangleRecords& subs, const FitTable& F, int level, SmoothOutput& out) {
  std::vector<Real> frame = convertReals<Real>(P.frame), coeffs = convertReals<Real>(P.coeffs);
  std::vector<Real> fit = convertReals<Real>(F.data), recs = convertReals<Real>(subs.records);
  LatticeEvaluator<Real> L(P.params, frame, coeffs);
  const size_t n = subs.size(), nv = size_t(tessVertexCount(level));
  out.patches.resize(n * SFFD_PATCH_STRIDE * 4);
  out.tess.resize(n * 2 * nv * 4);
  auto range = [&](size_t first, size_t last) {
    std::vector<Real> patch(SFFD_PATCH_STRIDE * 4), tess(2 * nv * 4);
    for (size_t s = first; s < last; ++s) {
      deformOne<Real>(L, fit, F.points, &subs.headers[4 * s], &recs[s * SFFD_SUB_STRIDE * 4], level, patch.data(), tess.data());
      std::copy(patch.begin(), patch.end(), out.patches.begin() + s * patch.size());
      std::copy(tess.begin(), tess.end(), out.tess.begin() + s * tess.size());
    }
  };
  const unsigned threads = cpuThreads(n);
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(range, n * t / threads, n * (t + 1) / threads);
  range(0, n / threads);
  for (std::thread& t : pool) t.join();
}

template <class Real>
void deformGpu(Backend& backend, const PackedLattice& P, const SubTriangleRecords& subs, const FitTable& F, int level,
               KernelVariant variant, bool split, size_t maxChunk, SmoothOutput& out) {
  const DeviceLimits& lim = backend.info().limits;
  const size_t n = subs.size(), nv = size_t(tessVertexCount(level));
  const size_t recReals = SFFD_SUB_STRIDE * 4, patchReals = SFFD_PATCH_STRIDE * 4, tessReals = 2 * nv * 4;
  const size_t sampleReals = (SFFD_SAMPLE_FIXED + size_t(F.points)) * 4;
  // Chunks of sub-triangles whose every per-sub-triangle buffer fits one binding.
  size_t chunk = size_t(lim.maxStorageBufferRange / (std::max({recReals, patchReals, tessReals, sampleReals}) * sizeof(Real)));
  chunk = std::min<size_t>(chunk, size_t(lim.maxWorkGroupCount[0]) * lim.maxWorkGroupCount[1] * SFFD_LOCAL_SIZE);
  if (maxChunk) chunk = std::min(chunk, maxChunk);
  chunk = std::max<size_t>(1, std::min(chunk, std::max<size_t>(n, 1)));
  std::vector<Real> frame = convertReals<Real>(P.frame), coeffs = convertReals<Real>(P.coeffs), fit = convertReals<Real>(F.data);
  auto make = [&](const void* data, size_t bytes) {
    BufferId b = backend.createBuffer(std::max<size_t>(bytes, 16));
    if (data && bytes) backend.upload(b, 0, data, bytes);
    return b;
  };
  BufferId bFrame = make(frame.data(), frame.size() * sizeof(Real)), bCoeffs = make(coeffs.data(), coeffs.size() * sizeof(Real));
  BufferId bFit = make(fit.data(), fit.size() * sizeof(Real));
  BufferId bHdr = make(nullptr, chunk * 16), bRec = make(nullptr, chunk * recReals * sizeof(Real));
  BufferId bPatch = make(nullptr, chunk * patchReals * sizeof(Real)), bTess = make(nullptr, chunk * tessReals * sizeof(Real));
  BufferId bSamples = split ? make(nullptr, chunk * sampleReals * sizeof(Real)) : 0;
  out.patches.resize(n * patchReals);
  out.tess.resize(n * tessReals);
  std::vector<Real> rec(chunk * recReals), buf(chunk * std::max(patchReals, tessReals));
  gpu::DeformParams params = deformParamsFor(P, variant.f64, &F.data);
  for (size_t first = 0; first < n; first += chunk) {
    size_t count = std::min(chunk, n - first);
    std::transform(subs.records.begin() + first * recReals, subs.records.begin() + (first + count) * recReals, rec.begin(),
                   [](double v) { return Real(v); });
    backend.upload(bHdr, 0, &subs.headers[4 * first], count * 16);
    backend.upload(bRec, 0, rec.data(), count * recReals * sizeof(Real));
    params.range = {0, uint32_t(count), uint32_t(F.points), uint32_t(level)};
    dispatchDeform(backend, params, {bCoeffs, bFrame, bFit, bHdr, bRec, bPatch, bTess, bSamples}, count, variant, split);
    backend.download(bPatch, 0, buf.data(), count * patchReals * sizeof(Real));
    std::copy(buf.begin(), buf.begin() + count * patchReals, out.patches.begin() + first * patchReals);
    backend.download(bTess, 0, buf.data(), count * tessReals * sizeof(Real));
    std::copy(buf.begin(), buf.begin() + count * tessReals, out.tess.begin() + first * tessReals);
  }
  backend.finish();
  for (BufferId b : {bFrame, bCoeffs, bFit, bHdr, bRec, bPatch, bTess}) backend.destroyBuffer(b);
  if (split) backend.destroyBuffer(bSamples);
  out.timings = backend.takeTimings();
}

}  // namespace

unsigned cpuThreadCount() {
  unsigned t = std::max(1u, std::thread::hardware_concurrency());
  if (const char* env = std::getenv("SFFD_CPU_THREADS")) t = std::max(1u, unsigned(std::strtoul(env, nullptr, 10)));
  return std::min(t, 256u);
}

SmoothOutput smoothDeformCpu(const PackedLattice& lattice, const SubTriangleRecords& subs, const FitTable& fit, int level,
                             KernelVariant variant) {
  SmoothOutput out;
  out.level = level;
  auto t0 = std::chrono::steady_clock::now();
  if (variant.f64) deformCpu<double>(lattice, subs, fit, level, out);
  else deformCpu<float>(lattice, subs, fit, level, out);
  out.wallMs = msSince(t0);
  out.timings.push_back({"deform", out.wallMs});
  return out;
}

SmoothOutput smoothDeformGpu(Backend& backend, const PackedLattice& lattice, const SubTriangleRecords& subs,
                             const FitTable& fit, int level, KernelVariant variant, bool split, size_t maxChunk) {
  if (variant.f64 && !backend.info().limits.float64)
    throw deviceError(backend.info().name + " has no double-precision shader support; use --precision float");
  SmoothOutput out;
  out.level = level;
  auto t0 = std::chrono::steady_clock::now();
  if (subs.size()) {
    if (variant.f64) deformGpu<double>(backend, lattice, subs, fit, level, variant, split, maxChunk, out);
    else deformGpu<float>(backend, lattice, subs, fit, level, variant, split, maxChunk, out);
  }
  out.wallMs = msSince(t0);
  return out;
}

void dispatchDeform(Backend& backend, const gpu::DeformParams& params, const DeformBuffers& b, size_t count,
                    KernelVariant variant, bool split) {
  std::vector<BufferBinding> buffers = {
      {SFFD_BINDING_LATTICE_COEFFS, b.coeffs}, {SFFD_BINDING_LATTICE_FRAME, b.frame}, {SFFD_BINDING_DEFORM_FIT, b.fit},
      {SFFD_BINDING_DEFORM_SUB_HEADERS, b.headers}, {SFFD_BINDING_DEFORM_SUB_RECORDS, b.records},
      {SFFD_BINDING_DEFORM_PATCHES, b.patches}, {SFFD_BINDING_DEFORM_TESS, b.tess}};
  if (split) buffers.push_back({SFFD_BINDING_DEFORM_SAMPLES, b.samples});
  auto dispatch = [&](const char* kernel, const char* label) {
    Dispatch d;
    d.kernel = kernel;
    d.label = label;
    d.variant = variant;
    d.params = &params;
    d.paramsSize = sizeof(params);
    d.buffers = buffers;
    gridFor(count, backend.info().limits, d.groups);
    backend.dispatch(d);
    backend.barrier();
  };
  if (split) {
    dispatch("deform_step_sample", "deform.sample");
    dispatch("deform_step_fit", "deform.fit");
    dispatch("deform_step_adjust", "deform.adjust");
    dispatch("deform_step_tessellate", "deform.tessellate");
  } else {
    dispatch("deform_smooth", "deform");
  }
}

PatchVertices patchVerticesOf(const SubTriangleRecords& subs, const SmoothOutput& out) {
  PatchVertices P;
  P.level = out.level;
  const int L = out.level, nv = tessVertexCount(L);
  const size_t n = subs.size();
  P.parent.resize(n);
  P.lamParent.resize(n * nv * 3);
  P.position.resize(n * nv * 3);
  P.normal.resize(n * nv * 3);
  for (size_t s = 0; s < n; ++s) {
    P.parent[s] = subs.headers[4 * s];
    glm::dvec3 lam[3];
    for (int c = 0; c < 3; ++c) {
      const double* l = &subs.records[(s * SFFD_SUB_STRIDE + SFFD_SUB_LAM + c) * 4];
      lam[c] = {l[0], l[1], l[2]};
    }
    const double* t = &out.tess[s * 2 * nv * 4];
    for (int r = 0; r <= L; ++r)
      for (int c = 0; c <= r; ++c) {
        int v = r * (r + 1) / 2 + c;
        glm::dvec3 w(double(L - r) / L, double(r - c) / L, double(c) / L);
        glm::dvec3 lp = w.x * lam[0] + w.y * lam[1] + w.z * lam[2];
        size_t g = s * nv + v;
        for (int a = 0; a < 3; ++a) {
          P.lamParent[3 * g + a] = lp[a];
          P.position[3 * g + a] = t[4 * v + a];
          P.normal[3 * g + a] = t[4 * (nv + v) + a];
        }
      }
  }
  return P;
}

}  // namespace sffd
