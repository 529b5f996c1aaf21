// sffd deform MESH -l LATTICE -o OUT: deforms a mesh and writes the result with vertex normals.
#include <chrono>
#include <cstdio>
#include <optional>

#include <nlohmann/json.hpp>

#include "atomic_file.h"
#include "classic_ffd.h"
#include "cli.h"
#include "error.h"
#include "job_budget.h"
#include "lattice_fold.h"

namespace sffd::cli {
namespace {

int run(const ParsedArgs& args) {
  std::string out = args.requireValue("--output");
  args.requireValue("--lattice");
  std::string method = args.get("--method", "smooth");
  if (method != "smooth" && method != "accurate" && method != "classic")
    throw Error(ErrorKind::Input, "--method must be smooth, accurate or classic, not '" + method + "'");
  std::string clip = args.get("--clip", "regular");
  if (clip != "regular" && clip != "knot-box") throw Error(ErrorKind::Input, "--clip must be regular or knot-box");
  auto opt = [&](const char* o) { return args.has(o) ? std::optional<std::string>(args.get(o)) : std::nullopt; };
  checkSizeOptions(opt("--edge-length"), opt("--tess"));   // docs/ROBUSTNESS.md "Limits"
  checkOutputPath(out, {args.positional[0], args.get("--lattice")});
  if (args.has("--stats")) checkOutputPath(args.get("--stats"), {args.positional[0], args.get("--lattice"), out});
  if (method != "classic")
    throw Error(ErrorKind::Internal, "--method " + method + " is not available in this build yet; use --method classic");

  auto t0 = std::chrono::steady_clock::now();
  Job job = loadJob(args);
  OpenedBackend backend = openBackendFromArgs(args);
  KernelVariant variant;
  variant.strict = args.has("--strict");
  variant.f64 = wantDouble(args, backend.info, /*autoDouble=*/true);
  PackedLattice packed = packLattice(job.lattice);
  if (std::string w = foldWarning(checkLatticeFold(packed), job.latticePath); !w.empty()) std::fprintf(stderr, "sffd: warning: %s\n", w.c_str());
  const DeviceLimits* limits = backend.gpu ? &backend.info.limits : nullptr;
  checkJobFits(estimateClassicJob(job.mesh, packed, variant.f64 ? 8 : 4, limits), packed, variant.f64 ? 8 : 4, limits);
  ClassicOutput result = backend.gpu ? classicFfdGpu(*backend.gpu, job.mesh, packed, variant)
                                     : classicFfdCpu(job.mesh, packed, variant);
  Mesh deformed = applyClassicOutput(job.mesh, result);
  writeMesh(out, deformed, variant.f64 ? 17 : 9);
  double totalMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  if (args.has("--stats")) {
    double deformMs = 0;
    for (const DispatchTiming& t : result.timings) deformMs += t.gpuMs > 0 ? t.gpuMs : 0;
    if (deformMs == 0) deformMs = result.wallMs;
    nlohmann::ordered_json j = {
        {"backend", backend.label},
        {"device", backend.info.name},
        {"method", method},
        {"clip", clip},
        {"precision", variant.f64 ? "double" : "float"},
        {"strict", variant.strict},
        {"input", {{"vertices", job.mesh.positions.size()}, {"triangles", job.mesh.triangles.size()}}},
        {"sub_triangles", 0},
        {"output", {{"vertices", deformed.positions.size()}, {"triangles", deformed.triangles.size()}}},
        {"timings_ms", {{"pn", 0.0}, {"clip", 0.0}, {"deform", deformMs}, {"total", totalMs}}},
    };
    std::string text = j.dump(1) + "\n";
    writeFileAtomically(args.get("--stats"), [&](std::ostream& o) { o << text; });
  }
  note(args, "wrote " + out + " (" + std::to_string(deformed.triangles.size()) + " triangles, " + backend.label + ", " +
                 backend.info.name + ")");
  return 0;
}

}  // namespace

CommandSpec deformCommand() {
  CommandSpec c{"deform", "MESH -l LATTICE -o OUT [options]",
                "Deforms a mesh by a lattice and writes the result (.obj .ply .off .stl) with vertex normals.",
                jobOptions(), run, 1, 1};
  c.options.insert(c.options.begin() + 1, {"--output|-o", "FILE", "output mesh (.obj .ply .off .stl)"});
  return c;
}

}  // namespace sffd::cli
