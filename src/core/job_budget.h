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
};

// Estimate for `deform --method classic`: the input mesh, the kernel outputs widened to double, the
// deformed copy, the writer's position index; on a GPU the lattice buffers and four chunk buffers of
// realBytes * 4 per vertex, chunked as classicFfdGpu does. `limits` null: the CPU reference.
JobEstimate estimateClassicJob(const Mesh& mesh, const PackedLattice& lattice, size_t realBytes, const DeviceLimits* limits);

// The host memory a job may use: SFFD_MEMORY_LIMIT (bytes, or with a K, M, G or T suffix) when set,
// else the machine's physical memory. 0 when neither is known (no limit).
uint64_t hostMemoryLimit();

// Throws an input Error ("... needs about X of host memory, more than the limit of Y ...") when the job
// cannot fit: host bytes above hostMemoryLimit(), or one unchunkable buffer (the lattice coefficients)
// above the device's storage-binding range.
void checkJobFits(const JobEstimate& estimate, const PackedLattice& lattice, size_t realBytes, const DeviceLimits* limits);

// "1.50 GiB" style.
std::string formatBytes(uint64_t bytes);

}  // namespace sffd
