// The smooth-FFD pipeline on the CPU backend, stage by stage, on the teapot (teapot.bpt, 36 patches,
// 7200 triangles) and the torus (torus.obj, 8400 triangles), both normalised to a largest
// half-extent of 1/1.1 and clipped with target edge length l = 0.2 (the call sequence of
// apps/sffd/smooth_job.cpp). At l = 0.2 every edge of both models is shorter than l, so regular
// clipping yields one sub-triangle per triangle; the `fine` cases use l = 0.02, where the split
// patterns really subdivide (several segments an edge), to measure clipping and deform at scale:
// prepareMesh -> pnTriangles (K1) -> buildClipTriangles + regularClip (K2) -> smoothDeform
// (K3, tessellation levels 1, 5, 10) with makeFitTable(6). Each stage is timed alone on the cached
// output of the previous ones, so a regression points at one stage. Items are triangles for the
// pre-compute stages and sub-triangles for clip output and deform. The CPU backend runs every kernel
// on all cores (SFFD_CPU_THREADS), so the kernels are measured in wall time (UseRealTime).
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <tuple>

#include "bench_data.h"
#include "model/lattice_pack.h"
#include "kernels/pn/pn_triangles.h"
#include "model/prepared_mesh.h"
#include "kernels/clip/regular_clip.h"
#include "kernels/smooth/smooth_deform.h"
#include "kernels/clip/split_pattern_table.h"

using namespace sffd;

namespace {

constexpr double kEdgeLengths[] = {0.2, 0.02};   // index = the `fine` argument
const char* const kModels[] = {"teapot.bpt", "torus.obj"};

// Every stage's output for one model and arithmetic, computed once.
struct Stages {
  const Mesh* mesh = nullptr;
  PreparedMesh prepared;
  PnOutput pn;
  ClipTriangles clip;
  SubTriangleRecords subs;
  PackedLattice lattice;
  FitTable fit;
};

const Stages& stages(int model, bool f64, int fine = 0) {
  static std::map<std::tuple<int, bool, int>, std::unique_ptr<Stages>> cache;
  auto& s = cache[{model, f64, fine}];
  const double l = kEdgeLengths[fine];
  if (!s) {
    s = std::make_unique<Stages>();
    KernelVariant v{false, f64};
    s->mesh = &bench::model(kModels[model]);
    s->prepared = prepareMesh(*s->mesh);
    s->pn = pnTriangles(bench::cpuBackend(), s->prepared, v);
    s->clip = buildClipTriangles(*s->mesh, l, splitPatternTable().nmax());
    s->subs = regularClip(bench::cpuBackend(), s->prepared, s->pn, s->clip, l, v);
    s->lattice = packLattice(bench::deformedLattice(*s->mesh, 5, 2));
    s->fit = makeFitTable(6);
  }
  return *s;
}

void setModelLabel(benchmark::State& state, int model) { state.SetLabel(kModels[model]); }

// Arg: model (0 teapot, 1 torus). Items = triangles.
void BM_PrepareMesh(benchmark::State& state) {
  const int model = int(state.range(0));
  const Mesh& m = bench::model(kModels[model]);
  for (auto _ : state) {
    PreparedMesh P = prepareMesh(m);
    benchmark::DoNotOptimize(P.triangles.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(m.triangles.size()));
  setModelLabel(state, model);
}
BENCHMARK(BM_PrepareMesh)->ArgName("model")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// Args: model, f64. Items = triangles.
void BM_PnTrianglesCpu(benchmark::State& state) {
  const int model = int(state.range(0));
  const bool f64 = state.range(1) != 0;
  const Stages& s = stages(model, f64);
  for (auto _ : state) {
    PnOutput pn = pnTriangles(bench::cpuBackend(), s.prepared, {false, f64});
    benchmark::DoNotOptimize(pn.records.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(s.prepared.triangleCount()));
  setModelLabel(state, model);
}
BENCHMARK(BM_PnTrianglesCpu)->ArgNames({"model", "f64"})->ArgsProduct({{0, 1}, {1, 0}})->UseRealTime()->Unit(benchmark::kMillisecond);

// Args: model, fine. The pre-split into clip triangles of at most Nmax segments an edge. Items =
// triangles.
void BM_BuildClipTriangles(benchmark::State& state) {
  const int model = int(state.range(0));
  const double l = kEdgeLengths[state.range(1)];
  const Mesh& m = bench::model(kModels[model]);
  const int nmax = splitPatternTable().nmax();
  size_t clipCount = 0;
  for (auto _ : state) {
    ClipTriangles C = buildClipTriangles(m, l, nmax);
    clipCount = C.triangles.size();
    benchmark::DoNotOptimize(C.triangles.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(m.triangles.size()));
  state.counters["clip_tris"] = double(clipCount);
  setModelLabel(state, model);
}
BENCHMARK(BM_BuildClipTriangles)->ArgNames({"model", "fine"})->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMillisecond);

// Args: model, f64, fine. Regular clipping by the split-pattern table into sub-triangle records
// lifted onto the PN surface. Items = sub-triangles written.
void BM_RegularClipCpu(benchmark::State& state) {
  const int model = int(state.range(0));
  const bool f64 = state.range(1) != 0;
  const int fine = int(state.range(2));
  const Stages& s = stages(model, f64, fine);
  size_t subs = 0;
  for (auto _ : state) {
    SubTriangleRecords R = regularClip(bench::cpuBackend(), s.prepared, s.pn, s.clip, kEdgeLengths[fine], {false, f64});
    subs = R.size();
    benchmark::DoNotOptimize(R.records.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(subs));
  state.counters["sub_tris"] = double(subs);
  setModelLabel(state, model);
}
BENCHMARK(BM_RegularClipCpu)
    ->ArgNames({"model", "f64", "fine"})
    ->ArgsProduct({{0, 1}, {1, 0}, {0}})
    ->Args({0, 1, 1})
    ->Args({0, 0, 1})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// The sampling-lattice fit table (closed-form constrained least squares), degree s.
void BM_MakeFitTable(benchmark::State& state) {
  const int s = int(state.range(0));
  int points = 0;
  for (auto _ : state) {
    FitTable F = makeFitTable(s);
    points = F.points;
    benchmark::DoNotOptimize(F.data.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * points);
  state.counters["fit_points"] = points;
}
BENCHMARK(BM_MakeFitTable)->ArgName("s")->Arg(6)->Unit(benchmark::kMicrosecond);

// Args: model, tessellation level, f64, fine. The deform stage K3 (sample, fit, adjust, tessellate)
// with a twisted 5x5x5 degree-2 lattice. Items = sub-triangles (patches).
void BM_SmoothDeformCpu(benchmark::State& state) {
  const int model = int(state.range(0));
  const int level = int(state.range(1));
  const bool f64 = state.range(2) != 0;
  const Stages& s = stages(model, f64, int(state.range(3)));
  for (auto _ : state) {
    SmoothOutput out = smoothDeform(bench::cpuBackend(), s.lattice, s.subs, s.fit, level, {false, f64});
    benchmark::DoNotOptimize(out.tess.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(s.subs.size()));
  state.counters["sub_tris"] = double(s.subs.size());
  setModelLabel(state, model);
}
BENCHMARK(BM_SmoothDeformCpu)
    ->ArgNames({"model", "level", "f64", "fine"})
    ->ArgsProduct({{0}, {1, 5, 10}, {0, 1}, {0}})
    ->Args({1, 5, 1, 0})
    ->Args({0, 5, 0, 1})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
