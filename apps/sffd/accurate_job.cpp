// --method accurate: knot-box clipping (CPU), then the exact Bezier patches of degree nu+nv+nw and their
// tessellation (kernel accurate_patches). Double precision by default where the
// device has it: accurate FFD is the reference the other methods are measured against.
#include <chrono>

#include "kernels/accurate/accurate_patches.h"
#include "apps/sffd/deform_job.h"
#include <sffd/error.h>
#include "core/job_budget.h"
#include "kernels/clip/knot_box_clip.h"

namespace sffd::cli {

DeformRun runAccurate(const ParsedArgs& args, Job& job, OpenedBackend& backend) {
  DeformRun run;
  run.variant.strict = args.has("--strict");
  run.variant.f64 = wantDouble(args, backend.info, /*autoDouble=*/true);
  const int level = args.getInt("--tess", 10);
  if (level < 1 || level > kMaxTessLevel)
    throw Error(ErrorKind::Input, "--tess must be an integer 1.." + std::to_string(kMaxTessLevel));

  auto t0 = std::chrono::steady_clock::now();
  std::vector<SubTriangle> subs = clipAgainstKnotBoxes(job.mesh, job.lattice);
  run.clipMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  AccurateJob aj = makeAccurateJob(job.mesh, job.lattice, std::move(subs), level);
  run.subTriangles = aj.count();

  PackedLattice packed = packLattice(job.lattice);
  // Host memory: kernel outputs (4 doubles a value), the patch vertices (9 doubles a vertex) and the
  // welded mesh (about 8 doubles and a hash entry a vertex), per tessellation vertex.
  const uint64_t nv = uint64_t(tessVertexCount(level)), m = uint64_t(triangleControlPoints(aj.degree));
  JobEstimate est;
  est.hostBytes = aj.count() * (nv * (8 + 9 + 8) * 8 + nv * 64 + m * 32 + tessTriangleCount(level) * 12);
  checkJobFits(est, packed, run.variant.f64 ? 8 : 4, &backend.info.limits);

  AccurateOutput out = accurateFfd(*backend.backend, aj, packed, run.variant);
  run.deformMs = stageMs(out.timings, out.wallMs);
  run.patches = accuratePatchVertices(aj, out);
  run.mesh = weldPatchVertices(*run.patches);
  return run;
}

}  // namespace sffd::cli
