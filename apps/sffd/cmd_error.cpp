// sffd error MESH -l LATTICE [--json]: geometry, normal and volume error of a method against the exact
// FFD of the same surface points (src/analysis/error_metrics.h, docs/ACCURACY.md "Error metrics").
#include <cstdio>
#include <optional>

#include <nlohmann/json.hpp>

#include "apps/sffd/cli.h"
#include "apps/sffd/deform_job.h"
#include <sffd/error.h>
#include "analysis/error_metrics.h"
#include "core/job_budget.h"
#include "io/atomic_file.h"

namespace sffd::cli {
namespace {

nlohmann::ordered_json statsJson(const ErrorStats& s) { return {{"avg", s.avg}, {"max", s.max}, {"std", s.std}}; }

int run(const ParsedArgs& args) {
  checkJobOptions(args);
  if (args.has("--stats")) checkOutputPath(args.get("--stats"), {args.positional[0], args.get("--lattice")});

  JobAndDevice opened = loadJobAndOpenDevice(args);
  Job& job = opened.job;
  Device& device = opened.device;
  DeformRun run = runDeformJob(args, job, device);
  const bool f64 = run.deformer.doublePrecision();
  // job.mesh as the method used it (its triangles are the patches' parents), measured in the frame the
  // devices computed in (a model far from the origin, or of any size).
  std::optional<PatchVertices> samples = run.patches();
  if (!samples) samples = linearPatchVertices(run.mesh, args.getInt("--tess", 10));
  const LocalFrame frame{run.deformer.localOrigin(), run.deformer.localScale()};
  const ErrorReport rep = measureErrorsInFrame(job.mesh, job.lattice, std::move(*samples), run.mesh, frame);

  if (args.has("--json") || args.has("--stats")) {
    nlohmann::ordered_json j = {
        {"method", run.method},
        {"clip", run.clip},
        {"vertices", rep.vertices},
        {"geometry", statsJson(rep.geometry)},
        {"normal_deg", statsJson(rep.normalDeg)},
        {"volume", rep.volume ? nlohmann::ordered_json{{"reference", rep.volume->reference},
                                                       {"result", rep.volume->result},
                                                       {"rel_error", rep.volume->relError}}
                              : nlohmann::ordered_json(nullptr)},
        {"sub_triangles", run.deformer.subTriangles()},
        {"backend", device.label()},
        {"precision", f64 ? "double" : "float"},
    };
    // --stats: the same object in a file (it was taken and not written).
    if (args.has("--stats")) writeFileAtomically(args.get("--stats"), [&](std::ostream& o) { o << j.dump(1) << "\n"; });
    if (args.has("--json")) std::printf("%s\n", j.dump(1).c_str());
  }
  if (!args.has("--json")) {
    std::printf("%s FFD (%s clipping) against exact FFD, %zu tessellation vertices (%s, %s)\n", run.method.c_str(),
                run.method == "classic" ? "no" : run.clip.c_str(), rep.vertices, device.label().c_str(),
                f64 ? "double" : "float");
    std::printf("  geometry    avg %.6g  max %.6g  std %.6g\n", rep.geometry.avg, rep.geometry.max, rep.geometry.std);
    std::printf("  normal deg  avg %.6g  max %.6g  std %.6g\n", rep.normalDeg.avg, rep.normalDeg.max, rep.normalDeg.std);
    if (rep.volume)
      std::printf("  volume      reference %.10g  result %.10g  rel_error %.6g\n", rep.volume->reference, rep.volume->result,
                  rep.volume->relError);
    else
      std::printf("  volume      none (the mesh is open)\n");
  }
  return 0;
}

}  // namespace

CommandSpec errorCommand() {
  CommandSpec c{"error", "MESH -l LATTICE [--json] [options]",
                "Geometry, normal and volume error of a method against the exact (accurate) FFD.", jobOptions(), run, 1, 1};
  c.options.insert(c.options.begin() + 1, {"--json", nullptr, "print the result as JSON"});
  return c;
}

}  // namespace sffd::cli
