// The host memory of a one-shot smooth job with regular clipping (DeformSession::streamed: `sffd deform`
// into a .ply or .stl). Such a job never holds all of its sub-triangles: estimateSmoothJob (job_budget.h),
// which assumes it does, is far above what it needs (5.96 GiB for a run that peaks at 241 MB, docs/
// PERFORMANCE.md "Scaling"). This estimate counts what stays alive, phase by phase.
#pragma once
#include <cstdint>

#include <sffd/device.h>

#include "core/job_budget.h"
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

}  // namespace sffd
