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

namespace sffd {

namespace {
// A pre-compute chunk's inputs: the clip kernels' two input ranges (all the vertices, then its parents'
// and clip triangles' sections) in buffers of its own, so that no binding exceeds the device's limit;
// pn_triangles reads the mesh's sections and writes the PN records'.
struct PreChunkInputs {
  ClipRanges ranges;
  BufferId reals = 0, words = 0;
};
}  // namespace

struct DeformSession::Impl {
  Lattice structure;            // degrees, counts, knots, frame of the session's lattice
  PreparedMesh mesh;             // until uploaded; kept for the knot-box clipping (which reads it on the host) and streamed
  ClipTriangles clip;            // until uploaded (clipCount stays)
  // Streamed (DeformSession::streamed()): the mesh the clip triangles are made from, chunk by chunk, and the
  // deform kernel's parameters, set by deform() for streamChunks().
  Mesh creased;                  // the mesh with its creases applied, where the input had them still to apply
  const Mesh* clipSource = nullptr;
  std::unique_ptr<ClipTriangleBuilder> clipBuilder;
  gpu::DeformParams deformParams;
  size_t triangles = 0, clipCount = 0;
  std::vector<SubTriangle> knotBoxSubs;
  FitTable fit;
  size_t realSize = 4;
  std::vector<BufferId> owned;   // every buffer, destroyed with the session
  std::vector<PreChunkInputs> pre;   // the pre-compute's chunks of consecutive parents
  BufferId frame = 0, coeffs = 0;
  struct ChunkBuffers { BufferId headers = 0, records = 0; size_t firstClip = 0, clipCount = 0; };
  std::vector<ChunkBuffers> chunkBuffers;

  BufferId make(Backend& b, uint64_t bytes) {
    BufferId id = b.createBuffer(std::max<uint64_t>(bytes, 16));
    owned.push_back(id);
    return id;
  }
  // Destroys an owned buffer and sets its id to 0 (0: already gone).
  void drop(Backend& b, BufferId& id) {
    if (!id) return;
    b.destroyBuffer(id);
    owned.erase(std::find(owned.begin(), owned.end(), id));
    id = 0;
  }
  BufferId upload(Backend& b, const void* data, uint64_t bytes) {
    BufferId id = make(b, bytes);
    if (bytes) b.upload(id, 0, data, bytes);
    return id;
  }
  template <class T>
  BufferId uploadVector(Backend& b, const std::vector<T>& v) {
    return upload(b, v.data(), v.size() * sizeof(T));
  }
  // A pre-compute chunk's inputs built from the prepared mesh and its clip triangles `pc`, uploaded.
  PreChunkInputs uploadInputs(Backend& b, const ClipRanges& r, const PackedClip& pc) {
    PreChunkInputs c{r};
    if (realSize == 8) c.reals = uploadVector(b, clipRealRange<double>(r, mesh, nullptr, pc));
    else c.reals = uploadVector(b, clipRealRange<float>(r, mesh, nullptr, pc));
    c.words = uploadVector(b, clipWordRange(r, mesh, pc));
    return c;
  }
  // The same for a streamed chunk: the vertices' section, which every chunk repeats, is built once
  // (vertexSection, with its padding) and each chunk's own sections apart, so no chunk's whole range is
  // built on the host.
  std::vector<unsigned char> vertexSection;
  void makeVertexSection(const ClipRanges& r) {
    vertexSection.assign(r.byteOf(r.slotNormals), 0);
    if (realSize == 8) writeClipVertexSection(mesh, reinterpret_cast<double*>(vertexSection.data()));
    else writeClipVertexSection(mesh, reinterpret_cast<float*>(vertexSection.data()));
  }
  PreChunkInputs uploadStreamedInputs(Backend& b, const ClipRanges& r, const PackedClip& pc) {
    PreChunkInputs c{r};
    c.reals = make(b, r.byteOf(r.realElements));
    b.upload(c.reals, 0, vertexSection.data(), vertexSection.size());
    auto upload = [&](auto zero) {
      using Real = decltype(zero);
      std::vector<Real> own;
      resizeHuge(own, 4 * (r.realElements - r.slotNormals), zero);
      writeClipParentSections(r, mesh, nullptr, pc, own.data());
      b.upload(c.reals, r.byteOf(r.slotNormals), own.data(), own.size() * sizeof(Real));
    };
    realSize == 8 ? upload(0.0) : upload(0.0f);
    c.words = uploadVector(b, clipWordRange(r, mesh, pc));
    return c;
  }
};

namespace {

// The most bytes of reals a pre-compute chunk takes beyond its first parent: its range is built on the host
// whole before the upload, so a large mesh in one chunk would hold its inputs twice (host and device) at once.
constexpr uint64_t kPreChunkHostBytes = uint64_t(64) << 20;

Error tooLargeForOneBinding(uint64_t vertices, uint64_t parent, size_t realSize, uint64_t limit) {
  const ClipRanges one = clipRanges(vertices, parent, 1, 0, 0, realSize);
  return Error(ErrorKind::Input, "the job's vertices and one triangle's PN record and clip triangles (" +
                                     std::to_string(one.byteOf(one.realElements) >> 20) +
                                     " MiB) exceed one storage binding on this device (" + std::to_string(limit >> 20) +
                                     " MiB); use a coarser mesh");
}

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


// The most bytes of reals a streamed chunk (DeformSession::streamChunks) takes beyond the vertices, which
// every chunk repeats: its inputs, records and outputs are all there is of the job's at a time.
constexpr uint64_t kStreamedChunkBytes = uint64_t(16) << 20;

// What one sub-triangle takes on the device: its record, its tessellation and its output range (the
// patches, the tessellation and, split, the samples).
struct SubBytes {
  uint64_t record = 0, tess = 0, out = 0;
};
SubBytes subBytesOf(const DeformSessionOptions& o, size_t realSize, int fitPoints) {
  const uint64_t scale = realSize / 4, nv = uint64_t(tessVertexCount(o.level));
  SubBytes b;
  b.record = SFFD_SUB_STRIDE * 16 * scale;
  b.tess = 2 * nv * 16 * scale;
  const uint64_t patch = SFFD_PATCH_STRIDE * 16 * scale, sample = (SFFD_SAMPLE_FIXED + uint64_t(fitPoints)) * 16 * scale;
  b.out = patch + b.tess + (o.split ? sample : 0);
  return b;
}

// The most sub-triangles of a chunk: its records and its output range each within one storage binding.
uint64_t maxChunkSubs(const DeviceLimits& lim, const SubBytes& b, size_t cap) {
  uint64_t n = lim.maxStorageBufferRange / std::max(b.record, b.out);
  if (cap) n = std::min<uint64_t>(n, cap);
  return std::max<uint64_t>(n, 1);
}

// A chunk of sub-triangles: clip triangles [firstClip, + clipCount) of pre-compute chunk `pre`, whose
// sub-triangles are [first, + count).
struct ChunkPlan {
  size_t firstClip, clipCount, first, count, pre;
};
// Appends the chunks of clip triangles [first, end) (one pre-compute chunk's), each with at most `maxSubs`
// sub-triangles (or one clip triangle's); `offsets` the exclusive scan of the clip triangles' counts.
void planChunks(std::vector<ChunkPlan>& plan, const std::vector<uint64_t>& offsets, size_t first, size_t end,
                uint64_t maxSubs, size_t pre) {
  while (first < end) {
    size_t last = first;
    while (last < end && offsets[last + 1] - offsets[first] <= maxSubs) ++last;
    plan.push_back({first, last - first, offsets[first], offsets[last] - offsets[first], pre});
    first = last;
  }
}

// The pre-compute's and the deform stage's dispatches, each followed by a barrier.
struct Kernels {
  Backend& B;
  const DeformSessionOptions& o;

  void dispatch(const char* kernel, const char* label, const void* params, size_t paramsSize, size_t threads,
                std::vector<BufferBinding> buffers) const {
    Dispatch d;
    d.kernel = kernel;
    d.label = label;
    d.variant = o.variant;
    d.params = params;
    d.paramsSize = paramsSize;
    d.buffers = std::move(buffers);
    gridFor(threads, B.info().limits, d.groups);
    B.dispatch(d);
    B.barrier();
  }
  // The clip kernels' parameters and bindings (a pre-compute chunk's inputs), for both passes.
  gpu::ClipParams clipParams(const ClipRanges& r, size_t first, size_t count) const {
    gpu::ClipParams params;
    const PackedTable& T = packedTable();
    params.table = {T.nmax, T.vertexWord, T.triangleWord, 0};
    params.target = {float(o.edgeLength), 0, 0, 0};
    params.range = {uint32_t(first), uint32_t(count), 0, 0};
    r.name(params);
    return params;
  }
  static std::vector<BufferBinding> clipBindings(const PreChunkInputs& c, std::vector<BufferBinding> extra) {
    std::vector<BufferBinding> b = {{SFFD_BINDING_CLIP_REALS, c.reals}, {SFFD_BINDING_CLIP_WORDS, c.words}};
    b.insert(b.end(), extra.begin(), extra.end());
    return b;
  }
  // pn_triangles: the chunk's PN records from its parents.
  void pn(const PreChunkInputs& c) const {
    const ClipRanges& R = c.ranges;
    if (!R.parents) return;
    gpu::PnParams params;
    params.range = {0, uint32_t(R.parents), uint32_t(R.normals), 0};
    dispatch("pn_triangles", "pn", &params, sizeof(params), R.parents,
             {{SFFD_BINDING_MESH_VERTICES, c.reals, 0, R.byteOf(R.slotNormals)},
              {SFFD_BINDING_MESH_TRIANGLES, c.words, R.triangles * 4, R.parents * 4 * SFFD_MESH_TRIANGLE_STRIDE * 4},
              {SFFD_BINDING_MESH_SLOT_NORMALS, c.reals, R.byteOf(R.slotNormals), R.byteOf(R.pn - R.slotNormals)},
              {SFFD_BINDING_PN_OUT, c.reals, R.byteOf(R.pn), R.byteOf(SFFD_PN_STRIDE * R.parents)}});
  }
  // clip_count: the sub-triangles of each of the chunk's clip triangles, into `counts`.
  void clipCount(const PreChunkInputs& c, uint32_t* counts) const {
    if (!c.ranges.clips) return;
    gpu::ClipParams params = clipParams(c.ranges, 0, c.ranges.clips);
    dispatch("clip_count", "clip_count", &params, sizeof(params), c.ranges.clips, clipBindings(c, {}));
    B.download(c.words, c.ranges.counts * 4, counts, c.ranges.clips * 4);
  }
  // clip_write: the records of the chunk's clip triangles [first, + count), the first at `offsets[0]` of
  // `headers` and `records` (offsets relative to the first's).
  void clipWrite(const PreChunkInputs& in, size_t first, size_t count, const uint32_t* offsets, BufferId headers,
                 BufferId records) const {
    B.upload(in.words, (in.ranges.counts + first) * 4, offsets, count * 4);
    gpu::ClipParams params = clipParams(in.ranges, first, count);
    dispatch("clip_write", "clip_write", &params, sizeof(params), count,
             clipBindings(in, {{SFFD_BINDING_SUB_HEADERS, headers}, {SFFD_BINDING_SUB_RECORDS, records}}));
  }
  // The deform kernel (or the split's four) over `count` sub-triangles.
  void deform(gpu::DeformParams params, size_t count, int fitPoints, const DeformBuffers& buffers) const {
    params.range = {0, uint32_t(count), uint32_t(fitPoints), uint32_t(o.level)};
    deformOutSections(params, count, o.level, fitPoints, o.split);
    dispatchDeform(B, params, buffers, count, o.variant, o.split);
  }
};

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
    throw deviceError(backend.info().name + " has no double-precision shader support; use --precision float");
  Impl& I = *impl_;
  const bool f64 = options.variant.f64;
  I.realSize = f64 ? 8 : 4;
  I.structure = lattice;
  // A copy only where the creases are still to be applied.
  Mesh withCreases;
  if (!input.normalsFromFile && !options.creasesApplied) {
    withCreases = input;
    applyCreaseAngle(withCreases, options.creaseAngleDeg);
  }
  const Mesh& mesh = input.normalsFromFile || options.creasesApplied ? input : withCreases;
  I.mesh = prepareMesh(mesh);
  I.triangles = I.mesh.triangleCount();
  int s = options.samples > 0 ? options.samples : lattice.degree[0] + lattice.degree[1] + lattice.degree[2];
  I.fit = makeFitTable(std::max(3, s));
  auto up = [&](const std::vector<double>& v) {
    std::vector<unsigned char> b = realBytes(v, f64);
    return I.upload(backend, b.data(), b.size());
  };
  PackedLattice packed = packLattice(lattice);
  I.frame = up(deformFrameRange(packed, I.fit.data));
  I.coeffs = up(packed.coeffs);
  if (streamed()) {   // the clip triangles are made, and everything run, a chunk at a time (streamChunks)
    if (&mesh == &withCreases) I.creased = std::move(withCreases);
    I.clipSource = &mesh == &input ? &input : &I.creased;
    I.clipBuilder = std::make_unique<ClipTriangleBuilder>(*I.clipSource, options.edgeLength, splitPatternTable().nmax());
    // The chunks read the slot normals' part of the topology (PreparedMesh::slotNormals), not the adjacency.
    I.mesh.topology.neighbour = {}, I.mesh.topology.neighbourEdge = {};
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
  if (options.once) {   // only a repeated precompute() reads them
    for (PreChunkInputs& c : I.pre) I.drop(backend, c.reals), I.drop(backend, c.words);
    inputsReleased_ = true;
  }
}

void DeformSession::requireOnce() const {
  if (!options_.once) throw std::logic_error("DeformSession: release without options().once");
}

void DeformSession::releaseRecords() {
  requireOnce();
  for (Impl::ChunkBuffers& c : impl_->chunkBuffers) impl_->drop(backend_, c.headers), impl_->drop(backend_, c.records);
  recordsReleased_ = true;
}

void DeformSession::releaseOutput(size_t chunk) {
  requireOnce();
  impl_->drop(backend_, chunks_.at(chunk).output);
}

size_t DeformSession::precomputeChunks() const { return impl_->pre.size(); }

DeformSession::~DeformSession() {
  for (BufferId b : impl_->owned) backend_.destroyBuffer(b);
}

namespace {

// Sums the dispatch times by stage (GPU time; the stage's wall share when the device has no timestamps).
void sumStages(SessionTimings& t) {
  t.pnMs = t.clipMs = t.deformMs = 0;
  for (const DispatchTiming& d : t.dispatches) {
    double ms = std::max(d.gpuMs, 0.0);
    traceFirstDispatch(d.label, d.gpuMs);
    if (d.label == "pn") t.pnMs += ms;
    else if (d.label.rfind("clip", 0) == 0) t.clipMs += ms;
    else if (d.label.rfind("deform", 0) == 0) t.deformMs += ms;
  }
}

}  // namespace

const SessionTimings& DeformSession::precompute(const StageProgress& progress) {
  if (inputsReleased_) throw Error(ErrorKind::Input, "the pre-compute's inputs were freed (DeformOptions::once)");
  if (streamed()) throw Error(ErrorKind::Input, "a one-shot session runs its pre-compute chunk by chunk (streamChunks)");
  Impl& I = *impl_;
  Backend& B = backend_;
  const Kernels K{B, options_};
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
    for (const PreChunkInputs& c : I.pre) K.clipCount(c, &counts[c.ranges.firstClip]);
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
  if (recordsReleased_) throw Error(ErrorKind::Input, "the sub-triangle records were freed after one deformation (DeformOptions::once)");
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
  const Kernels K{B, options_};
  for (size_t ci = 0; ci < chunks_.size(); ++ci) {
    const Chunk& c = chunks_[ci];
    if (!c.count) continue;
    K.deform(I.deformParams, c.count, I.fit.points, {I.coeffs, I.frame, I.chunkBuffers[ci].records, c.output});
    if (options_.once) {   // one deformation: the records' pre-images read now, so each chunk's records go at once
      if (!takenPreImages_) takenPreImages_.emplace(), takenPreImages_->parent.reserve(subCount_), takenPreImages_->lam.reserve(9 * subCount_);
      readPreImages(I.chunkBuffers[ci].headers, I.chunkBuffers[ci].records, c.count, *takenPreImages_);
      I.drop(B, I.chunkBuffers[ci].headers), I.drop(B, I.chunkBuffers[ci].records);
    }
    if (progress) progress("deform", double(ci + 1) / double(chunks_.size() + 1));
  }
  B.finish();
  if (options_.once) recordsReleased_ = true;
  timings_.dispatches = B.takeTimings();
  sumStages(timings_);
  timings_.wallMs = msSince(t0);
  if (!B.info().limits.timestamps) timings_.deformMs = timings_.wallMs;
  return timings_;
}

const SessionTimings& DeformSession::streamChunks(const ChunkReader& read, const StageProgress& progress) {
  if (!streamed()) throw std::logic_error("DeformSession: streamChunks without options().once (regular clipping)");
  if (recordsReleased_) throw Error(ErrorKind::Input, "the one-shot session's chunks were already streamed (DeformOptions::once)");
  if (!deformed_) throw Error(ErrorKind::Input, "DeformSession: streamChunks before deform()");
  recordsReleased_ = true;   // once, also when `read` throws half way
  Impl& I = *impl_;
  Backend& B = backend_;
  const Kernels K{B, options_};
  const DeviceLimits& lim = B.info().limits;
  auto t0 = std::chrono::steady_clock::now();
  timings_ = {};
  const uint64_t nv = I.mesh.positions.size() / 4, nt = I.triangles;
  const SubBytes bytes = subBytesOf(options_, I.realSize, I.fit.points);
  const uint64_t maxSubsOfBinding = maxChunkSubs(lim, bytes, options_.maxChunkSubTriangles);
  auto fits = [&](const ClipRanges& r) {
    return r.byteOf(r.realElements) <= lim.maxStorageBufferRange && r.words * 4 <= lim.maxStorageBufferRange;
  };
  ClipTriangles clips;               // the chunk's
  std::vector<ClipTriangle> next;    // parent p's, made but not yet in a chunk
  bool nextMade = false;
  std::vector<uint32_t> counts, chunkOffsets;
  std::vector<uint64_t> offsets;
  std::vector<ChunkPlan> plan;
  uint64_t p = 0, firstClip = 0;
  subCount_ = 0;
  I.makeVertexSection(clipRanges(nv, 0, 0, 0, 0, I.realSize));
  I.mesh.positions = {};   // in the vertex section now; the slot normals read the normals
  while (p < nt) {
    // The chunk's parents: as many as keep its inputs within one binding and kStreamedChunkBytes.
    const uint64_t p0 = p;
    clips.triangles.clear();
    ClipRanges r = clipRanges(nv, p0, 0, firstClip, 0, I.realSize);
    for (; p < nt && (!options_.maxChunkParents || p - p0 < options_.maxChunkParents); ++p) {
      if (!nextMade) next.clear(), I.clipBuilder->add(uint32_t(p), next), nextMade = true;
      const ClipRanges grown = clipRanges(nv, p0, p + 1 - p0, firstClip, clips.triangles.size() + next.size(), I.realSize);
      if (!fits(grown) || (r.parents && grown.byteOf(grown.realElements - grown.slotNormals) > kStreamedChunkBytes)) break;
      r = grown;
      clips.triangles.insert(clips.triangles.end(), next.begin(), next.end());
      nextMade = false;
    }
    if (!r.parents) throw tooLargeForOneBinding(nv, p0, I.realSize, lim.maxStorageBufferRange);
    const PreChunkInputs in = I.uploadStreamedInputs(B, r, packClip(clips));
    K.pn(in);
    counts.assign(r.clips, 0);
    K.clipCount(in, counts.data());
    offsets.assign(r.clips + 1, 0);
    uint64_t maxSubs = maxSubsOfBinding;
    for (size_t i = 0; i < r.clips; ++i) offsets[i + 1] = offsets[i] + counts[i], maxSubs = std::max<uint64_t>(maxSubs, counts[i]);
    plan.clear();
    planChunks(plan, offsets, 0, r.clips, maxSubs, 0);
    // Each chunk of sub-triangles clipped, deformed, read and freed before the next is made.
    for (const ChunkPlan& pl : plan) {
      Chunk c;
      c.first = subCount_ + pl.first;
      c.count = pl.count;
      c.output = I.make(B, pl.count * bytes.out);
      c.patchesOffset = pl.count * bytes.tess;
      BufferId headers = I.make(B, pl.count * 16), records = I.make(B, pl.count * bytes.record);
      chunkOffsets.resize(pl.clipCount);
      for (size_t i = 0; i < pl.clipCount; ++i) chunkOffsets[i] = uint32_t(offsets[pl.firstClip + i] - offsets[pl.firstClip]);
      K.clipWrite(in, pl.firstClip, pl.clipCount, chunkOffsets.data(), headers, records);
      K.deform(I.deformParams, c.count, I.fit.points, {I.coeffs, I.frame, records, c.output});
      SubTrianglePreImages pre;
      readPreImages(headers, records, c.count, pre);
      I.drop(B, headers), I.drop(B, records);
      read(c, pre);
      I.drop(B, c.output);
    }
    subCount_ += offsets.back();
    firstClip += r.clips;
    BufferId reals = in.reals, words = in.words;
    I.drop(B, reals), I.drop(B, words);
    if (progress) progress("deform", double(p) / double(nt + 1));
  }
  I.vertexSection = {};
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
  if (recordsReleased_) throw Error(ErrorKind::Input, "the sub-triangle records were freed after one deformation (DeformOptions::once)");
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
  if (takenPreImages_) {   // one deformation: read as deform() ran
    SubTrianglePreImages P = std::move(*takenPreImages_);
    takenPreImages_.reset();
    return P;
  }
  if (streamed()) throw Error(ErrorKind::Input, kStreamedOnly);
  if (recordsReleased_) throw Error(ErrorKind::Input, "the sub-triangle records were freed after one deformation (DeformOptions::once)");
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
    if (!c.output) throw Error(ErrorKind::Input, "the outputs were freed after one deformation (DeformOptions::once)");
    downloadRealsInto(backend_, c.output, c.patchesOffset, c.count * patchReals, options_.variant.f64,
                      &out.patches[c.first * patchReals], scratch);
    downloadRealsInto(backend_, c.output, 0, c.count * tessReals, options_.variant.f64, &out.tess[c.first * tessReals], scratch);
  }
  out.timings = timings_.dispatches;
  out.wallMs = timings_.wallMs;
  return out;
}

}  // namespace sffd
