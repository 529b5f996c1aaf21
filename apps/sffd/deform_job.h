// Running one deformation as the options say, through sffd::Deformer: the part of `sffd deform`
// that `render`, `error` and `view` share.
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <sffd/deformer.h>

#include "apps/sffd/cli.h"
#include "pipelines/patch_output.h"

namespace sffd::cli {

// --method smooth|accurate|classic; an input Error for another name.
Method methodOf(const std::string& name);

// The job options (--clip, --edge-length, --tess, --samples, --split, --precision, --strict,
// --crease-angle) for `method` on `device`, and what the library takes as options but the tool reads
// from the environment: SFFD_MEMORY_LIMIT (every method) and SFFD_MAX_CHUNK_VERTICES, _PATCHES, _SUBTRIANGLES (classic, accurate, smooth).
DeformOptions deformOptionsOf(const ParsedArgs& args, const Job& job, Device& device, Method method);

class ProgressLine;

struct DeformRun {
  std::string method, clip;   // as the stats and messages name them
  std::shared_ptr<ProgressLine> line;   // what the Deformer's progress callback draws on
  Deformer deformer;
  Mesh mesh;                  // the result as `deform` writes it (empty when streamed)
  // Wall times of the host phases: the Deformer made (pre-compute included), deform() (the kernels and
  // their waits), result() (download, weld, the move back from local coordinates).
  double prepareMs = 0, deformMs = 0, resultMs = 0;
  // Smooth and accurate: the tessellation with the pre-images of its vertices (downloaded again).
  std::optional<PatchVertices> patches();
};

// A Deformer for the job on `device`, deformed once. For smooth, job.mesh becomes the mesh as the
// method used it (creases split): the pre-images index its triangles. A progress line on stderr shows
// how far it is (progress_line.h).
// Where to stream a result (Deformer::streamResult), asked once the Deformer is made (the writer's digits
// depend on it); empty: the result is kept in DeformRun::mesh.
using SinkFor = std::function<MeshSink&(Deformer&)>;
// With `sinkFor`, the result is streamed instead of kept (DeformRun::mesh stays empty), and the Deformer is
// made for one deformation (DeformOptions::once); job.mesh is emptied while it runs (then the Deformer's).
DeformRun runMethod(const ParsedArgs& args, Job& job, Device& device, Method method, const SinkFor& sinkFor = {});

// A streamed smooth or accurate job's memory estimate (Deformer::Impl::estimate) with what its sink keeps per
// output vertex added (MeshFileWriter::heldBytesPerVertex: an STL's positions and normals), checked against
// SFFD_MEMORY_LIMIT before the stream starts: the input Error of the limit when it does not fit.
void checkSinkFits(Deformer& deformer, size_t bytesPerVertex);

// The Deformer's own memory estimate with `keptBytes` more kept beside it (animate's frames for a glTF),
// checked against SFFD_MEMORY_LIMIT (or the physical memory): the input Error "WHAT need about ...; HINT".
void checkKeptFits(Deformer& deformer, uint64_t keptBytes, const std::string& what, const std::string& hint);

// runMethod for --method, then the lattice's fold warning (after the work, so a job that fails prints
// its one error line only; shown even with --quiet: it is about the result).
DeformRun runDeformJob(const ParsedArgs& args, Job& job, Device& device, const SinkFor& sinkFor = {});

// --edge-length, or a tenth of the mesh's largest extent (the reference implementation's l = 0.2 for
// models in [-1, 1]).
double edgeLengthOf(const ParsedArgs& args, const Mesh& mesh);

// The options of a deformation checked before any work (an input Error naming the first bad one):
// --lattice given, --method and --clip known, --edge-length and --tess in range.
void checkJobOptions(const ParsedArgs& args);

}  // namespace sffd::cli
