// The CPU entry of kernel accurate_patches: its C++ twin, one stage a dispatch as the kernel runs
// (range.z: samples, control points, tessellation), the same operations in the same order.
#include <algorithm>
#include <span>

#include "kernels/accurate/accurate_patches.h"
#include "core/job_budget.h"
#include "kernels/common/cpu_kernel.h"

namespace sffd {
namespace {

// The point (i, j, k) / d of the flat triangle (c0, c1, c2) (accFlatPoint).
template <class Real>
RVec3<Real> flatPoint(RVec3<Real> c0, RVec3<Real> c1, RVec3<Real> c2, uint32_t i, uint32_t j, uint32_t k, uint32_t d) {
  Real l0 = Real(i) / Real(d);
  Real l1 = Real(j) / Real(d);
  Real l2 = Real(k) / Real(d);
  return (c0 * l0 + c1 * l1) + c2 * l2;
}

// Row r of linear index idx in the triangular layout (accRow).
uint32_t row(uint32_t idx) {
  uint32_t r = 0;
  while ((r + 1) * (r + 2) / 2 <= idx) ++r;
  return r;
}

template <class Real>
RVec3<Real> get(const Real* r) { return {r[0], r[1], r[2]}; }
template <class Real>
void put(Real* o, RVec3<Real> v) { o[0] = v.x, o[1] = v.y, o[2] = v.z, o[3] = 0; }

template <class Real>
void accurateThreads(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  const auto& p = a.paramsAs<gpu::AccurateParams>();
  const uint32_t n = p.shape.x, m = p.shape.y, L = p.shape.z, nv = p.shape.w, stage = p.range.z;
  a.check(m <= SFFD_ACC_MAX_CP && m == uint32_t(triangleControlPoints(int(n))) && L >= 1 && L <= uint32_t(kMaxTessLevel) &&
              nv == uint32_t(tessVertexCount(int(L))),
          "accurate: patch shape out of range");
  const uint64_t subs = uint64_t(p.range.x) + p.range.y, per = SFFD_ACC_THREADS_PER_SUB(stage, m, nv);
  // The sections of the chunk and scratch ranges and the tables in the frame range (layout.h).
  const uint64_t normalsAt = 4 * uint64_t(p.sections.x), cornersAt = 4 * uint64_t(p.sections.y),
                 patchesAt = 4 * uint64_t(p.sections.z);
  Real* chunk = a.array<Real>(SFFD_BINDING_ACC_CHUNK, std::max(normalsAt + 4 * nv * subs, cornersAt + 4 * SFFD_ACC_CORNER_STRIDE * subs)).data();
  Real* scratch = a.array<Real>(SFFD_BINDING_ACC_SCRATCH, std::max(4 * m * subs, patchesAt + 4 * m * subs)).data();
  const Real* corners = chunk + cornersAt;
  const uint64_t end = std::min<uint64_t>(last, per * p.range.y);
  if (stage == SFFD_ACC_STAGE_SAMPLES) {
    LatticeEvaluator<Real> eval = boundLattice<Real>(a, p.lattice, p.inline_lattice);
    Real* samples = scratch;
    for (uint64_t t = first; t < end; ++t) {
      const uint32_t local = uint32_t(t / per), e = uint32_t(t - uint64_t(local) * per), s = p.range.x + local;
      const Real* c = &corners[4 * SFFD_ACC_CORNER_STRIDE * size_t(s)];
      const uint32_t r = row(e), q = e - r * (r + 1) / 2;
      RVec3<Real> x = flatPoint(get(c), get(c + 4), get(c + 8), n - r, r - q, q, n);
      LatticeSampleT<Real> S = eval.evaluate(x);
      bool keep = !S.inside && p.lattice.degree.w == SFFD_OUTSIDE_KEEP;
      put(&samples[4 * (size_t(s) * m + e)], keep ? x : S.value);
    }
  } else if (stage == SFFD_ACC_STAGE_PATCHES) {
    const Real* matrix = tableReals<Real>(a, p.inline_lattice, p.tables.z, p.tables.x, uint64_t(m) * m);
    const Real* samples = scratch;
    Real* patches = scratch + patchesAt;
    for (uint64_t t = first; t < end; ++t) {
      const uint32_t s = p.range.x + uint32_t(t);   // a thread per sub-triangle
      for (uint32_t k = 0; k < m; ++k) {
        RVec3<Real> cp{};
        for (uint32_t l = 0; l < m; ++l) cp = cp + get(&samples[4 * (size_t(s) * m + l)]) * matrix[size_t(l) * m + k];
        put(&patches[4 * (size_t(s) * m + k)], cp);
      }
    }
  } else if (stage == SFFD_ACC_STAGE_TESSELLATE) {
    LatticeEvaluator<Real> eval = boundLattice<Real>(a, p.lattice, p.inline_lattice);
    const Real* basis = tableReals<Real>(a, p.inline_lattice, p.tables.w, p.tables.y, uint64_t(nv) * m);
    const Real* patches = scratch + patchesAt;
    Real* positions = chunk;
    Real* normals = chunk + normalsAt;
    for (uint64_t t = first; t < end; ++t) {
      const uint32_t local = uint32_t(t / per), e = uint32_t(t - uint64_t(local) * per), s = p.range.x + local;
      const Real* c = &corners[4 * SFFD_ACC_CORNER_STRIDE * size_t(s)];
      const RVec3<Real> nf = get(c + 12);
      const uint32_t r = row(e), q = e - r * (r + 1) / 2;
      const uint32_t i = L - r, j = r - q, k = q;
      RVec3<Real> x = flatPoint(get(c), get(c + 4), get(c + 8), i, j, k, L);
      LatticeSampleT<Real> S = eval.evaluate(x);
      bool keep = !S.inside && p.lattice.degree.w == SFFD_OUTSIDE_KEEP;
      RVec3<Real> pos{};
      if (i == 0 || j == 0 || k == 0) {
        pos = keep ? x : S.value;
      } else {
        const Real* b = &basis[size_t(e) * m];
        for (uint32_t kk = 0; kk < m; ++kk) pos = pos + get(&patches[4 * (size_t(s) * m + kk)]) * b[kk];
      }
      RVec3<Real> nrm = keep ? nf : eval.cofactorNormal(S, nf);
      if (!(sdot(nrm, nrm) > Real(0))) nrm = nf;   // a singular point of the map
      put(&positions[4 * (size_t(s) * nv + e)], pos);
      put(&normals[4 * (size_t(s) * nv + e)], snormalize(nrm));
    }
  } else {
    a.fail("accurate: unknown stage " + std::to_string(stage));
  }
}

}  // namespace

void cpu::accuratePatches(const CpuKernelArgs& a, uint64_t first, uint64_t last) {
  // Both precisions also as compiled for AVX2: double is what the method runs by default (--precision auto).
  a.variant.f64 ? withAvx2<accurateThreads<double>>(a, first, last) : withAvx2<accurateThreads<float>>(a, first, last);
}

}  // namespace sffd
