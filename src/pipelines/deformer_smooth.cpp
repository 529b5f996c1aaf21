// Deformer, Method::Smooth: DeformSession (deform_session.h) keeps the sub-triangle records and the
// tessellation on the device; the results are downloaded when asked for.
#include "kernels/smooth/smooth_deform.h"
#include "pipelines/deform_session.h"
#include "pipelines/deformer_internal.h"

namespace sffd {
namespace {

class SmoothRun final : public MethodRun {
 public:
  SmoothRun(Backend& backend, const Mesh& input, const Lattice& lattice, const ResolvedOptions& r, Timings& t,
            const ProgressReporter& progress)
      : input_(input) {
    DeformSessionOptions o;
    o.variant = r.variant;
    o.edgeLength = r.edgeLength;
    o.level = r.tess;
    o.samples = r.samples;
    o.knotBoxClip = r.knotBoxClip;
    o.split = r.split;
    o.creaseAngleDeg = r.creaseAngleDeg;
    o.maxChunkSubTriangles = r.maxChunkElements;
    session_ = std::make_unique<DeformSession>(backend, input, lattice, o, progress);
    t.pnMs = session_->timings().pnMs;
    t.clipMs = session_->timings().clipMs;
  }

  void deform(const Lattice& lattice, Timings& t, const ProgressReporter& progress) override {
    const SessionTimings& s = session_->deform(lattice, progress);
    t.deformMs = s.deformMs;
    t.steps = stepsOf(s.dispatches);
  }

  Mesh result(const ProgressReporter&) const override {
    return weldPatchVertices(*patchVertices());
  }

  std::optional<PatchVertices> patchVertices() const override {
    if (!records_) records_ = session_->records();   // fixed by the pre-compute: downloaded once
    PatchVertices p = patchVerticesOf(*records_, session_->output());
    carryAttributes(p, input_);
    return p;
  }

  std::vector<double> patchControlPoints() const override { return session_->output().patches; }
  size_t subTriangles() const override { return session_->subTriangles(); }

  std::vector<OutputChunk> deviceOutput() const override {
    std::vector<OutputChunk> out;
    const uint64_t patchBytes = 2 * uint64_t(tessVertexCount(session_->level())) * 4 * (session_->options().variant.f64 ? 8 : 4);
    for (const DeformSession::Chunk& c : session_->chunks()) out.push_back({c.first, c.count, c.output, 0, c.count * patchBytes});
    return out;
  }

  void precompute(Timings& t) override {
    records_.reset();
    const SessionTimings& s = session_->precompute();
    t.pnMs = s.pnMs;
    t.clipMs = s.clipMs;
    t.wallMs = s.wallMs;
  }

  DeformSession* session() override { return session_.get(); }

 private:
  const Mesh& input_;   // Deformer::Impl::input, which outlives the run
  std::unique_ptr<DeformSession> session_;
  mutable std::optional<SubTriangleRecords> records_;
};

}  // namespace

std::unique_ptr<MethodRun> makeSmoothRun(Backend& backend, const Mesh& input, const Lattice& lattice, const ResolvedOptions& r,
                                         Timings& t, const ProgressReporter& progress) {
  return std::make_unique<SmoothRun>(backend, input, lattice, r, t, progress);
}

}  // namespace sffd
