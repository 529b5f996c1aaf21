// Deformer, Method::Smooth: DeformSession (deform_session.h) keeps the sub-triangle records and the
// tessellation on the device; the results are downloaded when asked for.
#include <algorithm>
#include <memory>
#include <stdexcept>

#include <sffd/error.h>

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
    o.creasesApplied = true;   // Deformer applied them to its copy of the mesh (deformer.cpp)
    o.maxChunkSubTriangles = r.maxChunkElements;
    o.once = r.once;
    session_ = std::make_unique<DeformSession>(backend, input, lattice, o, progress);
    t.pnMs = session_->timings().pnMs;
    t.clipMs = session_->timings().clipMs;
  }

  void deform(const Lattice& lattice, Timings& t, const ProgressReporter& progress) override {
    const SessionTimings& s = session_->deform(lattice, progress);
    t.deformMs = s.deformMs;
    t.steps = stepsOf(s.dispatches);
  }

  // The patch vertices welded in slices as each chunk comes from the device: none of them held whole.
  Mesh result(const ProgressReporter&) const override {
    PatchWelder weld(session_->level(), preImages().size());
    weldChunks(weld);
    return weld.finish(input_);
  }

  void streamResult(MeshSink& sink, const ProgressReporter&) const override {
    PatchWelder weld(session_->level(), preImages().size(), &sink);
    sink.begin(PatchWelder::tablesOf(input_));
    weldChunks(weld);
    sink.end();
  }

  // The records' pre-images, downloaded once (fixed by the pre-compute). A one-shot run takes its result
  // once: the records go from the device as soon as read, each chunk's output once welded (forEachChunk).
  const SubTrianglePreImages& preImages() const {
    if (session_->options().once && taken_) throw Error(ErrorKind::Input, "the result was already taken (DeformOptions::once)");
    taken_ = true;
    if (!records_) records_ = session_->preImages();
    if (session_->options().once) session_->releaseRecords();
    return *records_;
  }

  // Each chunk's patch vertices into `weld`, kWeldSlice patches at a time (their carried fields filled).
  void weldChunks(PatchWelder& weld) const {
    PatchVertices slice;
    slice.level = session_->level();
    slice.reserve(kWeldSlice);
    auto add = [&](size_t first, size_t count, const auto* tess) {
      const size_t tessReals = 2 * size_t(tessVertexCount(session_->level())) * 4;
      for (size_t s = 0; s < count; s += kWeldSlice) {
        slice.clear();
        appendPatchVertices(*records_, first + s, std::min(kWeldSlice, count - s), tess + s * tessReals, slice);
        carryPatchAttributes(slice, input_);
        weld.add(slice);
      }
    };
    session_->options().variant.f64 ? forEachChunk<double>(add) : forEachChunk<float>(add);
  }

  std::optional<PatchVertices> patchVertices() const override {
    preImages();
    PatchVertices p;
    p.level = session_->level();
    p.reserve(records_->size());
    auto add = [&](size_t first, size_t count, const auto* tess) {
      if (first != p.patchCount()) throw std::logic_error("SmoothRun: chunks out of order");
      appendPatchVertices(*records_, first, count, tess, p);
    };
    session_->options().variant.f64 ? forEachChunk<double>(add) : forEachChunk<float>(add);
    carryAttributes(p, input_);
    return p;
  }

  // Calls add(first, count, tess) for consecutive runs of sub-triangles in order, each chunk's tessellation
  // read from the device a block of at most kDownloadBytes at a time into one reused buffer (no host copy of
  // the whole output, nor of a whole chunk, nor of the patches, which the vertices do not need).
  template <class Real, class Add>
  void forEachChunk(const Add& add) const {
    const size_t tessReals = 2 * size_t(tessVertexCount(session_->level())) * 4, patchBytes = tessReals * sizeof(Real);
    const size_t block = std::max<size_t>(1, kDownloadBytes / patchBytes / kWeldSlice) * kWeldSlice;   // whole weld slices
    size_t most = 0, done = 0;
    for (const DeformSession::Chunk& c : session_->chunks()) most = std::max(most, std::min(c.count, block));
    std::unique_ptr<Real[]> tess(new Real[most * tessReals]);   // not zero-filled: each download overwrites it
    adviseHugePages(tess.get(), most * tessReals * sizeof(Real));
    for (size_t ci = 0; ci < session_->chunks().size(); ++ci) {
      const DeformSession::Chunk& c = session_->chunks()[ci];
      if (!c.count) continue;
      if (c.first != done) throw std::logic_error("SmoothRun: chunks out of order");
      for (size_t b = 0; b < c.count; b += block) {
        const size_t n = std::min(block, c.count - b);
        session_->backend().download(c.output, b * patchBytes, tess.get(), n * patchBytes);
        add(c.first + b, n, static_cast<const Real*>(tess.get()));
      }
      done += c.count;
      if (session_->options().once) session_->releaseOutput(ci);
    }
    if (done != records_->size()) throw std::logic_error("SmoothRun: chunks do not cover the sub-triangles");
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
  static constexpr size_t kWeldSlice = 64;   // patches a slice: their vertices in double fit the cache
  static constexpr size_t kDownloadBytes = size_t(16) << 20;   // a download's block (rounded to whole slices)
  const Mesh& input_;   // Deformer::Impl::input, which outlives the run
  std::unique_ptr<DeformSession> session_;
  mutable std::optional<SubTrianglePreImages> records_;
  mutable bool taken_ = false;   // a result was taken (DeformOptions::once allows one)
};

}  // namespace

std::unique_ptr<MethodRun> makeSmoothRun(Backend& backend, const Mesh& input, const Lattice& lattice, const ResolvedOptions& r,
                                         Timings& t, const ProgressReporter& progress) {
  return std::make_unique<SmoothRun>(backend, input, lattice, r, t, progress);
}

}  // namespace sffd
