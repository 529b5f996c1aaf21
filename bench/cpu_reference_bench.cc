// CPU reference of the lattice itself: what it costs to turn a Lattice into the kernels' Bezier box
// form (packLattice: Boehm knot insertion per knot box, extractBoxForm), to evaluate the trivariate
// volume and its Jacobian at a point (LatticeEvaluator, the C++ twin of kernels/common/lattice_eval.glsl,
// in double as the oracle and in float in the strict kernels' order), classic FFD of a whole model
// (classicFfdCpu, torus.obj) and the exact reference of the error analysis (ExactReference).
// These are the innermost loops of every CPU path and of `sffd conform`/`sffd error`, so their
// per-point rate is the number to watch when the evaluator or the packing changes.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

#include "bench_data.h"
#include "kernels/classic/classic_ffd.h"
#include "analysis/error_metrics.h"
#include "kernels/common/lattice_eval.h"
#include "model/lattice_pack.h"

using namespace sffd;

namespace {

// Uniform points in [-1.05, 1.05]^3 (a few just outside the lattice box, as real meshes have).
std::vector<glm::dvec3> randomPoints(size_t n) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u(-1.05, 1.05);
  std::vector<glm::dvec3> pts(n);
  for (auto& p : pts) p = {u(rng), u(rng), u(rng)};
  return pts;
}

Lattice twistedCube(int counts, int degree) {
  Lattice L = makeIdentityLattice({-1, -1, -1}, {1, 1, 1}, {counts, counts, counts}, {degree, degree, degree});
  applyLatticePreset(L, "twist", 0.5);
  return L;
}

// Args: control points per axis, degree. Items = knot boxes extracted.
void BM_PackLattice(benchmark::State& state) {
  Lattice L = twistedCube(int(state.range(0)), int(state.range(1)));
  size_t boxes = 0;
  for (auto _ : state) {
    PackedLattice P = packLattice(L);
    boxes = P.params.boxes.x * P.params.boxes.y * P.params.boxes.z;
    benchmark::DoNotOptimize(P.coeffs.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(boxes));
  state.counters["boxes"] = double(boxes);
}
BENCHMARK(BM_PackLattice)->Args({5, 2})->Args({16, 3})->Unit(benchmark::kMicrosecond);

// Args: control points per axis, degree. Items = points (value + three partials + inside flag).
template <class Real>
void BM_LatticeEvaluate(benchmark::State& state) {
  PackedLattice P = packLattice(twistedCube(int(state.range(0)), int(state.range(1))));
  std::vector<Real> frame = convertReals<Real>(P.frame), coeffs = convertReals<Real>(P.coeffs);
  LatticeEvaluator<Real> E(P.params, frame, coeffs);
  std::vector<RVec3<Real>> pts;
  for (const auto& p : randomPoints(1 << 16)) pts.push_back(RVec3<Real>::from(p));
  for (auto _ : state) {
    for (const auto& x : pts) {
      LatticeSampleT<Real> S = E.evaluate(x);
      benchmark::DoNotOptimize(S);
    }
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(pts.size()));
}
BENCHMARK_TEMPLATE(BM_LatticeEvaluate, double)->Args({5, 2})->Args({16, 3})->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_LatticeEvaluate, float)->Args({5, 2})->Args({16, 3})->Unit(benchmark::kMillisecond);

// Evaluation plus the cofactor normal, as classic FFD does per vertex.
template <class Real>
void BM_LatticeEvaluateWithNormal(benchmark::State& state) {
  PackedLattice P = packLattice(twistedCube(5, 2));
  std::vector<Real> frame = convertReals<Real>(P.frame), coeffs = convertReals<Real>(P.coeffs);
  LatticeEvaluator<Real> E(P.params, frame, coeffs);
  std::vector<RVec3<Real>> pts;
  for (const auto& p : randomPoints(1 << 16)) pts.push_back(RVec3<Real>::from(p));
  const RVec3<Real> n{Real(0.48), Real(0.6), Real(0.64)};
  for (auto _ : state) {
    for (const auto& x : pts) {
      LatticeSampleT<Real> S = E.evaluate(x);
      RVec3<Real> m = snormalize(E.cofactorNormal(S, n));
      benchmark::DoNotOptimize(S.value);
      benchmark::DoNotOptimize(m);
    }
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(pts.size()));
}
BENCHMARK_TEMPLATE(BM_LatticeEvaluateWithNormal, double)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_LatticeEvaluateWithNormal, float)->Unit(benchmark::kMillisecond);

// Classic FFD of torus.obj (every vertex and normal) on the CPU reference. Arg: 1 = double
// (the oracle), 0 = float in the strict kernels' order. Items = vertices.
void BM_ClassicFfdCpuTorus(benchmark::State& state) {
  const Mesh& m = bench::model("torus.obj");
  PackedLattice P = packLattice(bench::deformedLattice(m, 5, 2));
  KernelVariant v{true, state.range(0) != 0};
  for (auto _ : state) {
    ClassicOutput out = classicFfdCpu(m, P, v);
    benchmark::DoNotOptimize(out.positions.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(m.positions.size()));
  state.counters["vertices"] = double(m.positions.size());
}
BENCHMARK(BM_ClassicFfdCpuTorus)->ArgName("f64")->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

// The error analysis' exact reference: pre-image of a point of a teapot triangle on the exact
// Bezier surface (.bpt), then its exact FFD (position and cofactor normal). Items = points.
void BM_ExactReferenceTeapot(benchmark::State& state) {
  const Mesh& m = bench::model("teapot.bpt");
  PackedLattice P = packLattice(bench::deformedLattice(m, 5, 2));
  ExactReference ref(m, P);
  const uint32_t triangles = uint32_t(m.triangles.size());
  const glm::dvec3 lam(0.2, 0.3, 0.5);
  for (auto _ : state) {
    for (uint32_t t = 0; t < triangles; ++t) {
      glm::dvec3 x, n, xr, nr;
      ref.preImage(t, lam, x, n);
      ref.deform(x, n, xr, nr);
      benchmark::DoNotOptimize(xr);
      benchmark::DoNotOptimize(nr);
    }
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(triangles));
  state.counters["exact_surface"] = ref.exactSurface() ? 1 : 0;
}
BENCHMARK(BM_ExactReferenceTeapot)->Unit(benchmark::kMillisecond);

}  // namespace
