#include "apps/sffd/deform_job.h"

#include <cstdio>

#include "kernels/classic/classic_ffd.h"
#include <sffd/error.h>
#include "core/job_budget.h"
#include "model/lattice_fold.h"

namespace sffd::cli {

double stageMs(const std::vector<DispatchTiming>& timings, double wallMs) {
  double ms = 0;
  for (const DispatchTiming& t : timings) ms += t.gpuMs > 0 ? t.gpuMs : 0;
  return ms > 0 ? ms : wallMs;
}

DeformRun runClassic(const ParsedArgs& args, Job& job, OpenedBackend& backend) {
  DeformRun run;
  run.variant.strict = args.has("--strict");
  run.variant.f64 = wantDouble(args, backend.info, /*autoDouble=*/true);
  PackedLattice packed = packLattice(job.lattice);
  const DeviceLimits* limits = &backend.info.limits;
  int realBytes = run.variant.f64 ? 8 : 4;
  checkJobFits(estimateClassicJob(job.mesh, packed, realBytes, limits), packed, realBytes, limits);
  ClassicOutput result = classicFfd(*backend.backend, job.mesh, packed, run.variant);
  run.mesh = applyClassicOutput(job.mesh, result);
  run.deformMs = stageMs(result.timings, result.wallMs);
  return run;
}

DeformRun runDeformJob(const ParsedArgs& args, Job& job, OpenedBackend& backend) {
  std::string method = args.get("--method", "smooth");
  std::string clip = args.get("--clip", "regular");
  std::string warning = foldWarning(checkLatticeFold(packLattice(job.lattice)), job.latticePath);
  DeformRun run = method == "classic" ? runClassic(args, job, backend)
                  : method == "accurate" ? runAccurate(args, job, backend)
                                         : runSmooth(args, job, backend);
  // After the work, so a job that fails prints its one error line only. Shown even with --quiet: it
  // is about the result.
  if (!warning.empty()) std::fprintf(stderr, "sffd: warning: %s\n", warning.c_str());
  run.method = method;
  run.clip = method == "accurate" ? "knot-box" : clip;
  return run;
}

}  // namespace sffd::cli
