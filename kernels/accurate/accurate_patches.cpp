#include "kernels/accurate/accurate_patches.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <mutex>

#include <sffd/error.h>
#include "core/job_budget.h"
#include "model/lattice_pack.h"
#include "core/kernel_registry.h"
#include "core/wall_clock.h"

namespace sffd {

void triangleMultiIndex(int n, int idx, int& i, int& j, int& k) {
  int r = 0;
  while ((r + 1) * (r + 2) / 2 <= idx) ++r;
  int t = idx - r * (r + 1) / 2;
  i = n - r;
  j = r - t;
  k = t;
}

namespace {

long double factorialL(int n) {
  long double f = 1;
  for (int i = 2; i <= n; ++i) f *= i;
  return f;
}

long double powL(long double x, int e) {
  long double r = 1;
  for (int i = 0; i < e; ++i) r *= x;
  return r;
}

// B^n_{ijk} at the barycentrics (a, b, c) / d, in long double.
long double bernsteinAtLattice(int n, int i, int j, int k, int a, int b, int c, int d) {
  long double coef = factorialL(n) / (factorialL(i) * factorialL(j) * factorialL(k));
  return coef * powL((long double)a / d, i) * powL((long double)b / d, j) * powL((long double)c / d, k);
}

std::vector<long double> interpolationMatrixL(int n) {
  const int m = triangleControlPoints(n);
  std::vector<long double> A(size_t(m) * m);
  for (int l = 0; l < m; ++l) {
    int a, b, c;
    triangleMultiIndex(n, l, a, b, c);
    for (int k = 0; k < m; ++k) {
      int i, j, kk;
      triangleMultiIndex(n, k, i, j, kk);
      A[size_t(l) * m + k] = bernsteinAtLattice(n, i, j, kk, a, b, c, n);
    }
  }
  return A;
}

// Gauss-Jordan elimination with partial pivoting, in long double.
std::vector<double> invert(std::vector<long double> A, int m) {
  std::vector<long double> X(size_t(m) * m, 0.0L);
  for (int i = 0; i < m; ++i) X[size_t(i) * m + i] = 1;
  for (int col = 0; col < m; ++col) {
    int piv = col;
    for (int r = col + 1; r < m; ++r)
      if (std::fabs(A[size_t(r) * m + col]) > std::fabs(A[size_t(piv) * m + col])) piv = r;
    if (A[size_t(piv) * m + col] == 0) throw Error(ErrorKind::Internal, "interpolation matrix is singular");
    if (piv != col)
      for (int c = 0; c < m; ++c) {
        std::swap(A[size_t(piv) * m + c], A[size_t(col) * m + c]);
        std::swap(X[size_t(piv) * m + c], X[size_t(col) * m + c]);
      }
    long double inv = 1 / A[size_t(col) * m + col];
    for (int c = 0; c < m; ++c) {
      A[size_t(col) * m + c] *= inv;
      X[size_t(col) * m + c] *= inv;
    }
    for (int r = 0; r < m; ++r) {
      if (r == col) continue;
      long double f = A[size_t(r) * m + col];
      if (f == 0) continue;
      for (int c = 0; c < m; ++c) {
        A[size_t(r) * m + c] -= f * A[size_t(col) * m + c];
        X[size_t(r) * m + c] -= f * X[size_t(col) * m + c];
      }
    }
  }
  return std::vector<double>(X.begin(), X.end());
}

}  // namespace

double triangleBernstein(int n, int i, int j, int k, const glm::dvec3& lambda) {
  double coef = double(factorialL(n) / (factorialL(i) * factorialL(j) * factorialL(k)));
  return coef * std::pow(lambda.x, i) * std::pow(lambda.y, j) * std::pow(lambda.z, k);
}

std::vector<double> interpolationMatrix(int n) {
  std::vector<long double> A = interpolationMatrixL(n);
  return std::vector<double>(A.begin(), A.end());
}

const std::vector<double>& interpolationInverse(int n) {
  if (n < 1 || n > SFFD_ACC_MAX_DEGREE)
    throw Error(ErrorKind::Input, "accurate FFD: patch degree " + std::to_string(n) + " is outside 1.." +
                                      std::to_string(SFFD_ACC_MAX_DEGREE));
  static std::array<std::vector<double>, SFFD_ACC_MAX_DEGREE + 1> cache;
  static std::array<std::once_flag, SFFD_ACC_MAX_DEGREE + 1> once;
  std::call_once(once[n], [n] { cache[n] = invert(interpolationMatrixL(n), triangleControlPoints(n)); });
  return cache[n];
}

std::vector<double> tessellationBasis(int n, int L) {
  const int m = triangleControlPoints(n);
  std::vector<double> B;
  B.reserve(size_t(tessVertexCount(L)) * m);
  for (int r = 0; r <= L; ++r)
    for (int q = 0; q <= r; ++q)
      for (int kappa = 0; kappa < m; ++kappa) {
        int i, j, k;
        triangleMultiIndex(n, kappa, i, j, k);
        B.push_back(double(bernsteinAtLattice(n, i, j, k, L - r, r - q, q, L)));
      }
  return B;
}

AccurateJob makeAccurateJob(const Mesh& mesh, const Lattice& lattice, std::vector<SubTriangle> subs, int level) {
  AccurateJob job;
  job.degree = lattice.degree[0] + lattice.degree[1] + lattice.degree[2];
  if (job.degree > SFFD_ACC_MAX_DEGREE)
    throw Error(ErrorKind::Input, "accurate FFD: patch degree " + std::to_string(job.degree) + " exceeds " +
                                      std::to_string(SFFD_ACC_MAX_DEGREE));
  if (level < 1 || level > kMaxTessLevel)
    throw Error(ErrorKind::Input, "the tessellation level must be 1.." + std::to_string(kMaxTessLevel) + ", not " + std::to_string(level));
  job.level = level;
  job.subs = std::move(subs);
  constexpr int stride = 4 * SFFD_ACC_CORNER_STRIDE;
  job.corners.resize(job.subs.size() * stride);
  for (size_t s = 0; s < job.subs.size(); ++s) {
    const SubTriangle& T = job.subs[s];
    const auto& tri = mesh.triangles[T.parent];
    glm::dvec3 nf = glm::cross(mesh.positions[tri[1]] - mesh.positions[tri[0]], mesh.positions[tri[2]] - mesh.positions[tri[0]]);
    double len = glm::length(nf);
    nf = len > 0 ? nf / len : glm::dvec3(0, 0, 1);
    double* o = &job.corners[stride * s + 12];
    o[0] = nf.x, o[1] = nf.y, o[2] = nf.z, o[3] = 0;
    for (int c = 0; c < 3; ++c) {
      const glm::dvec3& l = T.corners[c].lam;
      // On a parent edge one weight is 0 and the sum is the same bits from both triangles of the edge
      // (addition commutes); + 0.0 turns a -0 into +0 so that no coordinate differs only in its sign.
      glm::dvec3 x = (l.x * mesh.positions[tri[0]] + l.y * mesh.positions[tri[1]]) + l.z * mesh.positions[tri[2]];
      double* o = &job.corners[stride * s + 4 * c];
      o[0] = x.x + 0.0, o[1] = x.y + 0.0, o[2] = x.z + 0.0, o[3] = 0;
    }
  }
  return job;
}

namespace {

template <class Real>
void accurateRun(Backend& backend, const AccurateJob& job, const PackedLattice& P, KernelVariant variant, size_t maxChunk,
                 AccurateOutput& out) {
  const DeviceLimits& lim = backend.info().limits;
  const uint32_t m = uint32_t(triangleControlPoints(job.degree));
  const uint32_t nv = uint32_t(tessVertexCount(job.level));
  const size_t ns = job.count();
  const size_t r4 = 4 * sizeof(Real);
  const size_t chunk = accurateChunkPatches(lim, job, sizeof(Real), maxChunk);

  const AccurateFrame F = accurateFrame(P.frame, job.degree, job.level);
  std::vector<Real> frame = convertReals<Real>(F.reals), coeffs = convertReals<Real>(P.coeffs);
  for (const auto* v : {&coeffs, &frame})
    if (v->size() * sizeof(Real) > lim.maxStorageBufferRange)
      throw Error(ErrorKind::Input, "accurate FFD: a lattice or patch table does not fit one storage binding on this device");
  auto upload = [&](const std::vector<Real>& v) {
    BufferId b = backend.createBuffer(std::max<size_t>(v.size(), 1) * sizeof(Real));
    if (!v.empty()) backend.upload(b, 0, v.data(), v.size() * sizeof(Real));
    return b;
  };
  BufferId bFrame = upload(frame), bCoeffs = upload(coeffs);
  const gpu::AccurateParams params = accurateParamsFor(P, variant.f64, F);
  // The chunk range: positions, normals from element chunk * nv, corners from 2 * chunk * nv; the
  // scratch range: samples, control points from element chunk * m.
  const uint32_t normalsAt = uint32_t(chunk * nv), cornersAt = 2 * normalsAt, patchesAt = uint32_t(chunk * m);
  BufferId bChunk = backend.createBuffer((2 * chunk * nv + chunk * SFFD_ACC_CORNER_STRIDE) * r4);
  BufferId bScratch = backend.createBuffer(2 * chunk * m * r4);

  out.controlPoints.resize(ns * m * 4);
  out.positions.resize(ns * nv * 4);
  out.normals.resize(ns * nv * 4);
  std::vector<Real> corners(chunk * 4 * SFFD_ACC_CORNER_STRIDE), cps(chunk * m * 4), pos(chunk * nv * 4), nrm(chunk * nv * 4);
  for (size_t first = 0; first < ns; first += chunk) {
    const size_t count = std::min(chunk, ns - first);
    const size_t cw = 4 * SFFD_ACC_CORNER_STRIDE;
    for (size_t i = 0; i < cw * count; ++i) corners[i] = Real(job.corners[cw * first + i]);
    backend.upload(bChunk, cornersAt * r4, corners.data(), count * SFFD_ACC_CORNER_STRIDE * r4);
    dispatchAccurateChunk(backend, params, variant, job, count,
                          {{SFFD_BINDING_LATTICE_COEFFS, bCoeffs}, {SFFD_BINDING_LATTICE_FRAME, bFrame},
                           {SFFD_BINDING_ACC_CHUNK, bChunk}, {SFFD_BINDING_ACC_SCRATCH, bScratch},
                           normalsAt, cornersAt, patchesAt});
    backend.download(bScratch, patchesAt * r4, cps.data(), count * m * r4);
    backend.download(bChunk, 0, pos.data(), count * nv * r4);
    backend.download(bChunk, normalsAt * r4, nrm.data(), count * nv * r4);
    std::copy(cps.begin(), cps.begin() + count * m * 4, out.controlPoints.begin() + first * m * 4);
    std::copy(pos.begin(), pos.begin() + count * nv * 4, out.positions.begin() + first * nv * 4);
    std::copy(nrm.begin(), nrm.begin() + count * nv * 4, out.normals.begin() + first * nv * 4);
  }
  backend.finish();
  for (BufferId b : {bFrame, bCoeffs, bChunk, bScratch}) backend.destroyBuffer(b);
  out.timings = backend.takeTimings();
}

}  // namespace

std::vector<double> accurateKernelMatrix(int n) {
  const std::vector<double>& inv = interpolationInverse(n);
  const int m = triangleControlPoints(n);
  std::vector<double> t(size_t(m) * m);
  for (int k = 0; k < m; ++k)
    for (int l = 0; l < m; ++l) t[size_t(l) * m + k] = inv[size_t(k) * m + l];
  return t;
}

AccurateFrame accurateFrame(const std::vector<double>& latticeFrame, int degree, int level) {
  AccurateFrame f;
  f.reals = latticeFrame;
  f.matrixAt = uint32_t(f.reals.size());
  const std::vector<double> matrix = accurateKernelMatrix(degree), basis = tessellationBasis(degree, level);
  f.reals.insert(f.reals.end(), matrix.begin(), matrix.end());
  f.basisAt = uint32_t(f.reals.size());
  f.reals.insert(f.reals.end(), basis.begin(), basis.end());
  return f;
}

size_t accurateChunkPatches(const DeviceLimits& lim, const AccurateJob& job, size_t realBytes, size_t maxChunk) {
  const size_t m = size_t(triangleControlPoints(job.degree)), nv = size_t(tessVertexCount(job.level));
  const size_t r4 = 4 * realBytes;
  // The larger per-sub-triangle binding decides the chunk: the chunk range (positions, normals at an
  // aligned offset, corners at another) or the scratch range (samples, control points).
  const size_t perSub = std::max<size_t>(2 * nv + SFFD_ACC_CORNER_STRIDE, 2 * m) * r4;
  const uint64_t slack = std::min(lim.maxStorageBufferRange, 2 * lim.storageOffsetAlignment);
  size_t chunk = size_t((lim.maxStorageBufferRange - slack) / perSub);
  chunk = std::min<size_t>(chunk, size_t(lim.maxWorkGroupCount[0]) * lim.maxWorkGroupCount[1] * SFFD_LOCAL_SIZE / std::max(m, nv));
  chunk = std::min<size_t>(chunk, size_t(UINT32_MAX) / std::max(m, nv));   // thread indices are 32-bit
  if (maxChunk) chunk = std::min(chunk, maxChunk);
  return std::max<size_t>(1, std::min(chunk, std::max<size_t>(job.count(), 1)));
}

gpu::AccurateParams accurateParamsFor(const PackedLattice& lattice, bool f64, const AccurateFrame& frame) {
  gpu::AccurateParams p{};
  const uint32_t next = inlineLattice(lattice, f64, p.lattice, p.inline_lattice);
  const size_t matrixReals = frame.basisAt - frame.matrixAt, basisReals = frame.reals.size() - frame.basisAt;
  // Each table where it fits: A_n^{-1} (196 vec4 at n = 6) first, then the basis (462 at n = 6, level 10).
  const uint32_t matrixAt = inlineReals(&frame.reals[frame.matrixAt], matrixReals, next, p.inline_lattice);
  const uint32_t basisAt = inlineReals(&frame.reals[frame.basisAt], basisReals,
                                       matrixAt ? uint32_t(matrixAt + (matrixReals + 3) / 4) : next, p.inline_lattice);
  p.tables = {frame.matrixAt, frame.basisAt, matrixAt, basisAt};
  return p;
}

KernelUse accurateKernel(const gpu::AccurateParams& params, KernelVariant variant) {
  return {"accurate_patches", forLattice(variant, params)};
}

void dispatchAccurateChunk(Backend& backend, const gpu::AccurateParams& base, KernelVariant variant, const AccurateJob& job,
                           size_t count, const AccurateBindings& bindings) {
  const uint32_t n = uint32_t(job.degree), m = uint32_t(triangleControlPoints(job.degree));
  const uint32_t nv = uint32_t(tessVertexCount(job.level));
  // Samples, then control points, then the tessellation: three dispatches, a barrier between each.
  for (uint32_t stage : {SFFD_ACC_STAGE_SAMPLES, SFFD_ACC_STAGE_PATCHES, SFFD_ACC_STAGE_TESSELLATE}) {
    gpu::AccurateParams params = base;
    params.range = {0, uint32_t(count), stage, 0};
    params.shape = {n, m, uint32_t(job.level), nv};
    params.sections = {bindings.normalsAt, bindings.cornersAt, bindings.patchesAt, 0};
    Dispatch d;
    const KernelUse k = accurateKernel(base, variant);
    d.kernel = k.kernel;
    d.variant = k.variant;
    d.params = &params;
    d.paramsSize = sizeof(params);
    d.label = stage == SFFD_ACC_STAGE_SAMPLES ? "accurate_samples" : stage == SFFD_ACC_STAGE_PATCHES ? "accurate_patches" : "accurate_tessellate";
    d.buffers = {bindings.coeffs, bindings.frame, bindings.chunk, bindings.scratch};
    gridFor(uint64_t(count) * SFFD_ACC_THREADS_PER_SUB(stage, m, nv), backend.info().limits, d.groups);
    backend.dispatch(d);
    backend.barrier();
  }
}

AccurateOutput accurateFfd(Backend& backend, const AccurateJob& job, const PackedLattice& lattice, KernelVariant variant,
                           size_t maxChunk) {
  if (variant.f64 && !backend.info().limits.float64)
    throw noFloat64Error(backend.info());
  AccurateOutput out;
  auto t0 = std::chrono::steady_clock::now();
  if (job.count() > 0) {
    if (variant.f64) accurateRun<double>(backend, job, lattice, variant, maxChunk, out);
    else accurateRun<float>(backend, job, lattice, variant, maxChunk, out);
  }
  out.wallMs = msSince(t0);
  return out;
}

namespace {
template <class Real>
void writeAccurate(const AccurateJob& job, size_t first, size_t count, const Real* positions, const Real* normals, size_t at,
                   PatchVertices& pv) {
  const size_t nv = size_t(tessVertexCount(pv.level));
  const std::vector<double> w = tessWeights(pv.level);
  pv.resize(at + count);
  double* lamParent = &pv.lamParent[3 * nv * at];
  double* position = &pv.position[3 * nv * at];
  double* normal = &pv.normal[3 * nv * at];
  for (size_t s = 0; s < count; ++s, lamParent += 3 * nv) {
    const SubTriangle& T = job.subs[first + s];
    pv.parent[at + s] = T.parent;
    writeTessPreImages(w, &T.corners[0].lam[0], &T.corners[1].lam[0], &T.corners[2].lam[0], lamParent);
    for (size_t v = 0; v < nv; ++v, position += 3, normal += 3) {
      const size_t g = s * nv + v;
      for (int a = 0; a < 3; ++a) {
        position[a] = double(positions[4 * g + a]) + 0.0;   // -0 -> +0: welding compares bits
        normal[a] = double(normals[4 * g + a]) + 0.0;
      }
    }
  }
}
}  // namespace

void writeAccuratePatchVertices(const AccurateJob& job, size_t first, size_t count, const float* positions,
                                const float* normals, size_t at, PatchVertices& pv) {
  writeAccurate(job, first, count, positions, normals, at, pv);
}
void writeAccuratePatchVertices(const AccurateJob& job, size_t first, size_t count, const double* positions,
                                const double* normals, size_t at, PatchVertices& pv) {
  writeAccurate(job, first, count, positions, normals, at, pv);
}

PatchVertices accuratePatchVertices(const AccurateJob& job, const AccurateOutput& out) {
  PatchVertices pv;
  pv.level = job.level;
  pv.reserve(job.count());
  writeAccurate(job, 0, job.count(), out.positions.data(), out.normals.data(), 0, pv);
  return pv;
}

}  // namespace sffd
