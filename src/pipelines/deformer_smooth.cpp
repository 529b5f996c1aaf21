// Deformer, Method::Smooth: DeformSession (deform_session.h) keeps the sub-triangle records and the
// tessellation on the device; the results are downloaded when asked for. A one-shot Deformer's session
// (DeformSession::streamed) runs only when its result is taken, a chunk at a time, each welded as it comes.
#include <algorithm>
#include <chrono>
#include <memory>
#include <stdexcept>

#include <sffd/error.h>

#include "core/huge_pages.h"
#include "core/wall_clock.h"
#include "kernels/smooth/smooth_deform.h"
#include "pipelines/deform_session.h"
#include "pipelines/deformer_internal.h"

namespace sffd {
namespace {

class SmoothRun final : public MethodRun {
 public:
  SmoothRun(Backend& backend, const Mesh& input, const Lattice& lattice, const ResolvedOptions& r, Timings& t,
            const ProgressReporter& progress)
      : input_(input), timings_(t) {
    session_ = std::make_unique<DeformSession>(backend, input, lattice, sessionOptionsOf(r), progress);
    slice_.level = r.tess;
    slice_.reserve(kWeldSlice);
    t.pnMs = session_->timings().pnMs;
    t.clipMs = session_->timings().clipMs;
  }

  void deform(const Lattice& lattice, Timings& t, const ProgressReporter& progress) override {
    const SessionTimings& s = session_->deform(lattice, progress);
    t.deformMs = s.deformMs;
    t.steps = stepsOf(s.dispatches);
  }

  // The patch vertices welded in slices as each chunk comes from the device: none of them held whole.
  Mesh result(const ProgressReporter& progress) const override {
    if (session_->streamed()) {
      PatchWelder weld(session_->level(), 0);
      streamChunks([&](const DeformSession::Chunk& c, const SubTrianglePreImages& pre) { weldChunk(weld, c, pre, 0); }, progress);
      return weld.finish(input_);
    }
    PatchWelder weld(session_->level(), preImages().size());
    weldChunks(weld);
    return weld.finish(input_);
  }

  void streamResult(MeshSink& sink, const ProgressReporter& progress) const override {
    if (session_->streamed()) {   // a chunk at a time from the mesh, and the weld keeps only what later chunks reach
      PatchWelder weld(session_->level(), 0, &sink);
      weld.forgetPassedLocations(input_);
      sink.begin(PatchWelder::tablesOf(input_));
      streamChunks([&](const DeformSession::Chunk& c, const SubTrianglePreImages& pre) { weldChunk(weld, c, pre, 0); }, progress);
      sink.end();
      return;
    }
    PatchWelder weld(session_->level(), preImages().size(), &sink);
    weld.forgetPassedLocations(input_);
    sink.begin(PatchWelder::tablesOf(input_));
    weldChunks(weld);
    sink.end();
  }

  // The records' pre-images, downloaded once (fixed by the pre-compute; a one-shot session streams instead).
  const SubTrianglePreImages& preImages() const {
    if (!records_) records_ = session_->preImages();
    return *records_;
  }

  // A streamed session's run (DeformSession::streamChunks), its timings the Deformer's.
  void streamChunks(const DeformSession::ChunkReader& read, const StageProgress& progress) const {
    const SessionTimings& s = session_->streamChunks(read, progress);
    timings_.pnMs = s.pnMs;
    timings_.clipMs = s.clipMs;
    timings_.deformMs = s.deformMs;
    timings_.steps = stepsOf(s.dispatches);
  }

  // Chunk c's patch vertices into `weld`, kWeldSlice patches at a time (their carried fields filled); the
  // pre-image of c's first sub-triangle is pre's `preFirst`.
  void weldChunk(PatchWelder& weld, const DeformSession::Chunk& c, const SubTrianglePreImages& pre, size_t preFirst) const {
    auto add = [&](size_t first, size_t count, const auto* tess) {
      const auto t0 = std::chrono::steady_clock::now();
      const size_t tessReals = 2 * size_t(tessVertexCount(session_->level())) * 4;
      for (size_t s = 0; s < count; s += kWeldSlice) {
        writePatchVertices(pre, preFirst + first + s, std::min(kWeldSlice, count - s), tess + s * tessReals, 0, slice_);
        carryPatchAttributes(slice_, input_);
        weld.add(slice_);
      }
      timings_.weldMs += msSince(t0);
    };
    session_->options().variant.f64 ? forEachBlock(c, downloadD_, add) : forEachBlock(c, downloadF_, add);
  }

  // Each chunk's patch vertices into `weld` (the session not streamed).
  void weldChunks(PatchWelder& weld) const {
    for (size_t ci = 0; ci < session_->chunks().size(); ++ci) {
      const DeformSession::Chunk& c = session_->chunks()[ci];
      weldChunk(weld, c, *records_, c.first);
    }
  }

  std::optional<PatchVertices> patchVertices() const override {
    PatchVertices p;
    p.level = session_->level();
    auto append = [&](const DeformSession::Chunk& c, const SubTrianglePreImages& pre, size_t preFirst) {
      if (c.first != p.patchCount()) throw std::logic_error("SmoothRun: chunks out of order");
      auto add = [&](size_t first, size_t count, const auto* tess) { writePatchVertices(pre, preFirst + first, count, tess, p.patchCount(), p); };
      session_->options().variant.f64 ? forEachBlock(c, downloadD_, add) : forEachBlock(c, downloadF_, add);
    };
    if (session_->streamed()) {
      streamChunks([&](const DeformSession::Chunk& c, const SubTrianglePreImages& pre) { append(c, pre, 0); }, {});
    } else {
      preImages();
      p.reserve(records_->size());
      for (size_t ci = 0; ci < session_->chunks().size(); ++ci) {
        append(session_->chunks()[ci], *records_, session_->chunks()[ci].first);
      }
    }
    carryAttributes(p, input_);
    return p;
  }

  // A download buffer kept between chunks (not zero-filled: each download overwrites it).
  template <class Real>
  struct Download {
    std::unique_ptr<Real[]> data;
    size_t size = 0;
    Real* room(size_t n) {
      if (n > size) data.reset(new Real[n]), size = n, adviseHugePages(data.get(), n * sizeof(Real));
      return data.get();
    }
  };

  // Calls add(first, count, tess) for consecutive blocks of chunk c's sub-triangles (first counted from
  // c's), each block's tessellation read from the device into `buffer`, at most kDownloadBytes at a time
  // (no host copy of the whole output, nor of a whole chunk, nor of the patches, which the vertices do not need).
  template <class Real, class Add>
  void forEachBlock(const DeformSession::Chunk& c, Download<Real>& buffer, const Add& add) const {
    if (!c.count) return;
    const size_t tessReals = 2 * size_t(tessVertexCount(session_->level())) * 4, patchBytes = tessReals * sizeof(Real);
    const size_t block = std::max<size_t>(1, kDownloadBytes / patchBytes / kWeldSlice) * kWeldSlice;   // whole weld slices
    Real* tess = buffer.room(std::min(block, c.count) * tessReals);
    for (size_t b = 0; b < c.count; b += block) {
      const size_t n = std::min(block, c.count - b);
      session_->backend().download(c.output, b * patchBytes, tess, n * patchBytes);
      add(b, n, static_cast<const Real*>(tess));
    }
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
  static constexpr size_t kWeldSlice = kWeldSlicePatches, kDownloadBytes = kSmoothDownloadBytes;
  const Mesh& input_;   // Deformer::Impl::input, which outlives the run
  Timings& timings_;    // Deformer::Impl::timings: a streamed session's kernels run when its result is taken
  std::unique_ptr<DeformSession> session_;
  mutable PatchVertices slice_;   // a weld slice, its room kept
  mutable Download<float> downloadF_;
  mutable Download<double> downloadD_;
  mutable std::optional<SubTrianglePreImages> records_;
};

}  // namespace

DeformSessionOptions sessionOptionsOf(const ResolvedOptions& r) {
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
  return o;
}

std::unique_ptr<MethodRun> makeSmoothRun(Backend& backend, const Mesh& input, const Lattice& lattice, const ResolvedOptions& r,
                                         Timings& t, const ProgressReporter& progress) {
  return std::make_unique<SmoothRun>(backend, input, lattice, r, t, progress);
}

}  // namespace sffd
