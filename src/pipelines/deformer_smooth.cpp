// Deformer, Method::Smooth: DeformSession (deform_session.h) keeps the sub-triangle records and the
// tessellation on the device; the results are downloaded when asked for.
#include <algorithm>
#include <memory>
#include <stdexcept>

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
    if (!records_) records_ = session_->preImages();   // fixed by the pre-compute: downloaded once
    PatchVertices p = session_->options().variant.f64 ? downloadPatchVertices<double>() : downloadPatchVertices<float>();
    carryAttributes(p, input_);
    return p;
  }

  // patchVerticesOf(records, session->output()) without its host copies of the whole output (and of the
  // patches, which the vertices do not need): each chunk's tessellation read into one buffer and widened once.
  template <class Real>
  PatchVertices downloadPatchVertices() const {
    const size_t tessReals = 2 * size_t(tessVertexCount(session_->level())) * 4;
    size_t most = 0;
    for (const DeformSession::Chunk& c : session_->chunks()) most = std::max(most, c.count);
    std::unique_ptr<Real[]> tess(new Real[most * tessReals]);   // not zero-filled: each download overwrites it
    PatchVertices p;
    p.level = session_->level();
    for (const DeformSession::Chunk& c : session_->chunks()) {
      if (!c.count) continue;
      if (c.first != p.patchCount()) throw std::logic_error("SmoothRun: chunks out of order");
      session_->backend().download(c.output, 0, tess.get(), c.count * tessReals * sizeof(Real));
      appendPatchVertices(*records_, c.first, c.count, tess.get(), p);
    }
    if (p.patchCount() != records_->size()) throw std::logic_error("SmoothRun: chunks do not cover the sub-triangles");
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
  mutable std::optional<SubTrianglePreImages> records_;
};

}  // namespace

std::unique_ptr<MethodRun> makeSmoothRun(Backend& backend, const Mesh& input, const Lattice& lattice, const ResolvedOptions& r,
                                         Timings& t, const ProgressReporter& progress) {
  return std::make_unique<SmoothRun>(backend, input, lattice, r, t, progress);
}

}  // namespace sffd
