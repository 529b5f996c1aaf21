// Deformer, Method::Accurate: knot-box clipping on the host (once), the sub-triangles' flat corners
// uploaded once in chunks; each deform() uploads the lattice's coefficients and runs kernels/accurate
// (samples, control points, tessellation) into per-chunk output buffers that stay on the device
// (per patch nv positions, all of the chunk's, then the normals from half the buffer).
#include <algorithm>
#include <chrono>

#include "core/job_budget.h"
#include "core/wall_clock.h"
#include "kernels/accurate/accurate_patches.h"
#include "kernels/clip/knot_box_clip.h"
#include "pipelines/deformer_internal.h"
#include "pipelines/device_reals.h"

namespace sffd {
namespace {

class AccurateRun final : public MethodRun {
 public:
  AccurateRun(Backend& backend, const Mesh& input, const Lattice& lattice, const ResolvedOptions& r, Timings& t,
              const ProgressReporter& progress)
      : B_(backend), input_(input), variant_(r.variant) {
    const auto t0 = std::chrono::steady_clock::now();
    progress("clip", 0);
    job_ = makeAccurateJob(input, lattice, clipAgainstKnotBoxes(input, lattice), r.tess);
    t.clipMs = msSince(t0);
    progress("prepare", 0.5);

    const DeviceLimits& lim = B_.info().limits;
    const size_t realBytes = variant_.f64 ? 8 : 4;
    PackedLattice packed = packLattice(lattice);
    // Host memory: kernel outputs (4 doubles a value), the patch vertices (9 doubles a vertex) and the
    // welded mesh (about 8 doubles and a hash entry a vertex), per tessellation vertex.
    const uint64_t nv = uint64_t(tessVertexCount(job_.level)), m = uint64_t(triangleControlPoints(job_.degree));
    JobEstimate est;
    est.hostBytes = job_.count() * (nv * (8 + 9 + 8) * 8 + nv * 64 + m * 32 + tessTriangleCount(job_.level) * 12);
    checkJobFits(est, packed, realBytes, &lim, r.memoryLimit, "DeformOptions::memoryLimit");

    params_ = packed.params;
    frame_ = uploadReals(owned_, packed.frame, variant_.f64);
    coeffs_ = uploadReals(owned_, packed.coeffs, variant_.f64);
    matrix_ = uploadReals(owned_, accurateKernelMatrix(job_.degree), variant_.f64);
    basis_ = uploadReals(owned_, tessellationBasis(job_.degree, job_.level), variant_.f64);
    const size_t ns = job_.count(), chunk = accurateChunkPatches(lim, job_, realBytes, r.maxChunkElements);
    if (ns) {
      // Scratch of one chunk, shared by all: the samples and the control points.
      samples_ = makeBuffer(owned_, std::min(chunk, ns) * m * 4 * realBytes);
      patches_ = makeBuffer(owned_, std::min(chunk, ns) * m * 4 * realBytes);
    }
    const size_t cw = 4 * SFFD_ACC_CORNER_STRIDE;
    for (size_t first = 0; first < ns; first += chunk) {
      Chunk c;
      c.first = first;
      c.count = std::min(chunk, ns - first);
      c.half = alignUp(c.count * nv * 4 * realBytes, lim.storageOffsetAlignment);
      c.corners = uploadReals(owned_, std::vector<double>(job_.corners.begin() + cw * first, job_.corners.begin() + cw * (first + c.count)),
                              variant_.f64);
      c.out = makeBuffer(owned_, 2 * c.half);
      chunks_.push_back(c);
      progress("prepare", 0.5 + 0.5 * double(first + c.count) / double(ns));
    }
  }

  void deform(const Lattice& lattice, Timings& t, const ProgressReporter& progress) override {
    const auto t0 = std::chrono::steady_clock::now();
    PackedLattice packed = packLattice(lattice);
    std::vector<unsigned char> coeffs = realBytes(packed.coeffs, variant_.f64);
    B_.upload(coeffs_, 0, coeffs.data(), coeffs.size());
    const uint64_t realBytes = variant_.f64 ? 8 : 4, nv = uint64_t(tessVertexCount(job_.level));
    for (size_t i = 0; i < chunks_.size(); ++i) {
      const Chunk& c = chunks_[i];
      const uint64_t bytes = c.count * nv * 4 * realBytes;
      AccurateBindings b{{SFFD_BINDING_LATTICE_COEFFS, coeffs_}, {SFFD_BINDING_LATTICE_FRAME, frame_},
                         {SFFD_BINDING_ACC_MATRIX, matrix_},      {SFFD_BINDING_ACC_TESS_BASIS, basis_},
                         {SFFD_BINDING_ACC_CORNERS, c.corners},   {SFFD_BINDING_ACC_PATCHES, patches_},
                         {SFFD_BINDING_ACC_POSITIONS, c.out, 0, bytes}, {SFFD_BINDING_ACC_NORMALS, c.out, c.half, bytes},
                         {SFFD_BINDING_ACC_SAMPLES, samples_}};
      dispatchAccurateChunk(B_, params_, variant_, job_, c.count, b);
      progress("deform", double(i + 1) / double(chunks_.size() + 1));
    }
    B_.finish();
    std::vector<DispatchTiming> dispatches = B_.takeTimings();
    t.deformMs = stageMs(dispatches, msSince(t0));
    t.steps = stepsOf(dispatches);
  }

  Mesh result(const ProgressReporter&) const override {
    return weldPatchVertices(*patchVertices());
  }

  std::optional<PatchVertices> patchVertices() const override {
    AccurateOutput out;
    const size_t nv = size_t(tessVertexCount(job_.level));
    out.positions.resize(job_.count() * nv * 4);
    out.normals.resize(job_.count() * nv * 4);
    for (const Chunk& c : chunks_) {
      std::vector<double> pos = downloadReals(B_, c.out, 0, c.count * nv * 4, variant_.f64);
      std::vector<double> nrm = downloadReals(B_, c.out, c.half, c.count * nv * 4, variant_.f64);
      std::copy(pos.begin(), pos.end(), out.positions.begin() + c.first * nv * 4);
      std::copy(nrm.begin(), nrm.end(), out.normals.begin() + c.first * nv * 4);
    }
    PatchVertices p = accuratePatchVertices(job_, out);
    carryAttributes(p, input_);
    return p;
  }

  size_t subTriangles() const override { return job_.count(); }

  std::vector<OutputChunk> deviceOutput() const override {
    std::vector<OutputChunk> out;
    for (const Chunk& c : chunks_) out.push_back({c.first, c.count, c.out, 0, 2 * c.half});
    return out;
  }

 private:
  struct Chunk {
    size_t first = 0, count = 0;
    uint64_t half = 0;   // bytes from the positions to the normals
    BufferId corners = 0, out = 0;
  };
  Backend& B_;
  OwnedBuffers owned_{B_};   // first: destroyed last, after everything that names its buffers
  const Mesh& input_;   // Deformer::Impl::input, which outlives the run
  KernelVariant variant_;
  AccurateJob job_;
  gpu::LatticeParams params_;
  BufferId frame_ = 0, coeffs_ = 0, matrix_ = 0, basis_ = 0, samples_ = 0, patches_ = 0;
  std::vector<Chunk> chunks_;
};

}  // namespace

std::unique_ptr<MethodRun> makeAccurateRun(Backend& backend, const Mesh& input, const Lattice& lattice, const ResolvedOptions& r,
                                           Timings& t, const ProgressReporter& progress) {
  return std::make_unique<AccurateRun>(backend, input, lattice, r, t, progress);
}

}  // namespace sffd
