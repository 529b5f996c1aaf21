// Device-resident smooth FFD (Lu & Feng, "Improved smooth FFD"; METHOD.md 3): the pre-compute
// (PN triangles, regular clipping) runs once and its sub-triangle records stay on the device; each
// deform() uploads only the lattice's Bezier coefficients and runs the deform kernel into device
// buffers that a caller on the same GL context can draw from (gl::glBufferObject) or download.
// This is the interactive path (`sffd view`) and the one `sffd bench` times: no host round trip
// between the stages of one deformation.
//
//   DeformSession s(backend, mesh, lattice, {.edgeLength = 0.2});
//   s.deform(lattice);                          // after every lattice edit
//   for (const DeformSession::Chunk& c : s.chunks()) draw(c.output, c.count);
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/backend.h"
#include "model/lattice.h"
#include "model/mesh.h"
#include "kernels/clip/regular_clip.h"
#include "kernels/smooth/smooth_deform.h"

namespace sffd {

struct DeformSessionOptions {
  KernelVariant variant;       // float (fast) by default
  double edgeLength = 0.2;     // the paper's l, in model units (> 0)
  int level = 10;              // tessellation level 1..64
  int samples = 0;             // sampling density s; 0: nu + nv + nw of the lattice (at least 3)
  bool knotBoxClip = false;    // the 2015 clipping (computed on the CPU, records uploaded once)
  bool split = false;          // deform as four dispatches (per-step timings) instead of the fused kernel
  double creaseAngleDeg = kCreaseAngleAuto;  // for a mesh without normals: applyCreaseAngle's threshold
  bool creasesApplied = false;  // the mesh's normals are applyCreaseAngle's already (the Deformer's copy): not again
  size_t maxChunkSubTriangles = 0;   // 0: chunks as large as the device allows (smaller only to test chunking)
  size_t maxChunkParents = 0;        // the same for the pre-compute's chunks of mesh triangles
  // One deformation (DeformOptions::once): nothing runs before streamChunks(), which runs the pre-compute,
  // the clipping and the deform stage a chunk at a time (streamed()).
  bool once = false;
  // Whether the session runs chunk by chunk from the mesh (DeformSession::streamed): one-shot, either clipping.
  bool streamed() const { return once; }
};

// Told the stage and the fraction of the call done, at stage boundaries and after each chunk; it may
// throw (a cancelled Deformer), and the session stays usable for another precompute() or deform().
using StageProgress = std::function<void(const char* stage, double fraction)>;

// Times of the last precompute() or deform(): GPU time where the device measures it, else wall time.
struct SessionTimings {
  double pnMs = 0, clipMs = 0, deformMs = 0;
  double wallMs = 0;                        // host wall time of the call, including the wait for the device
  std::vector<DispatchTiming> dispatches;   // every dispatch of the call, in order (labels: pn, clip_count, ...)
};

class DeformSession {
 public:
  // Prepares the mesh (topology, creases from its normals, clip triangles) and runs precompute() (streamed():
  // neither clip triangles nor the pre-compute; `mesh` must then outlive the session, which reads it later).
  // The lattice fixes the degrees, counts, knots and box that later deform() calls must keep.
  // Throws an input Error for bad options and a device Error when the device refuses the work.
  DeformSession(Backend& backend, const Mesh& mesh, const Lattice& lattice, const DeformSessionOptions& options,
                const StageProgress& progress = {});
  ~DeformSession();
  DeformSession(const DeformSession&) = delete;
  DeformSession& operator=(const DeformSession&) = delete;

  // Runs the pre-compute stage again (PN triangles and clipping; the records stay on the device).
  const SessionTimings& precompute(const StageProgress& progress = {});
  // Deforms with the lattice's current control points into the chunks' buffers (undefined before the
  // first call); an input Error if the lattice's structure differs from the session's. Streamed: only
  // takes the lattice, for streamChunks().
  const SessionTimings& deform(const Lattice& lattice, const StageProgress& progress = {});
  const SessionTimings& timings() const { return timings_; }

  // Sub-triangles in groups whose buffers each fit one storage binding. The output buffer (layout.h,
  // SFFD_BINDING_DEFORM_OUT) begins with the tessellation (patch_output.h): per patch p of the chunk,
  // tessVertexCount(level) real4 positions at 2 * nv * p, then nv real4 unit normals; w = 0. From byte
  // patchesOffset the patches, SFFD_PATCH_STRIDE real4 per patch.
  struct Chunk {
    size_t first = 0, count = 0;   // sub-triangles [first, first + count)
    BufferId output = 0;
    uint64_t patchesOffset = 0;
  };
  const std::vector<Chunk>& chunks() const { return chunks_; }   // streamed: none
  size_t subTriangles() const { return subCount_; }               // streamed: those streamed so far

  // A one-shot job (options().once): the whole mesh is never clipped at once. After deform(), streamChunks()
  // makes the clip triangles of a few consecutive parents (their inputs beyond the vertices within
  // kStreamedChunkBytes, deform_session_internal.h, and options().maxChunkParents), uploads them, runs
  // pn_triangles, clip_count and clip_write (knot-box clipping: pn_triangles, then the parents' knot-box
  // sub-triangles and their records on the host, uploaded), deforms each chunk of their sub-triangles, hands
  // its output (still on the device) and its pre-images to `read`, and is done with it before the next:
  // only one chunk's records and outputs exist at a time. Chunks come in order, with the same bits as a session that is not once;
  // their `first` counts from the job's first sub-triangle. Once only (then an input Error).
  bool streamed() const { return options_.streamed(); }
  using ChunkReader = std::function<void(const Chunk& chunk, const SubTrianglePreImages& preImages)>;
  const SessionTimings& streamChunks(const ChunkReader& read, const StageProgress& progress = {});
  size_t precomputeChunks() const;   // the pre-compute's chunks of mesh triangles (options().maxChunkParents)
  int level() const { return options_.level; }
  const DeformSessionOptions& options() const { return options_; }
  Backend& backend() { return backend_; }

  // Host copies, downloaded on demand: the sub-triangle records of the last precompute() (for
  // pre-images and error analysis) and the output of the last deform().
  SubTriangleRecords records();
  SubTrianglePreImages preImages();   // what of the records the patch vertices need, a chunk at a time
  SmoothOutput output();

 private:
  void prepare(const Mesh& mesh, const Lattice& lattice, const StageProgress& progress);
  struct Impl;
  Backend& backend_;
  DeformSessionOptions options_;
  std::unique_ptr<Impl> impl_;
  std::vector<Chunk> chunks_;
  size_t subCount_ = 0;
  bool recordsReleased_ = false, deformed_ = false;   // streamed: the chunks were streamed; deform() ran
  // Appends the pre-images of `count` sub-triangles from their headers and records on the device.
  void readPreImages(BufferId headers, BufferId records, size_t count, SubTrianglePreImages& to);
  SessionTimings timings_;
};

}  // namespace sffd
