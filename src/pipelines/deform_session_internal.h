// What deform_session.cpp (the session, its pre-compute and deform stage) and deform_session_stream.cpp
// (a one-shot session run chunk by chunk) share: the session's state, the chunks' sizes and plan, and
// the kernels' dispatches. Not part of any API.
#pragma once
#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <sffd/error.h>
#include "core/huge_pages.h"
#include "core/job_budget.h"
#include "core/kernel_registry.h"
#include "kernels/clip/regular_clip.h"
#include "kernels/smooth/smooth_deform.h"
#include "model/prepared_mesh.h"
#include "pipelines/deform_session.h"
#include "pipelines/patch_output.h"

namespace sffd {

// The most bytes of reals a streamed chunk (DeformSession::streamChunks) takes beyond the vertices, which
// every chunk repeats: its inputs, records and outputs are all there is of the job's at a time (and what
// estimateStreamedSmoothJob, stream_budget.h, sizes a chunk by).
constexpr uint64_t kStreamedChunkBytes = uint64_t(8) << 20;
// A streamed chunk's buffers (Impl::StreamBuffer) grow by at least 1/kStreamBufferGrowth of their room, so
// they hold up to (1 + 1/kStreamBufferGrowth) times the largest chunk's bytes.
constexpr uint64_t kStreamBufferGrowth = 4;

// A pre-compute chunk's inputs: the clip kernels' two input ranges (all the vertices, then its parents'
// and clip triangles' sections) in buffers of its own, so that no binding exceeds the device's limit;
// pn_triangles reads the mesh's sections and writes the PN records'.
struct PreChunkInputs {
  ClipRanges ranges;
  BufferId reals = 0, words = 0;
};

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
  KernelVariant deformVariant;   // deformVariantOf the session's options and mesh
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
    c.words = make(b, r.words * 4);
    uploadClipWords(b, c.words, r, mesh, pc, true);
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
  // A buffer of the stream's, kept from chunk to chunk and made again only when a chunk needs more room: a
  // fresh buffer is fresh memory, which the CPU device and llvmpipe zero-fill, lavapipe faults in page by
  // page and a discrete GPU's driver allocates (at 1 M triangles 71 chunks made five buffers each). The
  // kernels read only the ranges their parameters name, so what an earlier chunk left beyond them is inert.
  struct StreamBuffer {
    BufferId id = 0;
    uint64_t room = 0;
    // The buffer, with at least `bytes`; `fresh` says whether it was made now. It grows by a quarter
    // (kStreamBufferGrowth) at least, within the binding limit (which every chunk's ranges keep to), so
    // that slowly growing chunks do not make it again each time.
    BufferId atLeast(Impl& I, Backend& B, uint64_t bytes, bool* fresh = nullptr) {
      bytes = std::max<uint64_t>(bytes, 16);
      if (fresh) *fresh = bytes > room;
      if (bytes > room) {
        I.drop(B, id);   // first: the old and the new never exist at once
        room = std::max(bytes, std::min(room + room / kStreamBufferGrowth, B.info().limits.maxStorageBufferRange));
        id = I.make(B, room);
      }
      return id;
    }
    void drop(Impl& I, Backend& B) { I.drop(B, id), room = 0; }
  };
  // Into the stream's buffers (StreamBuffer), which a chunk before may have filled: the vertices' section is
  // uploaded only into a fresh reals buffer, the split-pattern table only into a fresh words buffer.
  PreChunkInputs uploadStreamedInputs(Backend& b, const ClipRanges& r, const PackedClip& pc, BufferId reals,
                                      bool freshReals, BufferId words, bool freshWords) {
    PreChunkInputs c{r, reals, words};
    if (freshReals) b.upload(c.reals, 0, vertexSection.data(), vertexSection.size());
    auto upload = [&](auto zero) {
      using Real = decltype(zero);
      std::vector<Real> own;
      resizeHuge(own, 4 * (r.realElements - r.slotNormals), zero);
      writeClipParentSections(r, mesh, nullptr, pc, own.data());
      b.upload(c.reals, r.byteOf(r.slotNormals), own.data(), own.size() * sizeof(Real));
    };
    realSize == 8 ? upload(0.0) : upload(0.0f);
    uploadClipWords(b, c.words, r, mesh, pc, freshWords);
    return c;
  }
};

inline Error tooLargeForOneBinding(uint64_t vertices, uint64_t parent, size_t realSize, uint64_t limit) {
  const ClipRanges one = clipRanges(vertices, parent, 1, 0, 0, realSize);
  return Error(ErrorKind::Input, "the job's vertices and one triangle's PN record and clip triangles (" +
                                     std::to_string(one.byteOf(one.realElements) >> 20) +
                                     " MiB) exceed one storage binding on this device (" + std::to_string(limit >> 20) +
                                     " MiB); use a coarser mesh");
}

// What one sub-triangle takes on the device: its record, its tessellation and its output range (the
// patches, the tessellation and, split, the samples).
struct SubBytes {
  uint64_t record = 0, tess = 0, out = 0;
};
inline SubBytes subBytesOf(const DeformSessionOptions& o, size_t realSize, int fitPoints) {
  const uint64_t scale = realSize / 4, nv = uint64_t(tessVertexCount(o.level));
  SubBytes b;
  b.record = SFFD_SUB_STRIDE * 16 * scale;
  b.tess = 2 * nv * 16 * scale;
  const uint64_t patch = SFFD_PATCH_STRIDE * 16 * scale, sample = (SFFD_SAMPLE_FIXED + uint64_t(fitPoints)) * 16 * scale;
  b.out = patch + b.tess + (o.split ? sample : 0);
  return b;
}

// The most sub-triangles of a chunk: its records and its output range each within one storage binding.
inline uint64_t maxChunkSubs(const DeviceLimits& lim, const SubBytes& b, size_t cap) {
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
inline void planChunks(std::vector<ChunkPlan>& plan, const std::vector<uint64_t>& offsets, size_t first, size_t end,
                uint64_t maxSubs, size_t pre) {
  while (first < end) {
    size_t last = first;
    while (last < end && offsets[last + 1] - offsets[first] <= maxSubs) ++last;
    plan.push_back({first, last - first, offsets[first], offsets[last] - offsets[first], pre});
    first = last;
  }
}

// The most sub-triangles of a one-shot job that asks for deform_smooth's one-site form: lavapipe 22.3 translates
// it 8 ms quicker and runs it about 0.14 us a sub-triangle slower (the teapot's 7,200: 8.6 -> 9.6 ms), so it pays
// up to about 57,000 (docs/performance/kernels.md "One sample site for a one-shot job").
constexpr double kOneSampleSiteMaxSubTriangles = 20000;

// The deform kernel's variant for a session of `mesh`: a small one-shot job dispatches it once, and on lavapipe
// below Mesa 23 (forDevice keeps the bit only there) translating it costs more than running it.
inline KernelVariant deformVariantOf(const DeformSessionOptions& o, const Mesh& mesh) {
  KernelVariant v = o.variant;
  if (o.once && !o.split && estimateSubTriangles(mesh, o.edgeLength) <= kOneSampleSiteMaxSubTriangles)
    v.assumptions |= SFFD_ASSUME_ONE_SAMPLE_SITE;
  return v;
}

// The pre-compute's and the deform stage's dispatches, each followed by a barrier.
struct SessionKernels {
  Backend& B;
  const DeformSessionOptions& o;
  KernelVariant deformVariant;   // deformVariantOf

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
  // What the session dispatches, in order of first use (Backend::precompile): the knot-box
  // clipping runs on the host.
  std::vector<KernelUse> uses(const gpu::DeformParams& params) const {
    std::vector<KernelUse> k = {{"pn_triangles", o.variant}};
    if (!o.knotBoxClip) k.insert(k.end(), {{"clip_count", o.variant}, {"clip_write", o.variant}});
    for (const KernelUse& d : deformKernels(params, deformVariant, o.split)) k.push_back(d);
    return k;
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
    dispatchDeform(B, params, buffers, count, deformVariant, o.split);
  }
};

// Sums the dispatch times by stage (GPU time; the stage's wall share when the device has no timestamps).
inline void sumStages(SessionTimings& t) {
  t.pnMs = t.clipMs = t.deformMs = 0;
  for (const DispatchTiming& d : t.dispatches) {
    double ms = std::max(d.gpuMs, 0.0);
    traceFirstDispatch(d.label, d.gpuMs);
    if (d.label == "pn") t.pnMs += ms;
    else if (d.label.rfind("clip", 0) == 0) t.clipMs += ms;
    else if (d.label.rfind("deform", 0) == 0) t.deformMs += ms;
  }
}

}  // namespace sffd
