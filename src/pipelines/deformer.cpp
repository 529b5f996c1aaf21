// sffd::Deformer (<sffd/deformer.h>): the options resolved and checked once, then one MethodRun per
// method (deformer_internal.h) doing the device work.
#include <sffd/deformer.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <sffd/error.h>

#include "core/backend.h"
#include "core/job_budget.h"
#include "core/wall_clock.h"
#include "kernels/clip/regular_clip.h"
#include "model/mesh.h"
#include "model/mesh_topology.h"
#include "pipelines/deform_session.h"
#include "pipelines/deformer_internal.h"
#include "pipelines/stream_budget.h"

namespace sffd {

void ProgressReporter::operator()(const char* stage, double fraction) const {
  if (!callback_) return;
  Progress p;
  p.stage = stage;
  p.fraction = lo_ + (hi_ - lo_) * std::clamp(fraction, 0.0, 1.0);
  if (callback_(p)) return;
  // Queued work is finished and its timings dropped, so that the next call starts from a clean device.
  if (backend_) {
    backend_->finish();
    backend_->takeTimings();
  }
  throw Error(ErrorKind::Cancelled, "cancelled");
}

ProgressReporter ProgressReporter::part(double lo, double hi) const {
  ProgressReporter r = *this;
  r.lo_ = lo_ + (hi_ - lo_) * lo;
  r.hi_ = lo_ + (hi_ - lo_) * hi;
  return r;
}

std::vector<std::pair<std::string, double>> stepsOf(const std::vector<DispatchTiming>& dispatches) {
  std::vector<std::pair<std::string, double>> steps;
  for (const DispatchTiming& d : dispatches) {
    auto it = std::find_if(steps.begin(), steps.end(), [&](const auto& s) { return s.first == d.label; });
    if (it == steps.end()) steps.push_back({d.label, 0.0}), it = steps.end() - 1;
    it->second += std::max(d.gpuMs, 0.0);
  }
  return steps;
}

double stageMs(const std::vector<DispatchTiming>& dispatches, double wallMs) {
  double ms = 0;
  for (const DispatchTiming& d : dispatches) ms += d.gpuMs > 0 ? d.gpuMs : 0;
  return ms > 0 ? ms : wallMs;
}

namespace {

constexpr const char* kLimitName = "DeformOptions::memoryLimit";

ResolvedOptions resolve(const DeformOptions& o, const DeviceInfo& info, const Mesh& mesh, const Lattice& lattice) {
  ResolvedOptions r;
  r.method = o.method;
  r.variant.strict = o.strict;
  if (o.precision == Precision::Double && !info.limits.float64)
    throw noFloat64Error(info);
  // Classic and accurate FFD default to double: PyGeM's 1.5e-6 is below float resolution at its
  // coordinates, and accurate FFD is the reference the others are measured against.
  r.variant.f64 = o.precision == Precision::Double ||
                  (o.precision == Precision::Auto && o.method != Method::Smooth && info.limits.float64);
  if (o.tess < 1 || o.tess > kMaxTessLevel)
    throw Error(ErrorKind::Input, "the tessellation level must be 1.." + std::to_string(kMaxTessLevel) + ", not " + std::to_string(o.tess));
  r.tess = o.tess;
  if (!std::isfinite(o.edgeLength) || o.edgeLength < 0)
    throw Error(ErrorKind::Input, "the edge length must be a finite number > 0 (or 0: a tenth of the mesh's size)");
  r.edgeLength = o.edgeLength;
  if (r.edgeLength == 0) r.edgeLength = defaultEdgeLength(mesh);
  // Every option is checked whatever the method, so that a bad value is not found only when the method changes.
  if (o.samples < 0 || o.samples > 15)
    throw Error(ErrorKind::Input, "DeformOptions::samples must be 0 (nu+nv+nw) or 1..15 (below 3: 3), not " + std::to_string(o.samples));
  if (o.creaseAngleDeg != kCreaseAngleAuto && !(o.creaseAngleDeg >= 0 && o.creaseAngleDeg <= 180)) {
    char angle[32];
    std::snprintf(angle, sizeof angle, "%g", o.creaseAngleDeg);
    throw Error(ErrorKind::Input, std::string("DeformOptions::creaseAngleDeg must be 0..180 degrees or kCreaseAngleAuto, not ") + angle);
  }
  const int degrees = lattice.degree[0] + lattice.degree[1] + lattice.degree[2];
  r.samples = std::max(3, o.samples > 0 ? o.samples : degrees);
  r.knotBoxClip = o.clip == Clip::KnotBox;
  r.split = o.split;
  r.creaseAngleDeg = o.creaseAngleDeg;
  r.memoryLimit = o.memoryLimit;
  r.maxChunkElements = o.maxChunkElements;
  r.once = o.once;
  return r;
}


// Ends a public call on the device however the call ends (Backend::endCall: a GL device may then be
// used from another thread).
class CallScope {
 public:
  explicit CallScope(Backend& backend) : backend_(backend) {}
  CallScope(const CallScope&) = delete;
  CallScope& operator=(const CallScope&) = delete;
  ~CallScope() { backend_.endCall(); }

 private:
  Backend& backend_;
};

}  // namespace

Deformer::Deformer(Device& device, const MeshView& mesh, const Lattice& lattice, const DeformOptions& options)
    : Deformer(device, meshFromView(mesh), lattice, options) {}

Deformer::Deformer(Device& device, const Mesh& mesh, const Lattice& lattice, const DeformOptions& options)
    : impl_(std::make_unique<Impl>()) {
  const auto t0 = std::chrono::steady_clock::now();
  Impl& I = *impl_;
  I.device = device.handle();
  I.options = options;
  // The checks meshFromView makes, for a Mesh the caller filled: a bad index or count would be read out of
  // bounds by every method, a NaN deformed into NaN.
  validateMesh(mesh, "mesh");
  validateLattice(lattice, "lattice");
  I.resolved = resolve(options, device.info(), mesh, lattice);
  if (std::string big = latticeTooLarge(lattice, options.memoryLimit, kLimitName); !big.empty())
    throw Error(ErrorKind::Input, big);
  I.structure = lattice;
  I.input = mesh;
  // What <sffd/mesh.h> lets a caller leave empty, made as readMesh makes it.
  if (I.input.normals.empty()) computeVertexNormals(I.input), I.input.normalsFromFile = false;
  if (I.input.weldId.empty()) weldPositions(I.input);
  I.frame = latticeLocalFrame(lattice);
  const ResolvedOptions& r = I.resolved;
  Backend& backend = device.backend();
  CallScope call(backend);
  ProgressReporter progress(I.options.progress, &backend);
  progress("prepare", 0);
  if (r.method == Method::Smooth) {
    // Smooth FFD's pre-images index the mesh with its creases split (the error analysis needs it).
    if (!I.input.normalsFromFile) applyCreaseAngle(I.input, r.creaseAngleDeg);
    checkSubTriangleCount(I.input, r.edgeLength, "the edge length");
    // Host and device memory before anything is allocated (docs/ROBUSTNESS.md "Limits"): the whole job at
    // once, or for a job streamed from the mesh what stays alive (stream_budget.h).
    const DeviceInfo& info = device.info();
    const uint64_t latticeBytes = estimateLatticeBytes(lattice);
    JobEstimate whole = estimateSmoothJob(I.input, estimateSubTriangles(I.input, r.edgeLength), r.tess, r.variant.f64 ? 8 : 4,
                                          deviceIsHost(info));
    whole.hostBytes += latticeBytes;
    const DeformSessionOptions session = sessionOptionsOf(r);
    if (session.streamed() && !session.knotBoxClip) {   // stream_budget.h bounds the regular clipping's sub-triangles
      // The caller's mesh and, where the lattice box is away from the origin, the local-frame copy.
      const uint64_t others = meshHeldBytes(mesh) + (I.frame.isWorld() ? 0 : meshHeldBytes(I.input));
      I.estimate = estimateStreamedSmoothJob(I.input, session, info, others);
      I.estimate->hostBytes += latticeBytes;
      I.wholeEstimate = whole;
    } else {
      I.estimate = whole;
    }
    checkHostFits(*I.estimate, options.memoryLimit, kLimitName, "smooth job");
  }
  // The devices see the mesh and the lattice in the lattice box's frame (deformer_local_frame.cpp), and
  // the edge length in its units.
  const bool moved = !I.frame.isWorld();
  if (moved) I.localInput = sffd::localMesh(I.input, I.frame);
  const Lattice movedLattice = moved ? sffd::localLattice(lattice, I.frame) : Lattice{};
  const Mesh& localMesh = moved ? I.localInput : I.input;
  const Lattice& localLattice = moved ? movedLattice : lattice;
  ResolvedOptions localOptions = r;
  localOptions.edgeLength *= I.frame.scale;
  if (r.method == Method::Smooth && !r.knotBoxClip && !clipTargetFits(localOptions.edgeLength)) {
    char share[32];
    std::snprintf(share, sizeof share, "%.2g", localOptions.edgeLength);
    throw Error(ErrorKind::Input, std::string("the edge length is ") + share +
                                      " of the lattice's box, below the smallest float (1.2e-38) that the clip kernels take it "
                                      "in; use a lattice closer to the mesh's size or a longer edge length");
  }
  std::unique_ptr<MethodRun> local;
  if (r.method == Method::Smooth) local = makeSmoothRun(backend, localMesh, localLattice, localOptions, I.timings, progress);
  else if (r.method == Method::Classic) local = makeClassicRun(backend, localMesh, localLattice, localOptions, I.timings, progress);
  else {
    // Held throughout besides the run's mesh: the caller's, the Deformer's where the run has the local-frame
    // copy, the lattice.
    const uint64_t held = meshHeldBytes(mesh) + (moved ? meshHeldBytes(I.input) : 0) + estimateLatticeBytes(lattice);
    local = makeAccurateRun(backend, localMesh, localLattice, localOptions, I.timings, progress, held, I.estimate, I.wholeEstimate);
  }
  std::unique_ptr<MethodRun> run = inLocalFrame(std::move(local), I.frame);
  progress("prepare", 1);   // a cancel here frees the run's buffers before `call` ends
  I.run = std::move(run);
  I.timings.wallMs = msSince(t0);
}

Deformer::Deformer(Deformer&&) noexcept = default;
Deformer& Deformer::operator=(Deformer&& other) noexcept {
  if (this != &other) {
    Deformer old(std::move(*this));   // destroyed below, as a Deformer: its call ends
    impl_ = std::move(other.impl_);
  }
  return *this;
}
// Freeing the device buffers is a call on the device like any other: it may come from any thread (a
// Python Deformer's is made by whichever thread the garbage collector runs on).
Deformer::~Deformer() {
  if (!impl_) return;
  Backend& backend = impl_->backend();   // the constructor succeeded: the device has a backend
  impl_.reset();
  backend.endCall();
}

const Timings& Deformer::deform(const Lattice& lattice) {
  Impl& I = impl();
  // Refused before anything else: a one-shot Deformer's second call leaves its one result to be taken.
  if (I.options.once && I.deformed) throw Error(ErrorKind::Input, "a one-shot Deformer deforms once (DeformOptions::once)");
  // Whatever else this call throws for, the outputs are no longer the last deform()'s result (deformer.h): a
  // cancelled or failed call leaves them part old, part new, and one refused leaves another lattice's.
  I.hasResult = false;
  I.called = true;
  if (!sameLatticeStructure(lattice, I.structure))
    throw Error(ErrorKind::Input, "the lattice's degrees, counts, knots, frame or outside rule differ from the Deformer's");
  // The constructor checked the first lattice; an edited one could hold a NaN, which every method turned
  // silently into a result of NaN.
  validateLattice(lattice, "lattice");
  const auto t0 = std::chrono::steady_clock::now();
  CallScope call(I.backend());
  ProgressReporter progress(I.options.progress, &I.backend());
  progress("deform", 0);
  I.timings.steps.clear();
  I.deformed = true;
  I.run->deform(lattice, I.timings, progress);
  progress("deform", 1);
  I.hasResult = true;
  I.timings.wallMs = msSince(t0);
  return I.timings;
}

const Timings& Deformer::timings() const { return impl().timings; }

void Deformer::Impl::checkResult(const char* call) {
  if (!hasResult)
    throw Error(ErrorKind::Input, std::string(call) + (called ? ": the last deform() was cancelled or failed; deform() again first"
                                                              : ": no result yet; call deform() first"));
  if (options.once && resultLost)
    throw Error(ErrorKind::Input, std::string(call) + ": the one-shot result (DeformOptions::once) " + resultLost +
                                      " while it was being made, and what it is made from is not kept to make it again; "
                                      "make a new Deformer");
  if (options.once && resultTaken) throw Error(ErrorKind::Input, std::string(call) + ": the result was already taken (DeformOptions::once)");
}

namespace {
// Runs `take` (the run's result or streamResult) as the one result a one-shot Deformer gives, noting how it
// ended if it threw.
template <class Take>
auto takeResult(Deformer::Impl& I, Take&& take) -> decltype(take()) {
  I.resultTaken = true;
  try {
    return take();
  } catch (const Error& e) {
    I.resultLost = e.kind() == ErrorKind::Cancelled ? "was cancelled" : "failed";
    throw;
  } catch (...) {
    I.resultLost = "failed";
    throw;
  }
}
}  // namespace

Mesh Deformer::result() const {
  impl().checkResult("result()");
  // A streamed job's estimate counts a sink's pieces, not the welded mesh that result() holds.
  if (impl().wholeEstimate) checkEstimateFits(impl(), *impl().wholeEstimate, impl().options.memoryLimit, kLimitName);
  CallScope call(impl().backend());
  ProgressReporter progress(impl().options.progress, &impl().backend());
  progress("download", 0);
  impl().timings.weldMs = 0;
  return takeResult(impl(), [&] {
    Mesh mesh = impl().run->result(progress);
    progress("download", 1);
    return mesh;
  });
}

void Deformer::streamResult(MeshSink& sink) const {
  impl().checkResult("streamResult()");
  CallScope call(impl().backend());
  ProgressReporter progress(impl().options.progress, &impl().backend());
  progress("download", 0);
  impl().timings.weldMs = 0;
  takeResult(impl(), [&] {
    impl().run->streamResult(sink, progress);
    progress("download", 1);
  });
}

void checkEstimateFits(const Deformer::Impl& impl, const JobEstimate& estimate, uint64_t memoryLimit, const char* limitName) {
  if (impl.resolved.method == Method::Smooth) checkHostFits(estimate, memoryLimit, limitName, "smooth job");
  else checkJobFits(estimate, PackedLattice{}, 0, nullptr, memoryLimit, limitName);
}

void MethodRun::streamResult(MeshSink& sink, const ProgressReporter& progress) const {
  const Mesh mesh = result(progress);
  Mesh tables;
  tables.materials = mesh.materials;
  tables.groups = mesh.groups;
  tables.materialLibraries = mesh.materialLibraries;
  tables.weldIdIsLocation = mesh.weldIdIsLocation;
  tables.normalsFromFile = mesh.normalsFromFile;
  sink.begin(tables);
  sink.add(mesh, 0);
  sink.end();
}

std::vector<double> Deformer::patchControlPoints() const {
  impl().checkResult("patchControlPoints()");
  CallScope call(impl().backend());
  return impl().run->patchControlPoints();
}
size_t Deformer::subTriangles() const { return impl().run->subTriangles(); }
std::vector<OutputChunk> Deformer::deviceOutput() const {
  if (!impl().hasResult) return {};   // nothing to draw before the first deform(), nor after a cancelled one
  return impl().run->deviceOutput();
}
glm::dvec3 Deformer::localOrigin() const { return impl().frame.origin; }
double Deformer::localScale() const { return impl().frame.scale; }
bool Deformer::doublePrecision() const { return impl().resolved.variant.f64; }
int Deformer::resultDigits() const { return doublePrecision() || localOrigin() != glm::dvec3(0.0) ? 17 : 9; }
const DeformOptions& Deformer::options() const { return impl().options; }
Device& Deformer::device() const { return Device::of(impl().device); }
Deformer::Impl& Deformer::internal() { return impl(); }

Deformer::Impl& Deformer::impl() const {
  if (!impl_) throw Error(ErrorKind::Input, "this sffd::Deformer was moved from; use the Deformer it was moved to");
  return *impl_;
}

}  // namespace sffd
