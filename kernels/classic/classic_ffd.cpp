#include "kernels/classic/classic_ffd.h"

#include <algorithm>
#include <chrono>

#include <sffd/error.h>
#include "kernels/common/cpu_kernel.h"
#include "core/kernel_registry.h"
#include "core/wall_clock.h"

namespace sffd {
namespace {

template <class Real>
void classicRun(Backend& backend, const Mesh& mesh, const PackedLattice& P, KernelVariant variant, size_t maxChunk, ClassicOutput& out) {
  const DeviceLimits& lim = backend.info().limits;
  const size_t n = mesh.positions.size();
  const size_t vertexBytes = 4 * sizeof(Real);
  const size_t chunk = classicChunkVertices(lim, n, sizeof(Real), maxChunk);

  std::vector<Real> frame = convertReals<Real>(P.frame), coeffs = convertReals<Real>(P.coeffs);
  if (coeffs.size() * sizeof(Real) > lim.maxStorageBufferRange)
    throw Error(ErrorKind::Input, "lattice has too many knot boxes for one storage binding on this device");
  BufferId bFrame = backend.createBuffer(frame.size() * sizeof(Real));
  BufferId bCoeffs = backend.createBuffer(coeffs.size() * sizeof(Real));
  backend.upload(bFrame, 0, frame.data(), frame.size() * sizeof(Real));
  backend.upload(bCoeffs, 0, coeffs.data(), coeffs.size() * sizeof(Real));
  // One buffer in and one out: the positions, then the normals from element `chunk`.
  BufferId io[2];
  for (BufferId& b : io) b = backend.createBuffer(2 * chunk * vertexBytes);

  out.positions.resize(4 * n);
  out.normals.resize(4 * n);
  std::vector<Real> pos(4 * chunk), nrm(4 * chunk);
  for (size_t first = 0; first < n; first += chunk) {
    size_t count = std::min(chunk, n - first);
    for (size_t i = 0; i < count; ++i) {
      const glm::dvec3 &x = mesh.positions[first + i], &nn = mesh.normals[first + i];
      Real* p = &pos[4 * i];
      Real* q = &nrm[4 * i];
      p[0] = Real(x.x), p[1] = Real(x.y), p[2] = Real(x.z), p[3] = 1;
      q[0] = Real(nn.x), q[1] = Real(nn.y), q[2] = Real(nn.z), q[3] = 0;
    }
    backend.upload(io[0], 0, pos.data(), count * vertexBytes);
    backend.upload(io[0], chunk * vertexBytes, nrm.data(), count * vertexBytes);
    dispatchClassicFfd(backend, P.params, variant, count,
                       {{SFFD_BINDING_LATTICE_COEFFS, bCoeffs}, {SFFD_BINDING_LATTICE_FRAME, bFrame},
                        {SFFD_BINDING_CLASSIC_IN, io[0]}, {SFFD_BINDING_CLASSIC_OUT, io[1]}},
                       chunk);
    backend.download(io[1], 0, pos.data(), count * vertexBytes);
    backend.download(io[1], chunk * vertexBytes, nrm.data(), count * vertexBytes);
    for (size_t i = 0; i < 4 * count; ++i) {
      out.positions[4 * first + i] = pos[i];
      out.normals[4 * first + i] = nrm[i];
    }
  }
  backend.finish();
  for (BufferId b : io) backend.destroyBuffer(b);
  backend.destroyBuffer(bFrame);
  backend.destroyBuffer(bCoeffs);
  out.timings = backend.takeTimings();
}

}  // namespace

size_t classicChunkVertices(const DeviceLimits& lim, size_t n, size_t realBytes, size_t maxChunk) {
  // Every binding of a chunk (positions and normals, the latter at an aligned offset) stays within the
  // device's storage range and group-count limits.
  size_t maxByRange = size_t((lim.maxStorageBufferRange - std::min(lim.maxStorageBufferRange, lim.storageOffsetAlignment)) /
                             (8 * realBytes));
  size_t maxByGroups = size_t(lim.maxWorkGroupCount[0]) * lim.maxWorkGroupCount[1] * SFFD_LOCAL_SIZE;
  size_t chunk = std::min({maxByRange, maxByGroups, std::max<size_t>(n, 1)});
  if (maxChunk) chunk = std::min(chunk, maxChunk);
  return std::max<size_t>(1, chunk);
}

KernelUse classicKernel(const gpu::LatticeParams& lattice, KernelVariant variant) {
  return {"classic_ffd", forLattice(variant, lattice)};
}

void dispatchClassicFfd(Backend& backend, const gpu::LatticeParams& lattice, KernelVariant variant, size_t count,
                        const ClassicBindings& b, size_t normalsAt) {
  gpu::ClassicParams params;
  params.lattice = lattice;
  params.range = {0, uint32_t(count), uint32_t(normalsAt), 0};
  Dispatch d;
  const KernelUse k = classicKernel(lattice, variant);
  d.kernel = k.kernel;
  d.variant = k.variant;
  d.params = &params;
  d.paramsSize = sizeof(params);
  d.buffers = {b.coeffs, b.frame, b.in, b.out};
  gridFor(count, backend.info().limits, d.groups);
  backend.dispatch(d);
  backend.barrier();
}

ClassicOutput classicFfd(Backend& backend, const Mesh& mesh, const PackedLattice& lattice, KernelVariant variant,
                         size_t maxChunk) {
  if (variant.f64 && !backend.info().limits.float64)
    throw noFloat64Error(backend.info());
  ClassicOutput out;
  auto t0 = std::chrono::steady_clock::now();
  if (variant.f64) classicRun<double>(backend, mesh, lattice, variant, maxChunk, out);
  else classicRun<float>(backend, mesh, lattice, variant, maxChunk, out);
  out.wallMs = msSince(t0);
  return out;
}

namespace {

// The twin of classic_ffd.comp's main().
template <class Real>
void classicThreads(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  const auto& p = a.paramsAs<gpu::ClassicParams>();
  LatticeEvaluator<Real> eval = boundLattice<Real>(a, p.lattice);
  const uint64_t n = 4 * (uint64_t(p.range.x) + p.range.y), normals = 4 * uint64_t(p.range.z);
  const Real* posIn = a.array<const Real>(SFFD_BINDING_CLASSIC_IN, normals + n).data();
  const Real* nrmIn = posIn + normals;
  Real* posOut = a.array<Real>(SFFD_BINDING_CLASSIC_OUT, normals + n).data();
  Real* nrmOut = posOut + normals;
  for (uint64_t t = first; t < std::min<uint64_t>(last, p.range.y); ++t) {
    const size_t v = 4 * size_t(p.range.x + uint32_t(t));
    RVec3<Real> x{posIn[v], posIn[v + 1], posIn[v + 2]}, nr{nrmIn[v], nrmIn[v + 1], nrmIn[v + 2]};
    LatticeSampleT<Real> S = eval.evaluate(x);
    RVec3<Real> px = x, pn = nr;
    Real inside = 0;
    if (S.inside || p.lattice.degree.w != SFFD_OUTSIDE_KEEP) {
      px = S.value;
      pn = snormalize(eval.cofactorNormal(S, nr));
      inside = S.inside ? 1 : 0;
    }
    posOut[v] = px.x, posOut[v + 1] = px.y, posOut[v + 2] = px.z, posOut[v + 3] = inside;
    nrmOut[v] = pn.x, nrmOut[v + 1] = pn.y, nrmOut[v + 2] = pn.z, nrmOut[v + 3] = 0;
  }
}

}  // namespace

void cpu::classicFfd(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  // Both precisions also as compiled for AVX2: double is what the method runs by default (--precision auto).
  a.variant.f64 ? withAvx2<classicThreads<double>>(a, first, last) : withAvx2<classicThreads<float>>(a, first, last);
}

Mesh applyClassicOutput(const Mesh& input, const ClassicOutput& out) {
  Mesh m = input;
  for (size_t v = 0; v < m.positions.size(); ++v) {
    m.positions[v] = {out.positions[4 * v], out.positions[4 * v + 1], out.positions[4 * v + 2]};
    m.normals[v] = {out.normals[4 * v], out.normals[4 * v + 1], out.normals[4 * v + 2]};
  }
  m.patches.clear();
  m.vertexPatch.clear();
  m.vertexUV.clear();
  return m;
}

}  // namespace sffd
