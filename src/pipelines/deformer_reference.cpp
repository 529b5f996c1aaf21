// Deformer on the CPU reference, until the CPU reference is a Backend (branch `cpu`): the same
// steps as the device runs, through the reference functions (*Cpu). Nothing is device-resident.
#include <chrono>

#include "core/job_budget.h"
#include "core/wall_clock.h"
#include "kernels/accurate/accurate_patches.h"
#include "kernels/classic/classic_ffd.h"
#include "kernels/clip/knot_box_clip.h"
#include "kernels/clip/regular_clip.h"
#include "kernels/clip/split_pattern_table.h"
#include "kernels/pn/pn_triangles.h"
#include "kernels/smooth/smooth_deform.h"
#include "model/prepared_mesh.h"
#include "pipelines/deformer_internal.h"

namespace sffd {
namespace {

class ReferenceRun final : public MethodRun {
 public:
  ReferenceRun(const Mesh& input, const Lattice& lattice, const ResolvedOptions& r, Timings& t) : input_(input), r_(r) {
    if (r.method == Method::Smooth) {
      prepared_ = prepareMesh(input);
      if (!r.knotBoxClip) clip_ = buildClipTriangles(input, r.edgeLength, splitPatternTable().nmax());
      else knotBox_ = clipAgainstKnotBoxes(input, lattice);
      precompute(t);
    } else if (r.method == Method::Classic) {
      PackedLattice packed = packLattice(lattice);
      const size_t realBytes = r.variant.f64 ? 8 : 4;
      checkJobFits(estimateClassicJob(input, packed, realBytes, nullptr), packed, realBytes, nullptr, r.memoryLimit,
                   "DeformOptions::memoryLimit");
    } else {
      const auto t0 = std::chrono::steady_clock::now();
      accurate_ = makeAccurateJob(input, lattice, clipAgainstKnotBoxes(input, lattice), r.tess);
      t.clipMs = msSince(t0);
      const uint64_t nv = uint64_t(tessVertexCount(r.tess)), m = uint64_t(triangleControlPoints(accurate_.degree));
      JobEstimate est;
      est.hostBytes = accurate_.count() * (nv * (8 + 9 + 8) * 8 + nv * 64 + m * 32 + tessTriangleCount(r.tess) * 12);
      checkJobFits(est, packLattice(lattice), r.variant.f64 ? 8 : 4, nullptr, r.memoryLimit, "DeformOptions::memoryLimit");
    }
  }

  void precompute(Timings& t) override {
    const auto t0 = std::chrono::steady_clock::now();
    PnOutput pn = pnTrianglesCpu(prepared_, r_.variant);
    t.pnMs = stageMs(pn.timings, pn.wallMs);
    subs_ = r_.knotBoxClip ? recordsFromSubTriangles(prepared_, pn, knotBox_, r_.variant)
                           : regularClipCpu(prepared_, pn, clip_, r_.edgeLength, r_.variant);
    t.clipMs = stageMs(subs_.timings, subs_.wallMs);
    t.wallMs = msSince(t0);
  }

  void deform(const Lattice& lattice, Timings& t, const ProgressReporter&) override {
    PackedLattice packed = packLattice(lattice);
    std::vector<DispatchTiming> timings;
    double wallMs = 0;
    if (r_.method == Method::Smooth) {
      smooth_ = smoothDeformCpu(packed, subs_, makeFitTable(r_.samples), r_.tess, r_.variant);
      timings = smooth_.timings, wallMs = smooth_.wallMs;
    } else if (r_.method == Method::Classic) {
      classic_ = classicFfdCpu(input_, packed, r_.variant);
      timings = classic_.timings, wallMs = classic_.wallMs;
    } else {
      accurateOut_ = accurateFfdCpu(accurate_, packed, r_.variant);
      timings = accurateOut_.timings, wallMs = accurateOut_.wallMs;
    }
    t.deformMs = stageMs(timings, wallMs);
    t.steps = stepsOf(timings);
  }

  Mesh result(const ProgressReporter&) const override {
    if (r_.method == Method::Classic) return applyClassicOutput(input_, classic_);
    return weldPatchVertices(*patchVertices());
  }
  std::optional<PatchVertices> patchVertices() const override {
    if (r_.method == Method::Smooth) return patchVerticesOf(subs_, smooth_);
    if (r_.method == Method::Accurate) return accuratePatchVertices(accurate_, accurateOut_);
    return std::nullopt;
  }
  std::vector<double> patchControlPoints() const override { return smooth_.patches; }
  size_t subTriangles() const override {
    return r_.method == Method::Smooth ? subs_.size() : r_.method == Method::Accurate ? accurate_.count() : 0;
  }
  std::vector<OutputChunk> deviceOutput() const override { return {}; }

 private:
  const Mesh& input_;
  ResolvedOptions r_;
  PreparedMesh prepared_;
  ClipTriangles clip_;
  std::vector<SubTriangle> knotBox_;
  SubTriangleRecords subs_;
  SmoothOutput smooth_;
  ClassicOutput classic_;
  AccurateJob accurate_;
  AccurateOutput accurateOut_;
};

}  // namespace

std::unique_ptr<MethodRun> makeReferenceRun(const Mesh& input, const Lattice& lattice, const ResolvedOptions& r, Timings& t) {
  return std::make_unique<ReferenceRun>(input, lattice, r, t);
}

}  // namespace sffd
