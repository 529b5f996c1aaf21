// --method smooth: the improved smooth FFD end to end (PN triangles, clipping, deform, tessellation).
#include <algorithm>

#include "deform_job.h"
#include "error.h"
#include "knot_box_clip.h"
#include "mesh_topology.h"
#include "regular_clip.h"
#include "smooth_deform.h"
#include "split_pattern_table.h"

namespace sffd::cli {

int tessLevel(const ParsedArgs& args) { return args.getInt("--tess", 10); }

double edgeLengthOf(const ParsedArgs& args, const Mesh& mesh) {
  if (args.has("--edge-length")) return args.getDouble("--edge-length", 0);
  // The reference implementation's l = 0.2 for models in [-1,1]: a tenth of the largest extent.
  glm::dvec3 lo, hi;
  meshBounds(mesh, lo, hi);
  return 0.1 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
}

DeformRun runSmooth(const ParsedArgs& args, Job& job, OpenedBackend& backend) {
  DeformRun run;
  run.variant.strict = args.has("--strict");
  run.variant.f64 = wantDouble(args, backend.info, /*autoDouble=*/false);
  if (!job.mesh.normalsFromFile) applyCreaseAngle(job.mesh, args.getDouble("--crease-angle", 40.0));
  const int level = tessLevel(args);
  const double l = edgeLengthOf(args, job.mesh);
  checkEdgeLength(job.mesh, l);
  int s = args.getInt("--samples", job.lattice.degree[0] + job.lattice.degree[1] + job.lattice.degree[2]);
  FitTable fit = makeFitTable(std::max(3, s));

  PreparedMesh prepared = prepareMesh(job.mesh);
  PackedLattice packed = packLattice(job.lattice);
  Backend* gpu = backend.gpu.get();
  PnOutput pn = gpu ? pnTrianglesGpu(*gpu, prepared, run.variant) : pnTrianglesCpu(prepared, run.variant);
  run.pnMs = stageMs(pn.timings, pn.wallMs);
  SubTriangleRecords subs;
  if (args.get("--clip", "regular") == "knot-box") {
    // The 2015 clipping is the CPU baseline; the deform stage still runs on the chosen backend.
    subs = recordsFromSubTriangles(prepared, pn, clipAgainstKnotBoxes(job.mesh, job.lattice), run.variant);
  } else {
    ClipTriangles C = buildClipTriangles(job.mesh, l, splitPatternTable().nmax());
    subs = gpu ? regularClipGpu(*gpu, prepared, pn, C, l, run.variant) : regularClipCpu(prepared, pn, C, l, run.variant);
  }
  run.clipMs = stageMs(subs.timings, subs.wallMs);
  run.subTriangles = subs.size();
  bool split = args.has("--split");
  SmoothOutput out = gpu ? smoothDeformGpu(*gpu, packed, subs, fit, level, run.variant, split)
                         : smoothDeformCpu(packed, subs, fit, level, run.variant);
  run.deformMs = stageMs(out.timings, out.wallMs);
  if (split && gpu) {
    for (const DispatchTiming& t : out.timings) {
      auto it = std::find_if(run.stepMs.begin(), run.stepMs.end(), [&](const auto& p) { return p.first == t.label; });
      if (it == run.stepMs.end()) run.stepMs.push_back({t.label, 0.0}), it = run.stepMs.end() - 1;
      it->second += std::max(t.gpuMs, 0.0);
    }
  }
  run.patches = patchVerticesOf(subs, out);
  run.patchControlPoints = std::move(out.patches);
  run.mesh = weldPatchVertices(*run.patches);
  return run;
}

}  // namespace sffd::cli
