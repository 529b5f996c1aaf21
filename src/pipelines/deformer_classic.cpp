// Deformer, Method::Classic: the mesh's vertices and normals uploaded once, in chunks within the
// device's limits; each deform() uploads the lattice's coefficients and runs kernels/classic into
// per-chunk output buffers that stay on the device (positions, then normals from half the buffer).
#include <algorithm>
#include <chrono>

#include "core/job_budget.h"
#include "core/wall_clock.h"
#include "kernels/classic/classic_ffd.h"
#include "pipelines/deformer_internal.h"
#include "pipelines/device_reals.h"

namespace sffd {
namespace {

class ClassicRun final : public MethodRun {
 public:
  ClassicRun(Backend& backend, const Mesh& input, const Lattice& lattice, const ResolvedOptions& r, const ProgressReporter& progress)
      : B_(backend), input_(input), variant_(r.variant) {
    const DeviceLimits& lim = B_.info().limits;
    const size_t realBytes = variant_.f64 ? 8 : 4;
    PackedLattice packed = packLattice(lattice);
    B_.precompile({classicKernel(packed.params, variant_)});   // while the inputs are packed
    checkJobFits(estimateClassicJob(input, packed, realBytes, &lim), packed, realBytes, &lim, r.memoryLimit,
                 "DeformOptions::memoryLimit");
    params_ = packed.params;
    frame_ = uploadReals(owned_, packed.frame, variant_.f64);
    coeffs_ = uploadReals(owned_, packed.coeffs, variant_.f64);
    const size_t n = input.positions.size();
    const size_t chunk = classicChunkVertices(lim, n, realBytes, r.maxChunkElements);
    std::vector<double> in;
    for (size_t first = 0; first < n; first += chunk) {
      Chunk c;
      c.first = first;
      c.count = std::min(chunk, n - first);
      // One buffer each for the inputs and the outputs: positions, then normals at an aligned offset.
      c.half = alignUp(c.count * 4 * realBytes, lim.storageOffsetAlignment);
      in.assign(2 * c.half / realBytes, 0.0);
      for (size_t i = 0; i < c.count; ++i) {
        const glm::dvec3 &x = input.positions[first + i], &nn = input.normals[first + i];
        double* p = &in[4 * i];
        double* q = &in[c.half / realBytes + 4 * i];
        p[0] = x.x, p[1] = x.y, p[2] = x.z, p[3] = 1;
        q[0] = nn.x, q[1] = nn.y, q[2] = nn.z, q[3] = 0;
      }
      c.in = uploadReals(owned_, in, variant_.f64);
      c.out = makeBuffer(owned_, 2 * c.half);
      chunks_.push_back(c);
      progress("prepare", double(first + c.count) / double(n));
    }
  }

  void deform(const Lattice& lattice, Timings& t, const ProgressReporter& progress) override {
    const auto t0 = std::chrono::steady_clock::now();
    PackedLattice packed = packLattice(lattice);
    std::vector<unsigned char> coeffs = realBytes(packed.coeffs, variant_.f64);
    B_.upload(coeffs_, 0, coeffs.data(), coeffs.size());
    for (size_t i = 0; i < chunks_.size(); ++i) {
      const Chunk& c = chunks_[i];
      const uint64_t bytes = c.count * 4 * (variant_.f64 ? 8 : 4);
      ClassicBindings b{{SFFD_BINDING_LATTICE_COEFFS, coeffs_}, {SFFD_BINDING_LATTICE_FRAME, frame_},
                        {SFFD_BINDING_CLASSIC_IN, c.in, 0, c.half + bytes}, {SFFD_BINDING_CLASSIC_OUT, c.out, 0, c.half + bytes}};
      dispatchClassicFfd(B_, params_, variant_, c.count, b, c.half / (4 * (variant_.f64 ? 8 : 4)));
      progress("deform", double(i + 1) / double(chunks_.size() + 1));
    }
    B_.finish();
    std::vector<DispatchTiming> dispatches = B_.takeTimings();
    t.deformMs = stageMs(dispatches, msSince(t0));
    t.steps = stepsOf(dispatches);
  }

  Mesh result(const ProgressReporter& progress) const override {
    ClassicOutput out;
    const size_t n = input_.positions.size();
    out.positions.resize(4 * n);
    out.normals.resize(4 * n);
    for (size_t i = 0; i < chunks_.size(); ++i) {
      const Chunk& c = chunks_[i];
      progress("download", double(i) / double(chunks_.size()));
      std::vector<double> pos = downloadReals(B_, c.out, 0, 4 * c.count, variant_.f64);
      std::vector<double> nrm = downloadReals(B_, c.out, c.half, 4 * c.count, variant_.f64);
      std::copy(pos.begin(), pos.end(), out.positions.begin() + 4 * c.first);
      std::copy(nrm.begin(), nrm.end(), out.normals.begin() + 4 * c.first);
    }
    return applyClassicOutput(input_, out);
  }

  std::vector<OutputChunk> deviceOutput() const override {
    std::vector<OutputChunk> out;
    for (const Chunk& c : chunks_) out.push_back({c.first, c.count, c.out, 0, 2 * c.half});
    return out;
  }

 private:
  struct Chunk {
    size_t first = 0, count = 0;
    uint64_t half = 0;   // bytes from the positions to the normals
    BufferId in = 0, out = 0;
  };
  Backend& B_;
  OwnedBuffers owned_{B_};   // first: destroyed last, after everything that names its buffers
  const Mesh& input_;   // Deformer::Impl::input, which outlives the run
  KernelVariant variant_;
  gpu::LatticeParams params_;
  BufferId frame_ = 0, coeffs_ = 0;
  std::vector<Chunk> chunks_;
};

}  // namespace

std::unique_ptr<MethodRun> makeClassicRun(Backend& backend, const Mesh& input, const Lattice& lattice, const ResolvedOptions& r,
                                          Timings&, const ProgressReporter& progress) {
  return std::make_unique<ClassicRun>(backend, input, lattice, r, progress);
}

}  // namespace sffd
