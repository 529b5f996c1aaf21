#include "pipelines/stream_budget.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "io/piece_queue.h"
#include "kernels/clip/split_pattern_table.h"
#include "pipelines/deform_session_internal.h"
#include "pipelines/deformer_internal.h"
#include "pipelines/patch_output.h"

namespace sffd {
namespace {

constexpr double kMiB = 1024.0 * 1024.0;
// The program, its libraries and the CPU device's threads (a tiny job's peak RSS: 23 MiB on the CPU
// device); a graphics driver and its shader compiler on top (Mesa's: 77 MiB more for a tiny job, 99 MiB
// more than the CPU device's at 1 M triangles; NVIDIA's 83 MiB, docs/performance/gpu.md).
constexpr double kProgramBytes = 32 * kMiB, kDriverBytes = 128 * kMiB;

// The segments of an edge as the clipping counts them (regular_clip.cpp segmentCount), a hair long: the
// kernels count them in float.
double segments(const glm::dvec3& a, const glm::dvec3& b, double l) {
  return std::max(1.0, std::ceil(glm::length(b - a) / l * (1 + 1e-5)));
}

uint64_t bytesOf(double b) { return b >= 1.8e19 ? UINT64_MAX : uint64_t(b); }

// What the streamed weld holds (PatchWelder::forgetPassedLocations), as differences from parent to parent
// (Locations::of): what each parent adds and until which parent it stays.
class WeldFront {
 public:
  explicit WeldFront(const Mesh& mesh) : dLoc_(mesh.triangles.size() + 1), dVert_(mesh.triangles.size() + 1) {
    // Per weld id (a location of the input) its first and last parent.
    uint32_t nw = 0;
    for (uint32_t w : mesh.weldId) nw = std::max(nw, w + 1);
    first_.assign(nw, UINT32_MAX), last_.assign(nw, 0);
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
      for (uint32_t v : mesh.triangles[t]) {
        const uint32_t w = mesh.weldId[v];
        first_[w] = std::min(first_[w], t), last_[w] = t;
      }
  }
  // Parent t's corner at weld id w, with `vertices` vertices of t there: from its first parent to its last.
  void corner(uint32_t t, uint32_t w, double vertices) { hold(t, last_[w], first_[w] == t ? 1 : 0, vertices); }
  // `points` of t's input edge between weld ids a and b (its ends not counted), a vertex each: until either
  // end's last parent (a shared edge counted from both sides).
  void edge(uint32_t t, uint32_t a, uint32_t b, double points) {
    if (a != b) hold(t, std::min(last_[a], last_[b]), points, points);
  }
  // `points` of t's patches: held while t is the current parent.
  void patches(uint32_t t, double points) { hold(t, t, points, points); }
  // The most locations and vertices held at once, into s.
  void most(StreamShape& s) const {
    double locations = 0, vertices = 0;
    for (size_t t = 0; t + 1 < dLoc_.size(); ++t) {
      locations += dLoc_[t], vertices += dVert_[t];
      s.frontLocations = std::max(s.frontLocations, locations);
      s.frontVertices = std::max(s.frontVertices, vertices);
    }
  }

 private:
  void hold(size_t from, size_t until, double locations, double vertices) {
    dLoc_[from] += locations, dLoc_[until + 1] -= locations;
    dVert_[from] += vertices, dVert_[until + 1] -= vertices;
  }
  std::vector<uint32_t> first_, last_;
  std::vector<double> dLoc_, dVert_;
};

// The welded result's side of a stream of `s.subTriangles` patches at `level`: a weld slice (pre-images,
// positions, normals, carried values) and the piece it makes, the writer's two buffers (1 MiB and a piece
// as text, grown: twice), none larger than the job's whole output, and its queue's copies of pieces
// (PieceQueue: those waiting, the one written, the one being copied, a spare); and the weld (PatchWelder::
// forgetPassedLocations): between compactions up to twice the front (at least kCompactAt) and a slice's;
// per location its record, until and number (grown: twice) and up to 8 hash slots (grown twice, the old
// table beside the new); per vertex its normal, carried values, location, next and number (grown: twice).
// No more than the job's patch vertices, though.
double weldBytes(const Mesh& mesh, int level, const StreamShape& s) {
  const double nv = tessVertexCount(level), tris = tessTriangleCount(level);
  const double carried = (mesh.texcoords.empty() ? 0 : 16) + (mesh.colors.empty() ? 0 : 32);
  const double slicePatches = kWeldSlicePatches, patchVertices = s.subTriangles * nv;
  const double slice = slicePatches * (nv * (72 + 2 * carried + 60) + tris * 20);
  const double writer = std::min(4 * (kMiB + slicePatches * (nv * 400 + tris * 40)), 2 * s.subTriangles * (nv * 400 + tris * 40));
  const double queued = double(PieceQueue::kWaiting + 3) * slicePatches * (nv * (48 + carried) + tris * 12);
  const double locations = std::min(patchVertices, std::max(double(PatchWelder::kCompactAt), 2 * s.frontLocations) + slicePatches * nv);
  const double vertices = std::min(patchVertices, locations + s.frontVertices);
  return slice + writer + queued + locations * (2 * 40 + 8 * 32 + 4) + vertices * (2 * (36 + carried) + 4);
}

}  // namespace

bool deviceIsHost(const DeviceInfo& info) { return info.api == "cpu" || info.type == "cpu"; }

StreamShape streamShape(const Mesh& mesh, double l, int level, uint64_t chunkParents) {
  const size_t T = mesh.triangles.size();
  const double nmax = splitPatternTable().nmax(), nv = tessVertexCount(level);
  // A corner from its first parent to its last, with a vertex for each parent there (creases split them);
  // an input edge's points from each parent on it; the points of the current parent's patches.
  WeldFront front(mesh);
  std::vector<double> subs(T);
  StreamShape s;
  for (uint32_t t = 0; t < T; ++t) {
    const auto& tri = mesh.triangles[t];
    const uint32_t w[3] = {mesh.weldId[tri[0]], mesh.weldId[tri[1]], mesh.weldId[tri[2]]};
    double c = 1;
    for (int e = 0; e < 3; ++e) {
      const int f = (e + 1) % 3;
      const double n = segments(mesh.positions[tri[e]], mesh.positions[tri[f]], l);
      c = std::max(c, n);
      front.corner(t, w[e], 1);
      // A pre-split edge's halves are counted each rounded up: at most 2n + 1 segments.
      front.edge(t, w[e], w[f], (n <= nmax ? n : 2 * n + 1) * level - 1);
    }
    const bool presplit = c > nmax;
    subs[t] = presplit ? 2 * c * c : c * c;
    s.subTriangles += subs[t];
    if (presplit) s.presplitSubTriangles += subs[t], s.parentClips = std::max(s.parentClips, subs[t]);
    front.patches(t, subs[t] * nv);
  }
  front.most(s);
  double window = 0;
  for (size_t t = 0; t < T; ++t) {
    window += subs[t] - (t >= chunkParents ? subs[t - chunkParents] : 0);
    s.chunkSubTriangles = std::max(s.chunkSubTriangles, window);
  }
  return s;
}

StreamShape accurateStreamShape(const Mesh& mesh, const std::vector<SubTriangle>& subs, int level) {
  const double nv = tessVertexCount(level);
  WeldFront front(mesh);
  StreamShape s;
  s.subTriangles = s.chunkSubTriangles = double(subs.size());
  size_t i = 0;
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const uint32_t w[3] = {mesh.weldId[tri[0]], mesh.weldId[tri[1]], mesh.weldId[tri[2]]};
    // Per parent corner k its patches' vertices there; per parent edge e (corners e and e + 1, where the
    // barycentric e + 2 is 0) the points of its patches on it, a vertex each (Locations::of).
    double cornerVertices[3] = {0, 0, 0}, edgePoints[3] = {0, 0, 0};
    auto at = [&](const glm::dvec3& lam, double points) {
      const int zeros = (lam[0] == 0) + (lam[1] == 0) + (lam[2] == 0);
      if (zeros == 2) cornerVertices[lam[0] != 0 ? 0 : lam[1] != 0 ? 1 : 2] += points;
      if (zeros != 1) return;   // inside the parent: the parent's own
      const int a = (lam[0] == 0 ? 1 : lam[1] == 0 ? 2 : 0);   // the edge from corner a to a + 1
      (w[a] == w[(a + 1) % 3] ? cornerVertices[a] : edgePoints[a]) += points;
    };
    size_t n = 0;
    for (; i < subs.size() && subs[i].parent == t; ++i, ++n)
      for (int k = 0; k < 3; ++k) {
        const glm::dvec3 &a = subs[i].corners[k].lam, &b = subs[i].corners[(k + 1) % 3].lam;
        at(a, 1);
        // The level - 1 points inside the patch's edge from a to b: zero where both are.
        at(glm::dvec3(a[0] == 0 && b[0] == 0 ? 0 : 1, a[1] == 0 && b[1] == 0 ? 0 : 1, a[2] == 0 && b[2] == 0 ? 0 : 1), level - 1);
      }
    for (int k = 0; k < 3; ++k) front.corner(t, w[k], cornerVertices[k]);
    for (int e = 0; e < 3; ++e) front.edge(t, w[e], w[(e + 1) % 3], edgePoints[e]);
    front.patches(t, double(n) * nv);
  }
  if (i != subs.size()) throw std::logic_error("accurateStreamShape: sub-triangles out of parent order");
  front.most(s);
  return s;
}

JobEstimate estimateStreamedSmoothJob(const Mesh& mesh, const DeformSessionOptions& o, const DeviceInfo& device,
                                      uint64_t otherMeshBytes) {
  const size_t realSize = o.variant.f64 ? 8 : 4;
  const double r4 = 4.0 * double(realSize), T = double(mesh.triangles.size()), V = double(mesh.positions.size());
  const double nv = tessVertexCount(o.level), nmax = splitPatternTable().nmax();
  // A chunk's parents: each takes its slot normals, its PN record and at least one clip triangle within
  // kStreamedChunkBytes, which one parent may exceed alone (DeformSession::streamChunks).
  uint64_t chunkParents = kStreamedChunkBytes / uint64_t((SFFD_SLOT_NORMAL_STRIDE + SFFD_PN_STRIDE + SFFD_CLIP_REAL_STRIDE) * r4);
  ++chunkParents;
  if (o.maxChunkParents) chunkParents = std::min<uint64_t>(chunkParents, o.maxChunkParents);
  const StreamShape s = streamShape(mesh, o.edgeLength, o.level, chunkParents);
  const bool host = deviceIsHost(device);
  // Throughout: the program, a graphics driver, the mesh's copies.
  const double always = kProgramBytes + (device.api == "cpu" ? 0 : kDriverBytes) + double(meshHeldBytes(mesh) + otherMeshBytes);

  // Phase 1, the creases applied to the Deformer's copy where the normals were not read (applyCreaseAngle):
  // per triangle its face normal, corner and dihedral angles, adjacency (and the sorted edge records that
  // make it) and fan sets; per vertex its fan, the fan's normal sum and the copies' index.
  const double creases = mesh.normalsFromFile ? 0 : 112 * T + 120 * V;
  // Phase 2, prepareMesh: positions and normals (4 doubles each), triangles (8 words), the topology
  // (adjacency 15 bytes, slots 30 bytes a triangle) and the sorted edge records that make it (48 bytes).
  const double prepare = 64 * V + 32 * T + 93 * T;

  // Phase 3, the stream. Kept throughout: the prepared normals and triangles, the topology's slots, the
  // vertex section, the clip builder's split points (a map node each, at most one a pre-split
  // sub-triangle), the weld's last parent and corner slot per weld id (the latter grown: twice).
  const double kept = 32 * V + 62 * T + 2 * V * r4 + 96 * s.presplitSubTriangles + 12 * V;
  // One chunk's inputs: its parents' and clip triangles' sections (within kStreamedChunkBytes, or a first
  // parent's alone), its words (the split-pattern table, 8 a parent, 9 a clip triangle); on the host its
  // clip triangles (made, gathered, room to grow), packed (8 words and 36 doubles each), counts and offsets.
  const double parents = std::min(T, double(chunkParents));
  const double clips = std::min(s.chunkSubTriangles, double(kStreamedChunkBytes) / (SFFD_CLIP_REAL_STRIDE * r4) + s.parentClips);
  const double perParent = (SFFD_SLOT_NORMAL_STRIDE + SFFD_PN_STRIDE) * r4, perClip = SFFD_CLIP_REAL_STRIDE * r4;
  const double sections = std::min(double(kStreamedChunkBytes) + perParent + s.parentClips * perClip, perParent * parents + perClip * clips) +
                          3 * SFFD_SECTION_ALIGN;
  const double words = 4.0 * (double(packedTable().wordCount) + 8 * parents + 9 * clips) + 3 * SFFD_SECTION_ALIGN;
  const double inputs = 2 * V * r4 + sections + words;   // on the device: the vertex section again
  const double clipHost = clips * (3.0 * sizeof(ClipTriangle) + 32 + 288 + 20) + sections + words;
  // One deform chunk: at most the chunk's sub-triangles and what one binding holds (or one clip triangle's);
  // its headers, records and output on the device; downloaded, its headers and records and the pre-images
  // (76 bytes a sub-triangle, grown: twice).
  const SubBytes sub = subBytesOf(o, realSize, makeFitTable(std::max(3, o.samples)).points);
  const double perBinding = double(maxChunkSubs(device.limits, sub, o.maxChunkSubTriangles));
  const double deformSubs = std::min(s.chunkSubTriangles, std::max(perBinding, nmax * nmax));
  const double chunkDevice = inputs + deformSubs * double(16 + sub.record + sub.out);
  const double preImages = deformSubs * double(16 + sub.record + 152);
  // The result: a download block (none larger than the job's whole output), then the weld and the writer.
  const double patchVertices = s.subTriangles * nv;
  const double block = std::min(std::max(double(kSmoothDownloadBytes), double(kWeldSlicePatches) * sub.tess), deformSubs * sub.tess);
  // A GPU's staging: a chunk's uploads and the largest download.
  const double staging = host ? 0 : inputs + std::max(block, deformSubs * double(sub.record));
  // The chunk's buffers are kept from chunk to chunk, with room to grow (kStreamBufferGrowth).
  const double keptDevice = chunkDevice * (1 + 1.0 / kStreamBufferGrowth);
  const double stream = kept + clipHost + preImages + block + weldBytes(mesh, o.level, s) + (host ? keptDevice : staging);

  JobEstimate e;
  e.hostBytes = bytesOf(always + std::max({creases, prepare, stream}));
  e.deviceBytes = bytesOf(keptDevice);
  e.chunkVertices = bytesOf(deformSubs * nv);
  e.chunks = std::max<uint64_t>(1, (uint64_t(T) + chunkParents - 1) / chunkParents);
  e.outputVertices = bytesOf(patchVertices);
  return e;
}

JobEstimate estimateStreamedAccurateJob(const Mesh& mesh, const AccurateStream& run, const DeviceInfo& device,
                                        uint64_t otherMeshBytes) {
  const AccurateJob& job = *run.job;
  const StreamShape s = accurateStreamShape(mesh, job.subs, job.level);
  const double nv = tessVertexCount(job.level), V = double(mesh.positions.size()), r4 = 4.0 * double(run.realBytes);
  const bool host = deviceIsHost(device);
  const double always = kProgramBytes + (device.api == "cpu" ? 0 : kDriverBytes) + double(meshHeldBytes(mesh) + otherMeshBytes);
  // What the job's arrays touch: the clipping reserves two sub-triangles a parent, address space that is
  // not touched beyond those it makes (but for a huge page each).
  const double hugePage = 2 * kMiB;
  const double subs = double(job.subs.size() * sizeof(SubTriangle)) + hugePage;
  // Phase 1, the clipping: its sub-triangles, grown (the old array beside the new: twice at most).
  const double clip = 2 * subs;
  // Phase 2, the stream. Kept throughout: the job (sub-triangles and their corners), the run's frame, the
  // weld's last parent and corner slot per weld id (the latter grown: twice).
  const double kept = subs + double(job.corners.size() * sizeof(double)) + hugePage + double(run.hostBytes) + 12 * V;
  // One chunk: its corners copied and converted for their upload (uploadCorners), and read back a block
  // at a time, positions and normals (forEachChunk).
  const double chunk = double(std::min<uint64_t>(run.chunkPatches, job.count()));
  const double corners = chunk * SFFD_ACC_CORNER_STRIDE * (4 * sizeof(double) + r4);
  const double patchBytes = nv * r4, blockPatches = std::min(chunk, double(accurateBlockPatches(size_t(patchBytes))));
  const double block = 2 * blockPatches * patchBytes;
  // A GPU's staging: the corners' upload and the largest download (half a block).
  const double staging = chunk * SFFD_ACC_CORNER_STRIDE * r4 + blockPatches * patchBytes;
  const double stream = kept + corners + block + weldBytes(mesh, job.level, s) + (host ? double(run.deviceBytes) : staging);

  JobEstimate e;
  e.hostBytes = bytesOf(always + std::max(clip, stream));
  e.deviceBytes = run.deviceBytes;
  e.chunkVertices = bytesOf(chunk * nv);
  e.chunks = run.chunkPatches ? (job.count() + run.chunkPatches - 1) / run.chunkPatches : 0;
  e.outputVertices = bytesOf(s.subTriangles * nv);
  return e;
}

}  // namespace sffd
