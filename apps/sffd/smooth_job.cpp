// --method smooth: the improved smooth FFD end to end (PN triangles, clipping, deform, tessellation).
#include <algorithm>

#include "apps/sffd/deform_job.h"
#include "pipelines/deform_session.h"
#include <sffd/error.h>
#include "model/mesh_topology.h"
#include "kernels/smooth/smooth_deform.h"

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

  bool split = args.has("--split");
  bool knotBox = args.get("--clip", "regular") == "knot-box";
  // The device-resident path that `view` and `bench` use: no host round trip between the stages.
  DeformSessionOptions o;
  o.variant = run.variant;
  o.edgeLength = l;
  o.level = level;
  o.samples = std::max(3, s);
  o.knotBoxClip = knotBox;
  o.split = split;
  o.creaseAngleDeg = args.getDouble("--crease-angle", 40.0);
  DeformSession session(*backend.backend, job.mesh, job.lattice, o);
  run.pnMs = session.timings().pnMs;
  run.clipMs = session.timings().clipMs;
  const SessionTimings& t = session.deform(job.lattice);
  run.deformMs = t.deformMs;
  if (split)
    for (const DispatchTiming& d : t.dispatches) {
      auto it = std::find_if(run.stepMs.begin(), run.stepMs.end(), [&](const auto& p) { return p.first == d.label; });
      if (it == run.stepMs.end()) run.stepMs.push_back({d.label, 0.0}), it = run.stepMs.end() - 1;
      it->second += std::max(d.gpuMs, 0.0);
    }
  SubTriangleRecords subs = session.records();
  SmoothOutput out = session.output();
  run.subTriangles = subs.size();
  run.patches = patchVerticesOf(subs, out);
  run.patchControlPoints = std::move(out.patches);
  run.mesh = weldPatchVertices(*run.patches);
  return run;
}

}  // namespace sffd::cli
