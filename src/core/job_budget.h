// Resource limits of a job, checked before any GPU work: the options that size it (--tess,
// --edge-length) and an estimate of the host and device memory a classic job needs, refused with the
// numbers when it cannot fit (docs/ROBUSTNESS.md "Limits").
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "core/backend.h"
#include "model/lattice_pack.h"
#include "model/mesh.h"

namespace sffd {

// --tess N: 1..kMaxTessLevel. A patch at level N has (N+1)(N+2)/2 vertices and N^2 triangles, so 64
// already gives 4096 triangles a patch.
constexpr int kMaxTessLevel = 64;

// Checks the values of --edge-length (a finite number > 0) and --tess (an integer 1..kMaxTessLevel);
// throws an input Error naming the option. Either may be absent.
void checkSizeOptions(const std::optional<std::string>& edgeLength, const std::optional<std::string>& tess);

struct JobEstimate {
  uint64_t hostBytes = 0;       // peak host memory of the job after the inputs are read
  uint64_t deviceBytes = 0;     // device memory held at once (0 on the CPU reference)
  uint64_t chunkVertices = 0;   // vertices per dispatch (the whole mesh when it fits the limits)
  uint64_t chunks = 0;
  uint64_t outputVertices = 0;  // at most this many vertices in the result (streamed smooth: for a sink that keeps them)
};

// The bytes a Mesh's arrays hold (their capacity), carried attributes included.
uint64_t meshHeldBytes(const Mesh& mesh);

// Smooth FFD with target edge length l splits a mesh into about area / (sqrt(3)/4 l^2) sub-triangles,
// and at least one a triangle; jobs above kMaxSubTriangles are refused.
constexpr double kMaxSubTriangles = 50e6;
double estimateSubTriangles(const Mesh& mesh, double l);
// The edge length smooth FFD uses when none is given: a tenth of the mesh's largest extent (the
// reference implementation's l = 0.2 for models in [-1, 1]); 1 for a mesh without extent (one point, or none).
double defaultEdgeLength(const Mesh& mesh);
// Refuses (input Error) an edge length that is not a positive number or whose estimate exceeds
// kMaxSubTriangles, before any work; `name` is how the message calls it ("--edge-length" in the tool).
void checkSubTriangleCount(const Mesh& mesh, double l, const std::string& name);

// Estimate for `deform --method classic`: the input mesh, the kernel outputs widened to double, the
// deformed copy, the writer's position index; on a GPU the lattice buffers and, kept on the device by
// sffd::Deformer, every vertex's position and normal in and out (realBytes * 4 each), chunked as
// classicChunkVertices does. `limits` null: the CPU reference.
JobEstimate estimateClassicJob(const Mesh& mesh, const PackedLattice& lattice, size_t realBytes, const DeviceLimits* limits);

// "123", "4K", "1.5G", "2GB" (powers of 1024) as bytes; 0 when it does not parse.
uint64_t parseByteSize(const char* text);

// The host memory a job may use: `requested` when not 0, else the machine's physical memory (or the
// container's limit when lower). 0 when neither is known (no limit).
uint64_t hostMemoryLimit(uint64_t requested);

// Throws an input Error ("... needs about X of host memory, more than the limit of Y (NAME)") when the
// job cannot fit: host bytes above hostMemoryLimit(memoryLimit), or one unchunkable buffer (the lattice
// coefficients) above the device's storage-binding range. `limitName` names a memoryLimit given.
void checkJobFits(const JobEstimate& estimate, const PackedLattice& lattice, size_t realBytes, const DeviceLimits* limits,
                  uint64_t memoryLimit, const char* limitName = "memoryLimit");

// The host memory a lattice needs to be evaluated, from its counts, degrees and knots alone (the
// control points need not be there yet): the control points, the per-knot-box Bezier form (boxes x
// (n+1)^3 points, extractBoxForm), the packed kernel form (4 doubles a coefficient, packLattice) and
// its copy in the kernel's reals. What a reader checks before it allocates anything.
uint64_t estimateLatticeBytes(const Lattice& lattice);

// "the NxNxN lattice (up to B knot boxes of degree D) needs about X of host memory to evaluate, more
// than the limit of Y (LIMITNAME); ..." when estimateLatticeBytes exceeds hostMemoryLimit(memoryLimit),
// else empty.
std::string latticeTooLarge(const Lattice& lattice, uint64_t memoryLimit, const char* limitName);

// Estimate for `deform --method smooth` with about `subTriangles` sub-triangles at tessellation `level`
// (docs/ROBUSTNESS.md "Limits"): the copies of the input, PN and clip records, the sub-triangle records,
// patches and tessellation on the device and downloaded, the pre-images, the weld's index and the welded
// result. `deviceIsHost`: the device's buffers are host memory (the CPU reference, software drivers).
JobEstimate estimateSmoothJob(const Mesh& mesh, double subTriangles, int level, size_t realBytes, bool deviceIsHost);

// Throws the input Error of checkJobFits for host bytes above the limit (no device-range check).
void checkHostFits(const JobEstimate& estimate, uint64_t memoryLimit, const char* limitName, const char* what);
// Throws an input Error "SUBJECT about X of host memory, more than the limit of Y (LIMIT NAME); HINT" when `bytes`
// exceed hostMemoryLimit(memoryLimit): the one form of every host-memory refusal.
void checkHostBytesFit(uint64_t bytes, uint64_t memoryLimit, const char* limitName, const std::string& subject,
                       const std::string& hint);

// "1.50 GiB" style.
std::string formatBytes(uint64_t bytes);

}  // namespace sffd
