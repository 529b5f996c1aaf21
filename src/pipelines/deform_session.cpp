// Device-resident smooth FFD: the kernels of pn_triangles.cpp, regular_clip.cpp and smooth_deform.cpp
// chained on one backend with the intermediate buffers kept on the device. Only two small host
// transfers remain: the clip counts (to size the sub-triangle buffers, once per precompute) and the
// lattice coefficients (once per deform).
#include "pipelines/deform_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include <sffd/error.h>
#include "kernels/clip/knot_box_clip.h"
#include "model/lattice_pack.h"
#include "model/mesh_topology.h"
#include "pipelines/patch_output.h"
#include "kernels/pn/pn_triangles.h"
#include "model/prepared_mesh.h"
#include "kernels/clip/split_pattern_table.h"
#include "core/huge_pages.h"
#include "core/kernel_registry.h"
#include "core/wall_clock.h"
#include "pipelines/device_reals.h"
#include "pipelines/deform_session_internal.h"

namespace sffd {

namespace {

// The most bytes of reals a pre-compute chunk takes beyond its first parent: its range is built on the host
// whole before the upload, so a large mesh in one chunk would hold its inputs twice (host and device) at once.
constexpr uint64_t kPreChunkHostBytes = uint64_t(64) << 20;

// The pre-compute's chunks: consecutive parents (and their clip triangles, which follow the parents'
// order), as many to a chunk as keep both of its input ranges within one storage binding, and its reals
// within kPreChunkHostBytes.
std::vector<ClipRanges> preChunks(const PreparedMesh& mesh, const ClipTriangles& clip, size_t realSize, uint64_t limit,
                                  size_t maxParents) {
  const uint64_t nv = mesh.positions.size() / 4, nt = mesh.triangleCount();
  const std::vector<ClipTriangle>& ct = clip.triangles;
  auto fits = [&](const ClipRanges& r) { return r.byteOf(r.realElements) <= limit && r.words * 4 <= limit; };
  std::vector<ClipRanges> out;
  uint64_t p0 = 0, c0 = 0;
  do {
    ClipRanges r = clipRanges(nv, p0, 0, c0, 0, realSize);
    for (uint64_t p1 = p0, c1 = c0; p1 < nt && (!maxParents || p1 - p0 < maxParents); ++p1) {
      while (c1 < ct.size() && ct[c1].parent == p1) ++c1;
      ClipRanges next = clipRanges(nv, p0, p1 + 1 - p0, c0, c1 - c0, realSize);
      if (!fits(next) || (r.parents && next.byteOf(next.realElements) > kPreChunkHostBytes)) break;
      r = next;
    }
    if (!r.parents && p0 < nt) throw tooLargeForOneBinding(nv, p0, realSize, limit);
    out.push_back(r);
    p0 += r.parents, c0 += r.clips;
  } while (p0 < nt);
  return out;
}

}  // namespace

DeformSession::DeformSession(Backend& backend, const Mesh& input, const Lattice& lattice, const DeformSessionOptions& options,
                             const StageProgress& progress)
    : backend_(backend), options_(options), impl_(std::make_unique<Impl>()) {
  try {
    prepare(input, lattice, progress);
  } catch (...) {
    for (BufferId b : impl_->owned) backend_.destroyBuffer(b);   // the destructor does not run
    throw;
  }
}

void DeformSession::prepare(const Mesh& input, const Lattice& lattice, const StageProgress& progress) {
  Backend& backend = backend_;
  const DeformSessionOptions& options = options_;
  if (progress) progress("prepare", 0);
  if (!(options.edgeLength > 0) || !std::isfinite(options.edgeLength))
    throw Error(ErrorKind::Input, "the edge length must be a finite number > 0");
  if (options.level < 1 || options.level > 64) throw Error(ErrorKind::Input, "the tessellation level must be 1..64");
  if (options.variant.f64 && !backend.info().limits.float64)
    throw noFloat64Error(backend.info());
  Impl& I = *impl_;
  const bool f64 = options.variant.f64;
  I.realSize = f64 ? 8 : 4;
  I.structure = lattice;
  int s = options.samples > 0 ? options.samples : lattice.degree[0] + lattice.degree[1] + lattice.degree[2];
  I.fit = makeFitTable(std::max(3, s));
  PackedLattice packed = packLattice(lattice);
  // The kernels build on other threads (where the backend can) while the mesh is prepared.
  I.deformVariant = deformVariantOf(options, input);
  backend.precompile(SessionKernels{backend, options, I.deformVariant}.uses(deformParamsFor(packed, f64, &I.fit.data)));
  // A copy only where the creases are still to be applied.
  Mesh withCreases;
  if (!input.normalsFromFile && !options.creasesApplied) {
    withCreases = input;
    applyCreaseAngle(withCreases, options.creaseAngleDeg);
  }
  const Mesh& mesh = input.normalsFromFile || options.creasesApplied ? input : withCreases;
  I.mesh = prepareMesh(mesh);
  I.triangles = I.mesh.triangleCount();
  auto up = [&](const std::vector<double>& v) {
    std::vector<unsigned char> b = realBytes(v, f64);
    return I.upload(backend, b.data(), b.size());
  };
  I.frame = up(deformFrameRange(packed, I.fit.data));
  I.coeffs = up(packed.coeffs);
  if (streamed()) {   // the clip triangles are made, and everything run, a chunk at a time (streamChunks)
    if (&mesh == &withCreases) I.creased = std::move(withCreases);
    I.clipSource = &mesh == &input ? &input : &I.creased;
    if (!options.knotBoxClip)
      I.clipBuilder = std::make_unique<ClipTriangleBuilder>(*I.clipSource, options.edgeLength, splitPatternTable().nmax());
    // The chunks read the slot normals' part of the topology (PreparedMesh::slotNormals), not the adjacency.
    freeStorage(I.mesh.topology.neighbour), freeStorage(I.mesh.topology.neighbourEdge);
    return;
  }
  if (options.knotBoxClip) I.knotBoxSubs = clipAgainstKnotBoxes(mesh, lattice);
  else I.clip = buildClipTriangles(mesh, options.edgeLength, splitPatternTable().nmax());

  for (const ClipRanges& r : preChunks(I.mesh, I.clip, I.realSize, backend.info().limits.maxStorageBufferRange,
                                       options.maxChunkParents)) {
    const PackedClip pc = options.knotBoxClip ? PackedClip{} : packClip(I.clip, r.firstClip, r.firstClip + r.clips);
    I.pre.push_back(I.uploadInputs(backend, r, pc));
  }
  // The device holds what the regular clipping reads from here on: the host copies go (the knot-box
  // clipping reads the prepared mesh on the host).
  I.clipCount = I.clip.triangles.size();
  I.clip = {};
  if (!options.knotBoxClip) I.mesh = {};
  precompute(progress);
}

size_t DeformSession::precomputeChunks() const { return impl_->pre.size(); }

DeformSession::~DeformSession() {
  for (BufferId b : impl_->owned) backend_.destroyBuffer(b);
}

const SessionTimings& DeformSession::precompute(const StageProgress& progress) {
  if (streamed()) throw Error(ErrorKind::Input, "a one-shot session runs its pre-compute chunk by chunk (streamChunks)");
  Impl& I = *impl_;
  Backend& B = backend_;
  const SessionKernels K{B, options_, I.deformVariant};
  auto t0 = std::chrono::steady_clock::now();
  timings_ = {};
  const size_t nt = I.triangles;
  if (progress) progress("pn", 0.1);
  for (const PreChunkInputs& c : I.pre) K.pn(c);
  // Sub-triangle counts per chunk, and the chunk layout (a clip triangle's sub-triangles stay in one chunk).
  const SubBytes bytes = subBytesOf(options_, I.realSize, I.fit.points);
  uint64_t maxSubs = maxChunkSubs(B.info().limits, bytes, options_.maxChunkSubTriangles);

  std::vector<uint64_t> offsets;   // per clip triangle (regular) exclusive scan of the counts
  SubTriangleRecords knotRecords;
  size_t clipN = 0;
  if (progress) progress("clip", 0.2);
  if (!options_.knotBoxClip) {
    clipN = I.clipCount;
    std::vector<uint32_t> counts(clipN);
    for (const PreChunkInputs& c : I.pre) K.clipCount(c, c.ranges.clips ? &counts[c.ranges.firstClip] : nullptr);   // an empty mesh: none
    offsets.assign(clipN + 1, 0);
    for (size_t i = 0; i < clipN; ++i) offsets[i + 1] = offsets[i] + counts[i], maxSubs = std::max<uint64_t>(maxSubs, counts[i]);
  } else {
    // The 2015 clipping is the CPU baseline: PN records come back to the host for it once.
    PnOutput pn;
    pn.records = doublesOf([&] {
      const uint64_t perParent = SFFD_PN_STRIDE * 4 * I.realSize;
      std::vector<unsigned char> b(nt * perParent);
      for (const PreChunkInputs& c : I.pre)
        if (c.ranges.parents)
          B.download(c.reals, c.ranges.byteOf(c.ranges.pn), &b[c.ranges.firstParent * perParent], c.ranges.parents * perParent);
      return b;
    }(), options_.variant.f64);
    knotRecords = recordsFromSubTriangles(I.mesh, pn, I.knotBoxSubs, options_.variant);
    clipN = knotRecords.size();   // each "clip triangle" is one sub-triangle
    offsets.resize(clipN + 1);
    for (size_t i = 0; i <= clipN; ++i) offsets[i] = i;
  }
  subCount_ = offsets.back();

  // The chunks: per chunk the sub-triangle records and the deform outputs. A clip triangle's
  // sub-triangles stay in one chunk, and a chunk's clip triangles in one pre-compute chunk (clip_write
  // reads its inputs). The buffers are kept when the layout is the one already there (a repeated
  // precompute), so that nothing is reallocated.
  std::vector<ChunkPlan> plan;
  if (options_.knotBoxClip) planChunks(plan, offsets, 0, clipN, maxSubs, 0);
  else
    for (size_t pre = 0; pre < I.pre.size(); ++pre)
      planChunks(plan, offsets, I.pre[pre].ranges.firstClip, I.pre[pre].ranges.firstClip + I.pre[pre].ranges.clips, maxSubs, pre);
  bool same = plan.size() == chunks_.size();
  for (size_t i = 0; same && i < plan.size(); ++i)
    same = plan[i].first == chunks_[i].first && plan[i].count == chunks_[i].count && plan[i].firstClip == I.chunkBuffers[i].firstClip;
  if (!same) {
    for (Chunk& c : chunks_) I.drop(B, c.output);
    for (Impl::ChunkBuffers& c : I.chunkBuffers) I.drop(B, c.headers), I.drop(B, c.records);
    chunks_.clear();
    I.chunkBuffers.clear();
    for (const ChunkPlan& p : plan) {
      Chunk c;
      c.first = p.first;
      c.count = p.count;
      c.output = I.make(B, p.count * bytes.out);
      c.patchesOffset = p.count * bytes.tess;
      Impl::ChunkBuffers cb;
      cb.headers = I.make(B, p.count * 16);
      cb.records = I.make(B, p.count * bytes.record);
      cb.firstClip = p.firstClip;
      cb.clipCount = p.clipCount;
      chunks_.push_back(c);
      I.chunkBuffers.push_back(cb);
    }
  }
  std::vector<uint32_t> chunkOffsets;
  for (size_t ci = 0; ci < plan.size(); ++ci) {
    const ChunkPlan& p = plan[ci];
    const Chunk& c = chunks_[ci];
    const Impl::ChunkBuffers& cb = I.chunkBuffers[ci];
    const size_t first = p.firstClip, subs = p.count;
    if (!options_.knotBoxClip) {
      const PreChunkInputs& in = I.pre[p.pre];
      chunkOffsets.resize(p.clipCount);
      for (size_t i = 0; i < p.clipCount; ++i) chunkOffsets[i] = uint32_t(offsets[first + i] - offsets[first]);
      K.clipWrite(in, first - in.ranges.firstClip, p.clipCount, chunkOffsets.data(), cb.headers, cb.records);
    } else if (subs) {
      B.upload(cb.headers, 0, &knotRecords.headers[4 * c.first], subs * 16);
      std::vector<double> part(knotRecords.records.begin() + c.first * SFFD_SUB_STRIDE * 4,
                               knotRecords.records.begin() + (c.first + subs) * SFFD_SUB_STRIDE * 4);
      std::vector<unsigned char> b = realBytes(part, options_.variant.f64);
      B.upload(cb.records, 0, b.data(), b.size());
    }
    if (progress) progress("clip", 0.2 + 0.8 * double(ci + 1) / double(plan.size() + 1));
  }
  B.finish();
  timings_.dispatches = B.takeTimings();
  if (options_.knotBoxClip) timings_.dispatches.push_back({"clip", knotRecords.wallMs});
  sumStages(timings_);
  timings_.wallMs = msSince(t0);
  return timings_;
}

const SessionTimings& DeformSession::deform(const Lattice& lattice, const StageProgress& progress) {
  Impl& I = *impl_;
  Backend& B = backend_;
  if (!sameLatticeStructure(lattice, I.structure))
    throw Error(ErrorKind::Input, "the lattice's degrees, counts, knots or frame differ from the session's");
  if (recordsReleased_) throw Error(ErrorKind::Input, "the one-shot session's chunks were already streamed (DeformOptions::once)");
  auto t0 = std::chrono::steady_clock::now();
  timings_ = {};
  PackedLattice packed = packLattice(lattice);
  std::vector<unsigned char> coeffs = realBytes(packed.coeffs, options_.variant.f64);
  B.upload(I.coeffs, 0, coeffs.data(), coeffs.size());
  I.deformParams = deformParamsFor(packed, options_.variant.f64, &I.fit.data);
  if (streamed()) {   // the kernels run in streamChunks, chunk by chunk
    deformed_ = true;
    timings_.wallMs = msSince(t0);
    return timings_;
  }
  const SessionKernels K{B, options_, I.deformVariant};
  for (size_t ci = 0; ci < chunks_.size(); ++ci) {
    const Chunk& c = chunks_[ci];
    if (!c.count) continue;
    K.deform(I.deformParams, c.count, I.fit.points, {I.coeffs, I.frame, I.chunkBuffers[ci].records, c.output});
    if (progress) progress("deform", double(ci + 1) / double(chunks_.size() + 1));
  }
  B.finish();
  timings_.dispatches = B.takeTimings();
  sumStages(timings_);
  timings_.wallMs = msSince(t0);
  if (!B.info().limits.timestamps) timings_.deformMs = timings_.wallMs;
  return timings_;
}

namespace {
const char* const kStreamedOnly = "a one-shot session's records and outputs exist a chunk at a time, in streamChunks (DeformOptions::once)";
}  // namespace

SubTriangleRecords DeformSession::records() {
  if (streamed()) throw Error(ErrorKind::Input, kStreamedOnly);
  SubTriangleRecords R;
  R.headers.resize(4 * subCount_);
  R.records.resize(subCount_ * SFFD_SUB_STRIDE * 4);
  std::vector<float> scratch;
  for (size_t ci = 0; ci < chunks_.size(); ++ci) {
    const Chunk& c = chunks_[ci];
    if (!c.count) continue;
    backend_.download(impl_->chunkBuffers[ci].headers, 0, &R.headers[4 * c.first], c.count * 16);
    downloadRealsInto(backend_, impl_->chunkBuffers[ci].records, 0, c.count * SFFD_SUB_STRIDE * 4, options_.variant.f64,
                      &R.records[c.first * SFFD_SUB_STRIDE * 4], scratch);
  }
  return R;
}

SubTrianglePreImages DeformSession::preImages() {
  if (streamed()) throw Error(ErrorKind::Input, kStreamedOnly);
  SubTrianglePreImages P;
  P.parent.reserve(subCount_);
  P.lam.reserve(9 * subCount_);
  for (size_t ci = 0; ci < chunks_.size(); ++ci)
    readPreImages(impl_->chunkBuffers[ci].headers, impl_->chunkBuffers[ci].records, chunks_[ci].count, P);
  return P;
}

void DeformSession::readPreImages(BufferId headerBuffer, BufferId recordBuffer, size_t count, SubTrianglePreImages& P) {
  if (!count) return;
  std::vector<uint32_t> headers(4 * count);
  auto load = [&](auto& records) {   // one chunk's records at a time, as the device holds them
    resizeHuge(records, count * SFFD_SUB_STRIDE * 4);
    backend_.download(headerBuffer, 0, headers.data(), count * 16);
    backend_.download(recordBuffer, 0, records.data(), records.size() * sizeof(records[0]));
    P.append(headers.data(), records.data(), count);
  };
  std::vector<float> f;
  std::vector<double> d;
  options_.variant.f64 ? load(d) : load(f);
}

SmoothOutput DeformSession::output() {
  if (streamed()) throw Error(ErrorKind::Input, kStreamedOnly);
  SmoothOutput out;
  out.level = options_.level;
  const size_t nv = size_t(tessVertexCount(options_.level));
  std::vector<float> scratch;
  const size_t patchReals = SFFD_PATCH_STRIDE * 4, tessReals = 2 * nv * 4;
  out.patches.resize(subCount_ * patchReals);
  out.tess.resize(subCount_ * tessReals);
  for (const Chunk& c : chunks_) {
    if (!c.count) continue;
    downloadRealsInto(backend_, c.output, c.patchesOffset, c.count * patchReals, options_.variant.f64,
                      &out.patches[c.first * patchReals], scratch);
    downloadRealsInto(backend_, c.output, 0, c.count * tessReals, options_.variant.f64, &out.tess[c.first * tessReals], scratch);
  }
  out.timings = timings_.dispatches;
  out.wallMs = timings_.wallMs;
  return out;
}

}  // namespace sffd
