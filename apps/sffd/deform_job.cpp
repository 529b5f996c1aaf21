#include "apps/sffd/deform_job.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include <sffd/error.h>

#include "apps/sffd/progress_line.h"
#include "core/job_budget.h"
#include "model/lattice_coverage.h"
#include "model/lattice_fold.h"
#include "model/lattice_pack.h"
#include "pipelines/deformer_internal.h"

namespace sffd::cli {
Method methodOf(const std::string& name) {
  if (name == "smooth") return Method::Smooth;
  if (name == "accurate") return Method::Accurate;
  if (name == "classic") return Method::Classic;
  throw Error(ErrorKind::Input, "--method must be smooth, accurate or classic, not '" + name + "'");
}

void checkJobOptions(const ParsedArgs& args) {
  args.requireValue("--lattice");
  methodOf(args.get("--method", "smooth"));
  const std::string clip = args.get("--clip", "regular");
  if (clip != "regular" && clip != "knot-box") throw Error(ErrorKind::Input, "--clip must be regular or knot-box");
  auto opt = [&](const char* o) { return args.has(o) ? std::optional<std::string>(args.get(o)) : std::nullopt; };
  checkSizeOptions(opt("--edge-length"), opt("--tess"));   // docs/ROBUSTNESS.md "Limits"
}

double edgeLengthOf(const ParsedArgs& args, const Mesh& mesh) {
  return args.has("--edge-length") ? args.getDouble("--edge-length", 0) : defaultEdgeLength(mesh);
}

DeformOptions deformOptionsOf(const ParsedArgs& args, const Job& job, Device& device, Method method) {
  DeformOptions o;
  o.method = method;
  o.memoryLimit = memoryLimitFromEnvironment();
  o.precision = wantDouble(args, device.info(), method != Method::Smooth) ? Precision::Double : Precision::Float;
  o.strict = args.has("--strict");
  o.clip = args.get("--clip", "regular") == "knot-box" ? Clip::KnotBox : Clip::Regular;
  o.tess = args.getInt("--tess", 10);
  o.creaseAngleDeg = creaseAngleOf(args);
  o.split = args.has("--split");
  o.samples = samplesOf(args);
  if (method == Method::Smooth) {
    o.edgeLength = edgeLengthOf(args, job.mesh);
    checkEdgeLength(job.mesh, o.edgeLength);
    o.maxChunkElements = chunkFromEnvironment("SFFD_MAX_CHUNK_SUBTRIANGLES");
  } else {
    o.maxChunkElements = chunkFromEnvironment(method == Method::Classic ? "SFFD_MAX_CHUNK_VERTICES" : "SFFD_MAX_CHUNK_PATCHES");
  }
  return o;
}

std::optional<PatchVertices> DeformRun::patches() {
  std::optional<PatchVertices> p = deformer.internal().run->patchVertices();
  line->clear();
  return p;
}

DeformRun runMethod(const ParsedArgs& args, Job& job, Device& device, Method method, const SinkFor& sinkFor) {
  DeformOptions o = deformOptionsOf(args, job, device, method);
  o.once = bool(sinkFor);   // one deformation, its result streamed once: buffers freed as they are read
  auto line = std::make_shared<ProgressLine>(progressWanted(args));   // cleared also when a call throws
  o.progress = line->callback();
  auto make = [&] { return withToolLimitName([&] { return Deformer(device, job.mesh, job.lattice, o); }); };
  const char* name = method == Method::Smooth ? "smooth" : method == Method::Accurate ? "accurate" : "classic";
  auto t0 = std::chrono::steady_clock::now();
  auto lap = [&t0] {
    auto t = std::chrono::steady_clock::now();
    return std::chrono::duration<double, std::milli>(t - std::exchange(t0, t)).count();
  };
  DeformRun run{name, method == Method::Accurate ? "knot-box" : args.get("--clip", "regular"), line, make(), {}};
  run.prepareMs = lap();
  if (sinkFor) job.mesh = Mesh();   // the Deformer has its copy: not two at the streamed result's peak
  run.deformer.deform(job.lattice);
  run.deformMs = lap();
  if (sinkFor) run.deformer.streamResult(sinkFor(run.deformer));
  else run.mesh = run.deformer.result();
  run.resultMs = lap();
  line->clear();
  if (method == Method::Smooth || sinkFor) job.mesh = run.deformer.internal().input;
  return run;
}

void checkSinkFits(Deformer& deformer, size_t bytesPerVertex) {
  const Deformer::Impl& I = deformer.internal();
  if (!I.wholeEstimate || !bytesPerVertex) return;   // not streamed, or a sink that keeps nothing per vertex
  JobEstimate e = *I.estimate;
  e.hostBytes += e.outputVertices * bytesPerVertex;
  checkEstimateFits(I, e, memoryLimitFromEnvironment(), "SFFD_MEMORY_LIMIT");
}

void checkKeptFits(Deformer& deformer, uint64_t keptBytes, const std::string& what, const std::string& hint) {
  const Deformer::Impl& I = deformer.internal();
  checkHostBytesFit((I.estimate ? I.estimate->hostBytes : 0) + keptBytes, memoryLimitFromEnvironment(), "SFFD_MEMORY_LIMIT",
                    what + " need", hint);
}

DeformRun runDeformJob(const ParsedArgs& args, Job& job, Device& device, const SinkFor& sinkFor) {
  const std::string warnings[] = {foldWarning(checkLatticeFold(packLattice(job.lattice)), job.latticePath),
                                  discontinuityWarning(job.lattice, job.latticePath),
                                  outsideWarning(shareOutsideLattice(job.mesh, job.lattice), job.lattice, job.latticePath)};
  DeformRun run = runMethod(args, job, device, methodOf(args.get("--method", "smooth")), sinkFor);
  for (const std::string& w : warnings)
    if (!w.empty()) warnOnSuccess(w);
  if (std::string w = resolutionWarning(job.mesh, job.lattice, run.deformer.doublePrecision(), job.latticePath); !w.empty())
    warnOnSuccess(w);
  return run;
}

}  // namespace sffd::cli
