// A stand-in for src/core/deform_session.cpp, built only while that file does not exist (CMakeLists.txt
// checks): the DeformSession interface (deform_session.h) on top of the host pipeline functions, so
// that `sffd view` builds, draws from DeformSession's device buffers and is tested before the real,
// device-resident implementation lands. Unlike the real one it keeps the sub-triangle records on the
// host and round-trips the deform output through the host (smoothDeformGpu downloads it), then uploads
// the tessellation into the session's buffers as float4.
#include "deform_session.h"

#include <algorithm>
#include <chrono>

#include "error.h"
#include "job_budget.h"
#include "knot_box_clip.h"
#include "lattice_pack.h"
#include "patch_output.h"
#include "pn_triangles.h"
#include "prepared_mesh.h"
#include "split_pattern_table.h"

namespace sffd {

struct DeformSession::Impl {
  Mesh mesh;
  Lattice structure;
  FitTable fit;
  SubTriangleRecords subs;
  SmoothOutput last;
  std::vector<BufferId> buffers;
};

namespace {
double msOf(const std::vector<DispatchTiming>& t, double wallMs) {
  double ms = 0;
  for (const DispatchTiming& d : t) ms += d.gpuMs > 0 ? d.gpuMs : 0;
  return ms > 0 ? ms : wallMs;
}
bool sameStructure(const Lattice& a, const Lattice& b) {
  return a.degree == b.degree && a.counts == b.counts && a.knots == b.knots && a.frameLinear == b.frameLinear &&
         a.frameOffset == b.frameOffset && a.outside == b.outside;
}
}  // namespace

DeformSession::DeformSession(Backend& backend, const Mesh& mesh, const Lattice& lattice,
                             const DeformSessionOptions& options)
    : backend_(backend), options_(options), impl_(std::make_unique<Impl>()) {
  if (!(options.edgeLength > 0)) throw Error(ErrorKind::Input, "DeformSession: the edge length must be positive");
  if (options.level < 1 || options.level > kMaxTessLevel)
    throw Error(ErrorKind::Input, "DeformSession: the tessellation level must be 1.." + std::to_string(kMaxTessLevel));
  impl_->mesh = mesh;
  impl_->structure = lattice;
  int s = options.samples > 0 ? options.samples : lattice.degree[0] + lattice.degree[1] + lattice.degree[2];
  impl_->fit = makeFitTable(std::max(3, s));
  precompute();
}

DeformSession::~DeformSession() {
  for (BufferId b : impl_->buffers) backend_.destroyBuffer(b);
}

const SessionTimings& DeformSession::precompute() {
  auto t0 = std::chrono::steady_clock::now();
  Impl& m = *impl_;
  timings_ = {};
  PreparedMesh prepared = prepareMesh(m.mesh);
  PnOutput pn = pnTrianglesGpu(backend_, prepared, options_.variant);
  timings_.pnMs = msOf(pn.timings, pn.wallMs);
  if (options_.knotBoxClip)
    m.subs = recordsFromSubTriangles(prepared, pn, clipAgainstKnotBoxes(m.mesh, m.structure), options_.variant);
  else
    m.subs = regularClipGpu(backend_, prepared, pn, buildClipTriangles(m.mesh, options_.edgeLength, splitPatternTable().nmax()),
                            options_.edgeLength, options_.variant);
  timings_.clipMs = msOf(m.subs.timings, m.subs.wallMs);
  subCount_ = m.subs.size();
  // Chunks of whole patches that fit one storage binding.
  for (BufferId b : m.buffers) backend_.destroyBuffer(b);
  m.buffers.clear();
  chunks_.clear();
  const uint64_t perPatch = 2 * uint64_t(tessVertexCount(options_.level)) * 16;
  const size_t maxPerChunk = std::max<uint64_t>(1, backend_.info().limits.maxStorageBufferRange / perPatch);
  for (size_t first = 0; first < subCount_; first += maxPerChunk) {
    Chunk c;
    c.first = first;
    c.count = std::min(maxPerChunk, subCount_ - first);
    c.tess = backend_.createBuffer(c.count * perPatch);
    m.buffers.push_back(c.tess);
    chunks_.push_back(c);
  }
  timings_.wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return timings_;
}

const SessionTimings& DeformSession::deform(const Lattice& lattice) {
  if (!sameStructure(lattice, impl_->structure))
    throw Error(ErrorKind::Input, "DeformSession: the lattice's degrees, counts, knots or frame changed");
  auto t0 = std::chrono::steady_clock::now();
  Impl& m = *impl_;
  const double pn = timings_.pnMs, clip = timings_.clipMs;
  timings_ = {};
  timings_.pnMs = pn;
  timings_.clipMs = clip;
  m.last = smoothDeformGpu(backend_, packLattice(lattice), m.subs, m.fit, options_.level, options_.variant, options_.split);
  timings_.deformMs = msOf(m.last.timings, m.last.wallMs);
  timings_.dispatches = m.last.timings;
  const size_t perPatch = 2 * size_t(tessVertexCount(options_.level)) * 4;   // values
  for (const Chunk& c : chunks_) {
    std::vector<float> f(c.count * perPatch);
    for (size_t i = 0; i < f.size(); ++i) f[i] = float(m.last.tess[c.first * perPatch + i]);
    backend_.upload(c.tess, 0, f.data(), f.size() * sizeof(float));
  }
  backend_.finish();
  timings_.wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return timings_;
}

SubTriangleRecords DeformSession::records() { return impl_->subs; }
SmoothOutput DeformSession::output() { return impl_->last; }

}  // namespace sffd
