// DeformSession::streamChunks: a one-shot session (DeformSessionOptions::once) runs from
// the mesh a few parents at a time, each chunk's inputs, records and outputs made, used and done with before
// the next, so that only one chunk's exist at a time (docs/performance/scaling.md), in device buffers the
// chunks share (Impl::StreamBuffer).
#include <chrono>

#include "core/huge_pages.h"
#include "core/wall_clock.h"
#include "kernels/clip/knot_box_clip.h"
#include "pipelines/device_reals.h"
#include "pipelines/deform_session_internal.h"

namespace sffd {

const SessionTimings& DeformSession::streamChunks(const ChunkReader& read, const StageProgress& progress) {
  if (!streamed()) throw std::logic_error("DeformSession: streamChunks without options().once");
  if (recordsReleased_) throw Error(ErrorKind::Input, "the one-shot session's chunks were already streamed (DeformOptions::once)");
  if (!deformed_) throw Error(ErrorKind::Input, "DeformSession: streamChunks before deform()");
  recordsReleased_ = true;   // once, also when `read` throws half way
  Impl& I = *impl_;
  Backend& B = backend_;
  const SessionKernels K{B, options_, I.deformVariant};
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
  Impl::StreamBuffer realsBuffer, wordsBuffer, outputBuffer, headersBuffer, recordsBuffer;
  uint64_t p = 0, firstClip = 0;
  subCount_ = 0;
  // Knot-box clipping: the chunk's PN records come to the host, its sub-triangles' records are made there
  // (recordsFromSubTriangles) and uploaded, as many a time as one binding holds, each lot deformed and read.
  auto streamKnotBoxChunk = [&](const PreChunkInputs& in, const std::vector<SubTriangle>& subs) {
    const ClipRanges& r = in.ranges;
    const uint64_t perParent = SFFD_PN_STRIDE * 4 * I.realSize;
    std::vector<unsigned char> pnBytes(r.parents * perParent);
    B.download(in.reals, r.byteOf(r.pn), pnBytes.data(), pnBytes.size());
    const std::vector<double> pn = doublesOf(pnBytes, options_.variant.f64);
    const SubTriangleRecords R = recordsFromSubTriangles(I.mesh, pn, r.firstParent, r.parents, subs, options_.variant);
    for (uint64_t first = 0; first < subs.size(); first += maxSubsOfBinding) {
      Chunk c;
      c.first = subCount_ + first;
      c.count = std::min<uint64_t>(maxSubsOfBinding, subs.size() - first);
      c.output = outputBuffer.atLeast(I, B, c.count * bytes.out);
      c.patchesOffset = c.count * bytes.tess;
      const BufferId headers = headersBuffer.atLeast(I, B, c.count * 16), records = recordsBuffer.atLeast(I, B, c.count * bytes.record);
      B.upload(headers, 0, &R.headers[4 * first], c.count * 16);
      const std::vector<unsigned char> b = realBytes(
          std::vector<double>(R.records.begin() + first * SFFD_SUB_STRIDE * 4, R.records.begin() + (first + c.count) * SFFD_SUB_STRIDE * 4),
          options_.variant.f64);
      B.upload(records, 0, b.data(), b.size());
      K.deform(I.deformParams, c.count, I.fit.points, {I.coeffs, I.frame, records, c.output});
      SubTrianglePreImages pre;
      readPreImages(headers, records, c.count, pre);
      read(c, pre);
    }
    subCount_ += subs.size();
  };
  const bool knotBox = options_.knotBoxClip;
  std::vector<SubTriangle> knotBoxSubs;   // knot-box clipping: the chunk's sub-triangles
  I.makeVertexSection(clipRanges(nv, 0, 0, 0, 0, I.realSize));
  // In the vertex section now; the slot normals read the normals (the knot-box records read the positions).
  if (!knotBox) freeStorage(I.mesh.positions);
  while (p < nt) {
    // The chunk's parents: as many as keep its inputs within one binding and kStreamedChunkBytes (knot-box
    // clipping: no clip triangles on the device, only the parents' sections for pn_triangles).
    const uint64_t p0 = p;
    clips.triangles.clear();
    ClipRanges r = clipRanges(nv, p0, 0, firstClip, 0, I.realSize);
    for (; p < nt && (!options_.maxChunkParents || p - p0 < options_.maxChunkParents); ++p) {
      if (knotBox) next.clear(), nextMade = true;
      if (!nextMade) next.clear(), I.clipBuilder->add(uint32_t(p), next), nextMade = true;
      const ClipRanges grown = clipRanges(nv, p0, p + 1 - p0, firstClip, clips.triangles.size() + next.size(), I.realSize);
      if (!fits(grown) || (r.parents && grown.byteOf(grown.realElements - grown.slotNormals) > kStreamedChunkBytes)) break;
      r = grown;
      clips.triangles.insert(clips.triangles.end(), next.begin(), next.end());
      nextMade = false;
    }
    if (!r.parents) throw tooLargeForOneBinding(nv, p0, I.realSize, lim.maxStorageBufferRange);
    bool freshReals = false, freshWords = false;
    const BufferId reals = realsBuffer.atLeast(I, B, r.byteOf(r.realElements), &freshReals);
    const BufferId words = wordsBuffer.atLeast(I, B, r.words * 4, &freshWords);
    const PreChunkInputs in = I.uploadStreamedInputs(B, r, packClip(clips), reals, freshReals, words, freshWords);
    K.pn(in);
    if (knotBox) {
      knotBoxSubs.clear();
      clipAgainstKnotBoxes(*I.clipSource, I.structure, p0, p, knotBoxSubs);
      streamKnotBoxChunk(in, knotBoxSubs);
      if (progress) progress("deform", double(p) / double(nt + 1));
      continue;
    }
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
      c.output = outputBuffer.atLeast(I, B, pl.count * bytes.out);
      c.patchesOffset = pl.count * bytes.tess;
      const BufferId headers = headersBuffer.atLeast(I, B, pl.count * 16), records = recordsBuffer.atLeast(I, B, pl.count * bytes.record);
      chunkOffsets.resize(pl.clipCount);
      for (size_t i = 0; i < pl.clipCount; ++i) chunkOffsets[i] = uint32_t(offsets[pl.firstClip + i] - offsets[pl.firstClip]);
      K.clipWrite(in, pl.firstClip, pl.clipCount, chunkOffsets.data(), headers, records);
      K.deform(I.deformParams, c.count, I.fit.points, {I.coeffs, I.frame, records, c.output});
      SubTrianglePreImages pre;
      readPreImages(headers, records, c.count, pre);
      read(c, pre);
    }
    subCount_ += offsets.back();
    firstClip += r.clips;
    if (progress) progress("deform", double(p) / double(nt + 1));
  }
  for (Impl::StreamBuffer* b : {&realsBuffer, &wordsBuffer, &outputBuffer, &headersBuffer, &recordsBuffer}) b->drop(I, B);
  freeStorage(I.vertexSection);
  B.finish();
  timings_.dispatches = B.takeTimings();
  sumStages(timings_);
  timings_.wallMs = msSince(t0);
  if (!B.info().limits.timestamps) timings_.deformMs = timings_.wallMs;
  return timings_;
}

}  // namespace sffd
