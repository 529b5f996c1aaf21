// What sffd::Deformer (<sffd/deformer.h>) is made of, for the library's own files and the
// command-line tool's analysis (pre-images, sub-triangle records). Not part of the public API.
//
// deformer.cpp resolves the options and picks one MethodRun per method, each in its own file:
//   deformer_smooth.cpp    DeformSession (PN triangles, clipping, deform; all on the device)
//   deformer_classic.cpp   kernels/classic: vertices and normals, in per-chunk device buffers
//   deformer_accurate.cpp  knot-box clipping (host), then kernels/accurate, in per-chunk device buffers
#pragma once
#include <algorithm>
#include <memory>
#include <optional>
#include <vector>

#include <sffd/deformer.h>

#include "core/backend.h"
#include "core/job_budget.h"
#include "pipelines/local_frame.h"
#include "pipelines/patch_output.h"

namespace sffd {

class DeformSession;

// Tells DeformOptions::progress how far the current call is (`fraction` of it, 0..1). When the
// callback answers false, the device's queued work is finished and an Error of kind Cancelled thrown.
class ProgressReporter {
 public:
  ProgressReporter(const ProgressCallback& callback, Backend* backend) : callback_(callback), backend_(backend) {}
  void operator()(const char* stage, double fraction) const;
  // `fraction` of [lo, hi] of the call: for a step that is part of a larger one.
  ProgressReporter part(double lo, double hi) const;

 private:
  const ProgressCallback& callback_;
  Backend* backend_;
  double lo_ = 0, hi_ = 1;
};

// The smooth and accurate results are welded kWeldSlicePatches patches at a time (their vertices in double
// fit the cache); the smooth run reads its tessellation from the device kSmoothDownloadBytes at a time
// (rounded to whole slices).
constexpr size_t kWeldSlicePatches = 64;
constexpr size_t kSmoothDownloadBytes = size_t(4) << 20;
// The accurate run reads a chunk kAccurateDownloadBytes at a time (rounded to whole slices); a one-shot run
// (DeformOptions::once) runs chunks of at most kOnceChunkBytes (positions, normals and corners), one at a
// time in one buffer: what its memory estimate counts (stream_budget.h).
constexpr size_t kAccurateDownloadBytes = size_t(16) << 20;
constexpr uint64_t kOnceChunkBytes = uint64_t(32) << 20;
// The patches of one accurate download block, of `patchBytes` positions and as many normals: whole slices.
inline size_t accurateBlockPatches(size_t patchBytes) {
  return std::max<size_t>(1, kAccurateDownloadBytes / (2 * patchBytes) / kWeldSlicePatches) * kWeldSlicePatches;
}

// DeformOptions with every default resolved, as the method runs use them.
struct ResolvedOptions {
  Method method = Method::Smooth;
  KernelVariant variant;
  double edgeLength = 0;   // > 0
  int tess = 10;
  int samples = 3;         // >= 3
  bool knotBoxClip = false;
  bool split = false;
  double creaseAngleDeg = kCreaseAngleAuto;
  uint64_t memoryLimit = 0;
  size_t maxChunkElements = 0;
  bool once = false;
};

// The DeformSession options of a smooth run (deformer_smooth.cpp): what its memory estimate reads too.
struct DeformSessionOptions;
DeformSessionOptions sessionOptionsOf(const ResolvedOptions& options);

// One method's work on the device: the constructor prepares, deform() runs for a lattice.
class MethodRun {
 public:
  virtual ~MethodRun() = default;
  // Uploads the lattice's control points and runs the kernels; fills deformMs and steps.
  virtual void deform(const Lattice& lattice, Timings& timings, const ProgressReporter& progress) = 0;
  virtual Mesh result(const ProgressReporter& progress) const = 0;
  // result() handed to `sink`, begin() to end() (Deformer::streamResult); by default in one piece.
  virtual void streamResult(MeshSink& sink, const ProgressReporter& progress) const;
  virtual std::vector<OutputChunk> deviceOutput() const = 0;
  virtual size_t subTriangles() const { return 0; }
  // Smooth: the patches' control points (deformer.h); others: empty.
  virtual std::vector<double> patchControlPoints() const { return {}; }
  // Smooth and Accurate: the tessellation with each vertex's pre-image in Impl::input.
  virtual std::optional<PatchVertices> patchVertices() const { return std::nullopt; }
  // Smooth: runs the pre-compute again (PN triangles, clipping), filling pnMs and clipMs: what
  // `sffd bench` times. Others: nothing.
  virtual void precompute(Timings&) {}
  // Smooth on a device: the session whose buffers the viewer draws; others: null.
  virtual DeformSession* session() { return nullptr; }
};

std::unique_ptr<MethodRun> makeSmoothRun(Backend& backend, const Mesh& input, const Lattice& lattice,
                                         const ResolvedOptions& options, Timings& timings, const ProgressReporter& progress);
std::unique_ptr<MethodRun> makeClassicRun(Backend& backend, const Mesh& input, const Lattice& lattice,
                                          const ResolvedOptions& options, Timings& timings, const ProgressReporter& progress);
// The accurate run checks its own memory estimate (it needs the clipping's sub-triangles) and leaves it in
// `estimate` (a one-shot run's from what stays alive, stream_budget.h, the whole job's in `whole`);
// `heldBytes`: what its caller holds throughout (the other copies of the mesh, the lattice's bytes).
std::unique_ptr<MethodRun> makeAccurateRun(Backend& backend, const Mesh& input, const Lattice& lattice,
                                           const ResolvedOptions& options, Timings& timings, const ProgressReporter& progress,
                                           uint64_t heldBytes, std::optional<JobEstimate>& estimate,
                                           std::optional<JobEstimate>& whole);

// A run on inputs in `frame` (local_frame.h) whose results come out in world coordinates
// (deviceOutput() stays local).
std::unique_ptr<MethodRun> inLocalFrame(std::unique_ptr<MethodRun> local, const LocalFrame& frame);

struct Deformer::Impl {
  Device::Impl* device = nullptr;   // Device::of(device): the Device, wherever it was moved since
  Backend& backend() const { return Device::of(device).backend(); }
  DeformOptions options;
  ResolvedOptions resolved;
  Mesh input;           // the mesh as the method uses it (smooth: creases applied); pre-images index its triangles
  Lattice structure;    // the lattice the Deformer was made for (its structure is what deform() checks)
  LocalFrame frame;     // latticeLocalFrame(structure): the devices compute in it
  // `input` in that frame when it is not the world's (else empty): the runs keep a reference to the
  // mesh they were made with (for its texture coordinates, colours and materials), so it lives here.
  Mesh localInput;
  Timings timings;
  std::unique_ptr<MethodRun> run;
  // Smooth and accurate: the host-memory estimate checked against the limit (a streamed job's, stream_budget.h),
  // and for a streamed job the whole job's, which result() checks before it holds the welded mesh.
  std::optional<JobEstimate> estimate, wholeEstimate;
  // deform() has been called; it ran the method's deform step; the last one ran to its end (the outputs are
  // its result); a result was taken (DeformOptions::once allows one, for every method); that one-shot result
  // threw while being made (cancelled or failed: what it was made from is gone, so it cannot be made again).
  bool called = false, deformed = false, hasResult = false, resultTaken = false;
  const char* resultLost = nullptr;
  // The input Error of `call` (result(), ...) where there is no result to give.
  void checkResult(const char* call);
};

// The input Error of the memory limit when `estimate` exceeds it, in the words of the Deformer's method
// (smooth: checkHostFits's "the smooth job needs about", else checkJobFits's "the job needs about").
void checkEstimateFits(const Deformer::Impl& impl, const JobEstimate& estimate, uint64_t memoryLimit, const char* limitName);

// Sums dispatch times by label in first-seen order (GPU time; a negative time counts 0).
std::vector<std::pair<std::string, double>> stepsOf(const std::vector<DispatchTiming>& dispatches);
// The sum of the dispatches' GPU times; `wallMs` when the device measured none.
double stageMs(const std::vector<DispatchTiming>& dispatches, double wallMs);

}  // namespace sffd
