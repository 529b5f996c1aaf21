#include "kernels/smooth/smooth_deform.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <span>

#include <sffd/error.h>
#include "kernels/pn/pn_eval.h"
#include "kernels/common/shader_layout.h"
#include "core/kernel_registry.h"
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

template <class Real>
void deformRun(Backend& backend, const PackedLattice& P, const SubTriangleRecords& subs, const FitTable& F, int level,
               KernelVariant variant, bool split, size_t maxChunk, SmoothOutput& out) {
  const DeviceLimits& lim = backend.info().limits;
  const size_t n = subs.size(), nv = size_t(tessVertexCount(level));
  const size_t recReals = SFFD_SUB_STRIDE * 4, patchReals = SFFD_PATCH_STRIDE * 4, tessReals = 2 * nv * 4;
  const size_t sampleReals = (SFFD_SAMPLE_FIXED + size_t(F.points)) * 4;
  // Chunks of sub-triangles whose records and output range (patches, tessellation, samples) fit one binding each.
  const size_t outReals = patchReals + tessReals + (split ? sampleReals : 0);
  size_t chunk = size_t(lim.maxStorageBufferRange / (std::max(recReals, outReals) * sizeof(Real)));
  chunk = std::min<size_t>(chunk, size_t(lim.maxWorkGroupCount[0]) * lim.maxWorkGroupCount[1] * SFFD_LOCAL_SIZE);
  if (maxChunk) chunk = std::min(chunk, maxChunk);
  chunk = std::max<size_t>(1, std::min(chunk, std::max<size_t>(n, 1)));
  std::vector<Real> frame = convertReals<Real>(deformFrameRange(P, F.data)), coeffs = convertReals<Real>(P.coeffs);
  auto make = [&](const void* data, size_t bytes) {
    BufferId b = backend.createBuffer(std::max<size_t>(bytes, 16));
    if (data && bytes) backend.upload(b, 0, data, bytes);
    return b;
  };
  BufferId bFrame = make(frame.data(), frame.size() * sizeof(Real)), bCoeffs = make(coeffs.data(), coeffs.size() * sizeof(Real));
  BufferId bRec = make(nullptr, chunk * recReals * sizeof(Real));
  BufferId bOut = make(nullptr, chunk * outReals * sizeof(Real));
  out.patches.resize(n * patchReals);
  out.tess.resize(n * tessReals);
  std::vector<Real> rec(chunk * recReals), buf(chunk * (patchReals + tessReals));
  gpu::DeformParams params = deformParamsFor(P, variant.f64, &F.data);
  for (size_t first = 0; first < n; first += chunk) {
    size_t count = std::min(chunk, n - first);
    std::transform(subs.records.begin() + first * recReals, subs.records.begin() + (first + count) * recReals, rec.begin(),
                   [](double v) { return Real(v); });
    backend.upload(bRec, 0, rec.data(), count * recReals * sizeof(Real));
    params.range = {0, uint32_t(count), uint32_t(F.points), uint32_t(level)};
    deformOutSections(params, count, level, F.points, split);
    dispatchDeform(backend, params, {bCoeffs, bFrame, bRec, bOut}, count, variant, split);
    // The tessellation, then the patches from element sections.z: one download.
    backend.download(bOut, 0, buf.data(), count * (patchReals + tessReals) * sizeof(Real));
    std::copy(buf.begin(), buf.begin() + count * tessReals, out.tess.begin() + first * tessReals);
    std::copy(buf.begin() + count * tessReals, buf.begin() + count * (tessReals + patchReals), out.patches.begin() + first * patchReals);
  }
  backend.finish();
  for (BufferId b : {bFrame, bCoeffs, bRec, bOut}) backend.destroyBuffer(b);
  out.timings = backend.takeTimings();
}

}  // namespace

SmoothOutput smoothDeform(Backend& backend, const PackedLattice& lattice, const SubTriangleRecords& subs,
                          const FitTable& fit, int level, KernelVariant variant, bool split, size_t maxChunk) {
  if (variant.f64 && !backend.info().limits.float64)
    throw noFloat64Error(backend.info());
  SmoothOutput out;
  out.level = level;
  auto t0 = std::chrono::steady_clock::now();
  if (subs.size()) {
    if (variant.f64) deformRun<double>(backend, lattice, subs, fit, level, variant, split, maxChunk, out);
    else deformRun<float>(backend, lattice, subs, fit, level, variant, split, maxChunk, out);
  }
  out.wallMs = msSince(t0);
  return out;
}

uint64_t deformOutSections(gpu::DeformParams& params, uint64_t count, int level, int fitPoints, bool split) {
  const uint64_t patches = 2 * uint64_t(tessVertexCount(level)) * count, samples = patches + SFFD_PATCH_STRIDE * count;
  params.sections.z = uint32_t(patches);
  params.sections.w = split ? uint32_t(samples) : 0;
  return split ? samples + (SFFD_SAMPLE_FIXED + uint64_t(fitPoints)) * count : samples;
}

namespace {
// The deform kernel, or the split's four steps, with their timing labels.
struct DeformStep {
  const char* kernel;
  const char* label;
};
constexpr DeformStep kWholeDeform[] = {{"deform_smooth", "deform"}};
constexpr DeformStep kSplitDeform[] = {{"deform_step_sample", "deform.sample"},
                                       {"deform_step_fit", "deform.fit"},
                                       {"deform_step_adjust", "deform.adjust"},
                                       {"deform_step_tessellate", "deform.tessellate"}};
std::span<const DeformStep> deformSteps(bool split) {
  return split ? std::span<const DeformStep>(kSplitDeform) : std::span<const DeformStep>(kWholeDeform);
}
}  // namespace

std::vector<KernelUse> deformKernels(const gpu::DeformParams& params, KernelVariant variant, bool split) {
  std::vector<KernelUse> uses;
  for (const DeformStep& step : deformSteps(split)) uses.push_back({step.kernel, forLattice(variant, params)});
  return uses;
}

void dispatchDeform(Backend& backend, const gpu::DeformParams& params, const DeformBuffers& b, size_t count,
                    KernelVariant variant, bool split) {
  const std::vector<BufferBinding> buffers = {{SFFD_BINDING_LATTICE_COEFFS, b.coeffs}, {SFFD_BINDING_LATTICE_FRAME, b.frame},
                                              {SFFD_BINDING_DEFORM_SUB_RECORDS, b.records}, {SFFD_BINDING_DEFORM_OUT, b.out}};
  for (const DeformStep& step : deformSteps(split)) {
    Dispatch d;
    d.kernel = step.kernel;
    d.label = step.label;
    d.variant = forLattice(variant, params);
    d.params = &params;
    d.paramsSize = sizeof(params);
    d.buffers = buffers;
    gridFor(count, backend.info().limits, d.groups);
    backend.dispatch(d);
    backend.barrier();
  }
}

namespace {
template <class Real>
void writePatchVerticesOf(const SubTrianglePreImages& subs, size_t first, size_t count, const Real* tess, size_t at,
                          PatchVertices& P) {
  const size_t nv = size_t(tessVertexCount(P.level));
  const std::vector<double> w = tessWeights(P.level);
  P.resize(at + count);
  double* lamParent = &P.lamParent[3 * nv * at];
  double* position = &P.position[3 * nv * at];
  double* normal = &P.normal[3 * nv * at];
  for (size_t s = 0; s < count; ++s, lamParent += 3 * nv) {
    P.parent[at + s] = subs.parent[first + s];
    const double* lam = &subs.lam[9 * (first + s)];   // corner c's barycentrics from 3c
    writeTessPreImages(w, lam, lam + 3, lam + 6, lamParent);
    const Real* t = &tess[s * 2 * nv * 4];
    for (size_t v = 0; v < nv; ++v, position += 3, normal += 3)
      for (int a = 0; a < 3; ++a) {
        position[a] = double(t[4 * v + a]);
        normal[a] = double(t[4 * (nv + v) + a]);
      }
  }
}
}  // namespace

void writePatchVertices(const SubTrianglePreImages& subs, size_t first, size_t count, const float* tess, size_t at,
                        PatchVertices& P) {
  writePatchVerticesOf(subs, first, count, tess, at, P);
}
void writePatchVertices(const SubTrianglePreImages& subs, size_t first, size_t count, const double* tess, size_t at,
                        PatchVertices& P) {
  writePatchVerticesOf(subs, first, count, tess, at, P);
}

PatchVertices patchVerticesOf(const SubTriangleRecords& subs, const SmoothOutput& out) {
  PatchVertices P;
  P.level = out.level;
  SubTrianglePreImages pre;
  pre.append(subs.headers.data(), subs.records.data(), subs.size());
  P.reserve(pre.size());
  writePatchVerticesOf(pre, 0, pre.size(), out.tess.data(), 0, P);
  return P;
}

}  // namespace sffd
