// Deformer, Method::Accurate: knot-box clipping on the host (once), the sub-triangles' flat corners
// uploaded once in chunks; each deform() uploads the lattice's coefficients and runs kernels/accurate
// (samples, control points, tessellation) into per-chunk output buffers that stay on the device
// (per patch nv positions, all of the chunk's, then the normals from half the buffer, then the
// chunk's corners: one storage range for the kernel, layout.h). A one-shot run (DeformOptions::once)
// keeps no chunk on the device: its result runs each chunk in one reused buffer as the weld takes it.
#include <algorithm>
#include <chrono>
#include <memory>
#include <stdexcept>

#include <sffd/error.h>

#include "core/job_budget.h"
#include "core/wall_clock.h"
#include "kernels/accurate/accurate_patches.h"
#include "kernels/clip/knot_box_clip.h"
#include "pipelines/deformer_internal.h"
#include "pipelines/device_reals.h"
#include "pipelines/stream_budget.h"

namespace sffd {
namespace {

class AccurateRun final : public MethodRun {
 public:
  AccurateRun(Backend& backend, const Mesh& input, const Lattice& lattice, const ResolvedOptions& r, Timings& t,
              const ProgressReporter& progress, uint64_t heldBytes, std::optional<JobEstimate>& estimate,
              std::optional<JobEstimate>& whole)
      : B_(backend), input_(input), timings_(t), variant_(r.variant), once_(r.once) {
    const auto t0 = std::chrono::steady_clock::now();
    PackedLattice packed = packLattice(lattice);
    progress("clip", 0);
    job_ = makeAccurateJob(input, lattice, clipAgainstKnotBoxes(input, lattice), r.tess);
    t.clipMs = msSince(t0);
    progress("prepare", 0.5);

    const DeviceLimits& lim = B_.info().limits;
    const size_t realBytes = variant_.f64 ? 8 : 4;
    frame_ = accurateFrame(packed.frame, job_.degree, job_.level);   // the frame, then the patch tables
    params_ = accurateParamsFor(packed, variant_.f64, frame_);
    B_.precompile({accurateKernel(params_, variant_)});
    const size_t ns = job_.count(), nv = size_t(tessVertexCount(job_.level)), m = size_t(triangleControlPoints(job_.degree));
    size_t chunk = accurateChunkPatches(lim, job_, realBytes, r.maxChunkElements);
    // One-shot: chunks of at most kOnceChunkBytes, so that the one chunk alive at a time stays small also
    // where a binding is large (the CPU device's is its whole memory).
    if (once_) chunk = std::max<size_t>(1, std::min(chunk, size_t(kOnceChunkBytes / ((2 * nv + SFFD_ACC_CORNER_STRIDE) * 4 * realBytes))));
    // Scratch of one chunk, shared by all: the samples, then the control points.
    patchesAt_ = uint32_t(std::min(chunk, ns) * m);
    const uint64_t scratchBytes = 2 * uint64_t(patchesAt_) * 4 * realBytes;
    for (size_t first = 0; first < ns; first += chunk) {
      Chunk c;
      c.first = first;
      c.count = std::min(chunk, ns - first);
      c.half = alignUp(c.count * nv * 4 * realBytes, lim.storageOffsetAlignment);
      chunks_.push_back(c);
    }

    // Host memory. The whole job: kernel outputs (4 doubles a value), the patch vertices (9 doubles a
    // vertex) and the welded mesh (about 8 doubles and a hash entry a vertex), per tessellation vertex.
    JobEstimate all;
    all.hostBytes = ns * (nv * (8 + 9 + 8) * 8 + nv * 64 + m * 32 + tessTriangleCount(job_.level) * 12);
    whole.reset();
    if (once_) {
      // One-shot: what stays alive as the chunks run one at a time (stream_budget.h); result() holds the
      // welded mesh, so it is checked against the whole job's.
      AccurateStream s{&job_, realBytes, chunk, 0, frame_.reals.size() * sizeof(double)};
      s.deviceBytes = (packed.coeffs.size() + frame_.reals.size()) * realBytes + scratchBytes +
                      (chunks_.empty() ? 0 : chunkBytes(chunks_.front()));
      estimate = estimateStreamedAccurateJob(input, s, B_.info(), heldBytes);
      whole = all;
    } else {
      estimate = all;
    }
    checkJobFits(*estimate, packed, realBytes, &lim, r.memoryLimit, "DeformOptions::memoryLimit");

    frameBuffer_ = uploadReals(owned_, frame_.reals, variant_.f64);
    coeffs_ = uploadReals(owned_, packed.coeffs, variant_.f64);
    if (ns) scratch_ = makeBuffer(owned_, scratchBytes);
    for (Chunk& c : chunks_) {
      if (once_) continue;   // made as the result is taken (runChunk)
      c.out = makeBuffer(owned_, chunkBytes(c));
      uploadCorners(c);
      progress("prepare", 0.5 + 0.5 * double(c.first + c.count) / double(ns));
    }
  }

  void deform(const Lattice& lattice, Timings& t, const ProgressReporter& progress) override {
    const auto t0 = std::chrono::steady_clock::now();
    PackedLattice packed = packLattice(lattice);
    std::vector<unsigned char> coeffs = realBytes(packed.coeffs, variant_.f64);
    B_.upload(coeffs_, 0, coeffs.data(), coeffs.size());
    params_ = accurateParamsFor(packed, variant_.f64, frame_);   // the coefficients may be inline
    if (once_) return;   // the kernels run chunk by chunk as the result is taken (forEachChunk)
    for (size_t i = 0; i < chunks_.size(); ++i) {
      runChunk(chunks_[i]);
      progress("deform", double(i + 1) / double(chunks_.size() + 1));
    }
    B_.finish();
    std::vector<DispatchTiming> dispatches = B_.takeTimings();
    t.deformMs = stageMs(dispatches, msSince(t0));
    t.steps = stepsOf(dispatches);
  }

  // The patch vertices welded in slices as each chunk comes from the device: none of them held whole.
  Mesh result(const ProgressReporter&) const override {
    PatchWelder weld(job_.level, job_.count());
    weldChunks(weld);
    return weld.finish(input_);
  }

  void streamResult(MeshSink& sink, const ProgressReporter&) const override {
    PatchWelder weld(job_.level, job_.count(), &sink);
    weld.forgetPassedLocations(input_);
    sink.begin(PatchWelder::tablesOf(input_));
    weldChunks(weld);
    sink.end();
  }

  // Each chunk's patch vertices into `weld`, kWeldSlice patches at a time (their carried fields filled).
  void weldChunks(PatchWelder& weld) const {
    PatchVertices slice;
    slice.level = job_.level;
    slice.reserve(kWeldSlice);
    auto add = [&](size_t first, size_t count, const auto* pos, const auto* nrm) {
      const auto t0 = std::chrono::steady_clock::now();
      const size_t reals = size_t(tessVertexCount(job_.level)) * 4;
      for (size_t s = 0; s < count; s += kWeldSlice) {
        writeAccuratePatchVertices(job_, first + s, std::min(kWeldSlice, count - s), pos + s * reals, nrm + s * reals, 0, slice);
        carryPatchAttributes(slice, input_);
        weld.add(slice);
      }
      timings_.weldMs += msSince(t0);
    };
    variant_.f64 ? forEachChunk<double>(add) : forEachChunk<float>(add);
  }

  std::optional<PatchVertices> patchVertices() const override {
    PatchVertices p;
    p.level = job_.level;
    p.reserve(job_.count());
    auto add = [&](size_t first, size_t count, const auto* pos, const auto* nrm) {
      if (first != p.patchCount()) throw std::logic_error("AccurateRun: chunks out of order");
      writeAccuratePatchVertices(job_, first, count, pos, nrm, p.patchCount(), p);
    };
    variant_.f64 ? forEachChunk<double>(add) : forEachChunk<float>(add);
    carryAttributes(p, input_);
    return p;
  }

  // Calls add(first, count, positions, normals) for consecutive runs of patches in order, each chunk read
  // from the device a block of at most kAccurateDownloadBytes at a time into one reused buffer each (no host copy
  // of the whole output, nor of a whole chunk).
  template <class Real, class Add>
  void forEachChunk(const Add& add) const {
    const size_t nv = size_t(tessVertexCount(job_.level)), patchBytes = nv * 4 * sizeof(Real);
    const size_t block = accurateBlockPatches(patchBytes);
    size_t most = 0, done = 0;
    for (const Chunk& c : chunks_) most = std::max(most, std::min(c.count, block));
    std::unique_ptr<Real[]> pos(new Real[most * nv * 4]), nrm(new Real[most * nv * 4]);   // not zero-filled: overwritten
    adviseHugePages(pos.get(), most * patchBytes);
    adviseHugePages(nrm.get(), most * patchBytes);
    BufferId shared = 0;   // once: every chunk's, in turn (the first chunk is the largest)
    if (once_ && !chunks_.empty()) shared = makeBuffer(owned_, chunkBytes(chunks_.front()));
    for (Chunk& c : chunks_) {
      if (!c.count) continue;
      if (c.first != done) throw std::logic_error("AccurateRun: chunks out of order");
      if (once_) c.out = shared, uploadCorners(c), runChunk(c);
      if (!c.out) throw Error(ErrorKind::Input, "the outputs were freed after one deformation (DeformOptions::once)");
      for (size_t b = 0; b < c.count; b += block) {
        const size_t n = std::min(block, c.count - b);
        B_.download(c.out, b * patchBytes, pos.get(), n * patchBytes);
        B_.download(c.out, c.half + b * patchBytes, nrm.get(), n * patchBytes);
        add(c.first + b, n, static_cast<const Real*>(pos.get()), static_cast<const Real*>(nrm.get()));
      }
      done += c.count;
      if (once_) c.out = 0;   // the shared buffer goes below
    }
    if (shared) {
      B_.destroyBuffer(shared);
      owned_.ids.erase(std::find(owned_.ids.begin(), owned_.ids.end(), shared));
      std::vector<DispatchTiming> dispatches = B_.takeTimings();
      timings_.deformMs = stageMs(dispatches, 0);
      timings_.steps = stepsOf(dispatches);
    }
    if (done != job_.count()) throw std::logic_error("AccurateRun: chunks do not cover the sub-triangles");
  }

  size_t subTriangles() const override { return job_.count(); }

  std::vector<OutputChunk> deviceOutput() const override {
    std::vector<OutputChunk> out;
    if (once_) return out;   // no chunk is kept on the device
    for (const Chunk& c : chunks_) out.push_back({c.first, c.count, c.out, 0, 2 * c.half});
    return out;
  }

 private:
  static constexpr size_t kWeldSlice = kWeldSlicePatches;
  struct Chunk {
    size_t first = 0, count = 0;
    uint64_t half = 0;   // bytes from the positions to the normals, and from the normals to the corners
    BufferId out = 0;
  };

  // Chunk c's bytes on the device: positions, normals, corners.
  uint64_t chunkBytes(const Chunk& c) const { return 2 * c.half + c.count * 4 * SFFD_ACC_CORNER_STRIDE * (variant_.f64 ? 8 : 4); }

  // Chunk c's sub-triangle corners into its buffer, after the normals.
  void uploadCorners(const Chunk& c) const {
    const size_t cw = 4 * SFFD_ACC_CORNER_STRIDE;
    const std::vector<unsigned char> corners = sffd::realBytes(
        std::vector<double>(job_.corners.begin() + cw * c.first, job_.corners.begin() + cw * (c.first + c.count)), variant_.f64);
    B_.upload(c.out, 2 * c.half, corners.data(), corners.size());
  }

  // The kernels of chunk c (recorded; they run at the next finish or download).
  void runChunk(const Chunk& c) const {
    const uint32_t normalsAt = uint32_t(c.half / (variant_.f64 ? 32 : 16));
    AccurateBindings b{{SFFD_BINDING_LATTICE_COEFFS, coeffs_}, {SFFD_BINDING_LATTICE_FRAME, frameBuffer_},
                       {SFFD_BINDING_ACC_CHUNK, c.out}, {SFFD_BINDING_ACC_SCRATCH, scratch_},
                       normalsAt, 2 * normalsAt, patchesAt_};
    dispatchAccurateChunk(B_, params_, variant_, job_, c.count, b);
  }
  Backend& B_;
  mutable OwnedBuffers owned_{B_};   // first: destroyed last, after everything that names its buffers
  const Mesh& input_;   // Deformer::Impl::input, which outlives the run
  Timings& timings_;    // Deformer::Impl::timings: a one-shot run's kernels run when its result is taken
  KernelVariant variant_;
  AccurateJob job_;
  gpu::AccurateParams params_;   // the lattice's and tables' part (accurateParamsFor)
  AccurateFrame frame_;
  BufferId frameBuffer_ = 0, coeffs_ = 0, scratch_ = 0;
  uint32_t patchesAt_ = 0;   // the first control point in scratch_, after the samples
  mutable std::vector<Chunk> chunks_;   // mutable: a one-shot run frees their buffers as they are read
  bool once_ = false;   // one deform() and one result, which the Deformer enforces for every method
};

}  // namespace

std::unique_ptr<MethodRun> makeAccurateRun(Backend& backend, const Mesh& input, const Lattice& lattice, const ResolvedOptions& r,
                                           Timings& t, const ProgressReporter& progress, uint64_t heldBytes,
                                           std::optional<JobEstimate>& estimate, std::optional<JobEstimate>& whole) {
  return std::make_unique<AccurateRun>(backend, input, lattice, r, t, progress, heldBytes, estimate, whole);
}

}  // namespace sffd
