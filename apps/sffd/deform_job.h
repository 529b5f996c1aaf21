// Running one deformation as the options say: the part of `sffd deform` that `render`, `error`,
// `bench` and `view` share. Each method is one function; runDeformJob picks it.
#pragma once
#include <optional>
#include <string>

#include "backends/backend_select.h"
#include "apps/sffd/cli.h"
#include "pipelines/patch_output.h"

namespace sffd::cli {

struct DeformRun {
  std::string method, clip;
  KernelVariant variant;
  Mesh mesh;                               // the result as `deform` writes it
  std::optional<PatchVertices> patches;    // smooth and accurate: the tessellation with pre-images
  // Smooth: per patch SFFD_PATCH_STRIDE control points (x, y, z, 0): 10 geometry then 10 normal, in
  // the linear index order of METHOD.md 0 (what `deform --patches` writes).
  std::vector<double> patchControlPoints;
  size_t subTriangles = 0;
  double pnMs = 0, clipMs = 0, deformMs = 0;   // per stage: GPU time where measured, else wall time
  std::vector<std::pair<std::string, double>> stepMs;   // --split: the deform steps (deform.sample, ...)
};

// Reads --method, --clip, --edge-length, --tess, --precision, --strict and runs the job on `backend`.
DeformRun runDeformJob(const ParsedArgs& args, Job& job, OpenedBackend& backend);

// One function per method (deform_job.cpp, smooth_job.cpp, accurate_job.cpp).
DeformRun runClassic(const ParsedArgs& args, Job& job, OpenedBackend& backend);
DeformRun runSmooth(const ParsedArgs& args, Job& job, OpenedBackend& backend);
DeformRun runAccurate(const ParsedArgs& args, Job& job, OpenedBackend& backend);

// --tess (default 10) and --edge-length (default: a tenth of the mesh's largest extent, the reference
// implementation's l = 0.2 for models in [-1, 1]).
int tessLevel(const ParsedArgs& args);
double edgeLengthOf(const ParsedArgs& args, const Mesh& mesh);

// Sum of the GPU times of the timings (wall time when the device measured none).
double stageMs(const std::vector<DispatchTiming>& timings, double wallMs);

}  // namespace sffd::cli
