#include "kernels/pn/pn_triangles.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>

#include <sffd/error.h>
#include "model/lattice_pack.h"
#include "kernels/common/cpu_kernel.h"
#include "kernels/pn/pn_eval.h"
#include "kernels/common/shader_layout.h"
#include "core/wall_clock.h"

// pn_triangles.comp stores a record as 16 consecutive values, the normals right after the 10 points.
static_assert(SFFD_PN_NORMALS == 10 && SFFD_PN_STRIDE == 16, "pn_triangles.comp's record stores follow layout.h");

namespace sffd {
namespace {

// The twin of pn_triangles.comp's main().
template <class Real>
void pnThreads(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  const auto& p = a.paramsAs<gpu::PnParams>();
  const uint64_t nt = uint64_t(p.range.x) + p.range.y;
  // The vertices' range: positions, then the normals from element range.z (layout.h).
  std::span<const Real> pos = a.array<const Real>(SFFD_BINDING_MESH_VERTICES);
  std::span<const Real> nrm = pos.subspan(std::min<size_t>(pos.size(), 4 * size_t(p.range.z)));
  const uint32_t* tri = a.array<const uint32_t>(SFFD_BINDING_MESH_TRIANGLES, 4 * SFFD_MESH_TRIANGLE_STRIDE * nt).data();
  const Real* slots = a.array<const Real>(SFFD_BINDING_MESH_SLOT_NORMALS, 4 * SFFD_SLOT_NORMAL_STRIDE * nt).data();
  Real* out = a.array<Real>(SFFD_BINDING_PN_OUT, 4 * SFFD_PN_STRIDE * nt).data();
  auto vec = [](const Real* r) { return RVec3<Real>{r[0], r[1], r[2]}; };
  for (uint64_t t = first; t < std::min<uint64_t>(last, p.range.y); ++t) {
    const size_t tr = p.range.x + uint32_t(t);
    RVec3<Real> V[3], N[3], nFirst[6], nSecond[6];
    bool crease[6];
    uint32_t weld[3];
    for (int c = 0; c < 3; ++c) {
      const uint32_t id = tri[8 * tr + c];
      a.check(4 * uint64_t(id) + 4 <= std::min(pos.size(), nrm.size()), "a triangle's vertex id is outside the vertex buffers");
      V[c] = vec(&pos[4 * size_t(id)]);
      N[c] = vec(&nrm[4 * size_t(id)]);
      weld[c] = tri[8 * tr + 4 + c];
    }
    for (int s = 0; s < 6; ++s) {
      const Real* f = &slots[4 * (SFFD_SLOT_NORMAL_STRIDE * tr + 2 * s)];
      nFirst[s] = vec(f);
      crease[s] = f[3] > Real(0.5);
      nSecond[s] = vec(f + 4);
    }
    PnPatchT<Real> P = pnBuild(V, N, nFirst, crease, nSecond, weld);
    Real* o = &out[4 * SFFD_PN_STRIDE * tr];
    for (int i = 0; i < 10; ++i) o[4 * i] = P.cp[i].x, o[4 * i + 1] = P.cp[i].y, o[4 * i + 2] = P.cp[i].z, o[4 * i + 3] = 0;
    for (int i = 0; i < 6; ++i) {
      Real* q = o + 4 * (SFFD_PN_NORMALS + i);
      q[0] = P.n[i].x, q[1] = P.n[i].y, q[2] = P.n[i].z, q[3] = 0;
    }
  }
}

template <class Real>
void pnRun(Backend& backend, const PreparedMesh& M, KernelVariant variant, size_t maxChunk, PnOutput& out) {
  const DeviceLimits& lim = backend.info().limits;
  const size_t nt = M.triangleCount(), nv = M.positions.size() / 4;
  const uint64_t vertexBytes = nv * 4 * sizeof(Real);
  if (2 * vertexBytes > lim.maxStorageBufferRange)   // positions, then normals, in one range
    throw Error(ErrorKind::Input, "mesh has too many vertices for one storage binding on this device (" +
                                      std::to_string(nv) + " vertices)");
  // Per-triangle arrays go in chunks that fit one binding each; the largest is the PN record.
  const size_t perTriangle = SFFD_PN_STRIDE * 4 * sizeof(Real);
  size_t chunk = size_t(lim.maxStorageBufferRange / perTriangle);
  chunk = std::min<size_t>(chunk, size_t(lim.maxWorkGroupCount[0]) * lim.maxWorkGroupCount[1] * SFFD_LOCAL_SIZE);
  if (maxChunk) chunk = std::min(chunk, maxChunk);
  chunk = std::max<size_t>(1, std::min(chunk, std::max<size_t>(nt, 1)));

  const std::vector<Real> verts = convertReals<Real>(meshVertexRange(M));
  BufferId bVerts = backend.createBuffer(std::max<uint64_t>(2 * vertexBytes, 16));
  backend.upload(bVerts, 0, verts.data(), 2 * vertexBytes);
  BufferId bTri = backend.createBuffer(chunk * 8 * sizeof(uint32_t));
  BufferId bSlot = backend.createBuffer(chunk * 48 * sizeof(Real));
  BufferId bOut = backend.createBuffer(chunk * perTriangle);
  out.records.resize(nt * SFFD_PN_STRIDE * 4);
  std::vector<Real> slot(chunk * 48), rec(chunk * SFFD_PN_STRIDE * 4);
  for (size_t first = 0; first < nt; first += chunk) {
    size_t count = std::min(chunk, nt - first);
    M.slotNormals(first, count, slot.data());
    backend.upload(bTri, 0, &M.triangles[8 * first], count * 8 * sizeof(uint32_t));
    backend.upload(bSlot, 0, slot.data(), count * 48 * sizeof(Real));
    gpu::PnParams params;
    params.range = {0, uint32_t(count), uint32_t(nv), 0};
    Dispatch d;
    d.kernel = "pn_triangles";
    d.label = "pn";
    d.variant = variant;
    d.params = &params;
    d.paramsSize = sizeof(params);
    d.buffers = {{SFFD_BINDING_MESH_VERTICES, bVerts}, {SFFD_BINDING_MESH_TRIANGLES, bTri}, {SFFD_BINDING_MESH_SLOT_NORMALS, bSlot},
                 {SFFD_BINDING_PN_OUT, bOut}};
    gridFor(count, lim, d.groups);
    backend.dispatch(d);
    backend.barrier();
    backend.download(bOut, 0, rec.data(), count * perTriangle);
    std::copy(rec.begin(), rec.begin() + count * SFFD_PN_STRIDE * 4, out.records.begin() + first * SFFD_PN_STRIDE * 4);
  }
  backend.finish();
  for (BufferId b : {bVerts, bTri, bSlot, bOut}) backend.destroyBuffer(b);
  out.timings = backend.takeTimings();
}

}  // namespace

std::vector<double> meshVertexRange(const PreparedMesh& mesh) {
  std::vector<double> v = mesh.positions;
  v.insert(v.end(), mesh.normals.begin(), mesh.normals.end());
  return v;
}

PnOutput pnTriangles(Backend& backend, const PreparedMesh& mesh, KernelVariant variant, size_t maxChunk) {
  if (variant.f64 && !backend.info().limits.float64)
    throw noFloat64Error(backend.info());
  PnOutput out;
  auto t0 = std::chrono::steady_clock::now();
  if (mesh.triangleCount() > 0) {
    if (variant.f64) pnRun<double>(backend, mesh, variant, maxChunk, out);
    else pnRun<float>(backend, mesh, variant, maxChunk, out);
  }
  out.wallMs = msSince(t0);
  return out;
}

void cpu::pnTriangles(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  a.variant.f64 ? pnThreads<double>(a, first, last) : withAvx2<pnThreads<float>>(a, first, last);
}

}  // namespace sffd
