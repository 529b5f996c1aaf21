// The host memory of a one-shot smooth job with regular clipping (DeformSession::streamed: `sffd deform`
// into a .ply or .stl) and of a one-shot accurate job (AccurateRun with DeformOptions::once). Such a job
// never holds all of its sub-triangles' output: estimateSmoothJob (job_budget.h), which assumes it does, is
// far above what it needs (5.96 GiB for a run that peaks at 241 MB, docs/performance/scaling.md). This
// estimate counts what stays alive, phase by phase.
#pragma once
#include <cstdint>

#include <sffd/device.h>

#include "core/job_budget.h"
#include "kernels/accurate/accurate_patches.h"
#include "model/mesh.h"
#include "pipelines/deform_session.h"

namespace sffd {

// Whether a device's buffers are host memory: the CPU device and the software drivers (lavapipe, llvmpipe).
bool deviceIsHost(const DeviceInfo& info);

// What of a streamed job depends on the mesh's shape, from two passes over its triangles in order.
struct StreamShape {
  // At most: per parent c^2 sub-triangles for c segments on its longest edge (no split pattern has more),
  // 2c^2 where it is pre-split (c > Nmax; at most 1.15 c^2 measured over 200,000 random triangles).
  double subTriangles = 0;
  double presplitSubTriangles = 0;   // of those, the pre-split parents' (a bound on their clip triangles)
  double parentClips = 1;            // the most clip triangles of one parent
  double chunkSubTriangles = 0;      // the largest sum over `chunkParents` consecutive parents
  // The most locations and vertices the weld holds after a compaction (PatchWelder::forgetPassedLocations):
  // the input corners and edge points that a later parent still reaches, the current parent's points.
  double frontLocations = 0, frontVertices = 0;
};
StreamShape streamShape(const Mesh& mesh, double edgeLength, int level, uint64_t chunkParents);
// The same of an accurate job's sub-triangles `subs` (in parent order) at `level`, exact where streamShape
// bounds: the sub-triangles, and the front from where each patch's boundary lies on its parent.
StreamShape accurateStreamShape(const Mesh& mesh, const std::vector<SubTriangle>& subs, int level);

// Peak host bytes of the streamed job of `mesh` (its creases applied: the Deformer's copy), the largest of
// three phases: the creases applied to that copy, the session's prepared mesh and topology made, and the
// stream (the copies, the prepared mesh's normals and triangles, the topology's slot part, the vertex
// section, the clip builder's split points, one chunk's inputs, clip triangles, records and outputs, the
// pre-images, the download block, the weld's front and its slices, the writer's buffers, and the device's
// buffers where they are host memory, else the staging of one chunk); each with the program and, on a
// graphics device, its driver. `otherMeshBytes`: the mesh's other copies held throughout (the caller's, a
// local-frame copy). deviceBytes: one chunk's; outputVertices: at most the result's. The lattice's bytes
// (estimateLatticeBytes) are the caller's to add.
JobEstimate estimateStreamedSmoothJob(const Mesh& mesh, const DeformSessionOptions& options, const DeviceInfo& device,
                                      uint64_t otherMeshBytes);

// A one-shot accurate run as AccurateRun makes it (deformer_accurate.cpp).
struct AccurateStream {
  const AccurateJob* job = nullptr;   // its sub-triangles and their corners, kept throughout
  size_t realBytes = 8;               // of the kernel's reals
  uint64_t chunkPatches = 1;          // sub-triangles a chunk at most (within kOnceChunkBytes)
  uint64_t deviceBytes = 0;           // its buffers: the lattice's, the frame's, the scratch and one chunk's
  uint64_t hostBytes = 0;             // what else it keeps on the host: the frame and its tables
};

// Peak host bytes of a one-shot accurate job of `mesh` (the run's): the larger of the clipping (its
// sub-triangles grown: twice) and the stream (the job, the weld's per-weld-id slots, one chunk's
// corners made for their upload, the download block, the weld's front and its slice, the writer's buffers,
// and the device's buffers where they are host memory, else the staging of one chunk), with the program
// and, on a graphics device, its driver. `otherMeshBytes` and outputVertices as for the smooth job's; the
// lattice's bytes are the caller's to add.
JobEstimate estimateStreamedAccurateJob(const Mesh& mesh, const AccurateStream& run, const DeviceInfo& device,
                                        uint64_t otherMeshBytes);

}  // namespace sffd
