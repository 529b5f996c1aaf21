// sffd deform MESH -l LATTICE -o OUT: deforms a mesh and writes the result with vertex normals.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <utility>

#include <nlohmann/json.hpp>

#include "io/atomic_file.h"
#include "io/io_util.h"
#include "apps/sffd/cli.h"
#include <sffd/error.h>
#include "apps/sffd/deform_job.h"
#include "core/job_budget.h"
#include "core/shader_binary_cache.h"
#include "pipelines/deformer_internal.h"

namespace sffd::cli {
namespace {

// The patch file (docs/CLI.md "Patch files"): a header line, then per patch its parent triangle and
// 10 geometry and 10 normal control points of the cubic triangular Bezier patch, one per line.
void writePatchFile(const std::string& path, DeformRun& run, const std::vector<double>& controlPoints) {
  const PatchVertices patches = *run.patches();
  const size_t n = patches.patchCount();
  const int digits = run.deformer.resultDigits();
  writeFileAtomically(path, [&](std::ostream& o) {
    char line[128];
    o << "sffd-patches 1 " << n << " 3\n";
    for (size_t p = 0; p < n; ++p) {
      o << "patch " << patches.parent[p] << "\n";
      for (int k = 0; k < 20; ++k) {
        const double* c = &controlPoints[(p * 20 + k) * 4];
        std::snprintf(line, sizeof line, "%.*g %.*g %.*g\n", digits, c[0], digits, c[1], digits, c[2]);
        o << line;
      }
    }
  });
}

int run(const ParsedArgs& args) {
  std::string out = args.requireValue("--output");
  checkJobOptions(args);
  const std::string outExt = io::lowerExtension(out);
  if (args.has("--binary") && outExt != ".ply" && outExt != ".stl")
    throw Error(ErrorKind::Input, "--binary writes .ply and .stl, not '" + outExt + "'");
  checkOutputPath(out, {args.positional[0], args.get("--lattice")});
  if (args.has("--stats")) checkOutputPath(args.get("--stats"), {args.positional[0], args.get("--lattice"), out, args.get("--patches")});
  if (args.has("--patches")) {
    // Before any work: refused after it, the output was left written.
    if (methodOf(args.get("--method", "smooth")) != Method::Smooth) throw Error(ErrorKind::Input, "--patches needs --method smooth");
    checkOutputPath(args.get("--patches"), {args.positional[0], args.get("--lattice"), out});
  }

  auto t0 = std::chrono::steady_clock::now(), lapStart = t0;
  auto lap = [&lapStart] {
    auto t = std::chrono::steady_clock::now();
    return std::chrono::duration<double, std::milli>(t - std::exchange(lapStart, t)).count();
  };
  JobAndDevice opened = loadJobAndOpenDevice(args);
  Job& job = opened.job;
  Device& device = opened.device;
  // The phases add up to the wall time: `read` is what the inputs took beyond the device's opening.
  const double openMs = opened.openMs, readMs = std::max(0.0, lap() - openMs);
  // Smooth and accurate results go to a .ply or .stl as they are welded (MeshFileWriter), never held whole
  // (--patches reads the Deformer again afterwards: then the result is taken as before).
  const bool streamed = methodOf(args.get("--method", "smooth")) != Method::Classic && !args.has("--patches") &&
                        MeshFileWriter::streams(out, {.binary = args.has("--binary")}, !job.mesh.colors.empty());
  WrittenFiles written;   // as they were again when a later file fails (a --patches or --stats that cannot be written)
  std::unique_ptr<MeshFileWriter> writer;
  auto writerFor = [&](Deformer& d) -> MeshSink& {
    const MeshWriteOptions options{.significantDigits = d.resultDigits(), .binary = args.has("--binary")};
    checkSinkFits(d, MeshFileWriter::heldBytesPerVertex(out, options));
    written.willWrite(out);
    writer = std::make_unique<MeshFileWriter>(out, options);
    return *writer;
  };
  DeformRun run = runDeformJob(args, job, device, streamed ? SinkFor(writerFor) : SinkFor());
  const double checksMs = lap() - run.prepareMs - run.deformMs - run.resultMs;   // the lattice's fold, knot and coverage checks
  const Timings& t = run.deformer.timings();
  const Mesh& deformed = run.mesh;
  if (!streamed) {
    written.willWrite(out);
    writeMesh(out, deformed, MeshWriteOptions{.significantDigits = run.deformer.resultDigits(), .binary = args.has("--binary")});
  }
  const double writeMs = lap();
  const size_t outVertices = streamed ? writer->vertexCount() : deformed.positions.size();
  const size_t outTriangles = streamed ? writer->triangleCount() : deformed.triangles.size();
  if (args.has("--patches")) {
    written.willWrite(args.get("--patches"));
    writePatchFile(args.get("--patches"), run, run.deformer.patchControlPoints());
  }
  double totalMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  if (args.has("--stats")) {
    nlohmann::ordered_json j = {
        {"backend", device.label()},
        {"device", device.info().name},
        {"method", run.method},
        {"clip", run.clip},
        {"precision", run.deformer.doublePrecision() ? "double" : "float"},
        {"strict", args.has("--strict")},
        {"input", {{"vertices", job.mesh.positions.size()}, {"triangles", job.mesh.triangles.size()}}},
        {"sub_triangles", run.deformer.subTriangles()},
        {"output", {{"vertices", outVertices}, {"triangles", outTriangles}}},
        {"timings_ms", {{"pn", t.pnMs}, {"clip", t.clipMs}, {"deform", t.deformMs}, {"total", totalMs}}},
        // Where the whole run's wall time goes (docs/performance/whole_run.md): the inputs read,
        // the device opened, the lattice checked, the Deformer made (pre-compute), deformed, its result taken (download,
        // weld), the output written; then the weld's share of the result.
        {"host_ms",
         {{"read", readMs},
          {"open_device", openMs},
          {"checks", checksMs},
          {"prepare", run.prepareMs},
          {"deform", run.deformMs},
          {"result", run.resultMs},
          {"write", writeMs},
          {"weld", t.weldMs}}},   // part of result
    };
    // Smooth: the target edge length used (given, or a tenth of the mesh's largest extent); others: null.
    j["edge_length"] = run.method == "smooth" ? nlohmann::ordered_json(edgeLengthOf(args, job.mesh)) : nlohmann::ordered_json();
    // Smooth and accurate: the host-memory estimate checked against SFFD_MEMORY_LIMIT (bytes); classic: null.
    const std::optional<JobEstimate>& estimate = run.deformer.internal().estimate;
    j["host_memory_estimate"] = estimate ? nlohmann::ordered_json(estimate->hostBytes) : nlohmann::ordered_json();
    // Kernels made from the shader cache's binaries, made from SPIR-V for want of one, and binaries stored
    // (docs/CLI.md "Shader cache"); all 0 where the cache is not used (no VK_EXT_shader_object, not Vulkan).
    const ShaderBinaryCache::Counts cache = ShaderBinaryCache::counts();
    j["shader_cache"] = {{"hits", cache.hits}, {"misses", cache.misses}, {"stores", cache.stores}};
    // The deform stage's steps where it has several: --split (deform.sample, ...), which the fused kernel
    // does not have, and accurate's three dispatches (accurate_samples, _patches, _tessellate).
    for (const auto& [step, ms] : t.steps)
      if ((args.has("--split") && step.find('.') != std::string::npos) || step.rfind("accurate_", 0) == 0)
        j["timings_ms"][step] = ms;
    std::string text = j.dump(1) + "\n";
    written.willWrite(args.get("--stats"));
    writeFileAtomically(args.get("--stats"), [&](std::ostream& o) { o << text; });
  }
  written.keep();
  note(args, "wrote " + out + " (" + std::to_string(outTriangles) + " triangles, " + device.label() + ", " +
                 device.info().name + ")");
  return 0;
}

}  // namespace

CommandSpec deformCommand() {
  CommandSpec c{"deform", "MESH -l LATTICE -o OUT [options]",
                "Deforms a mesh by a lattice and writes the result (.obj .ply .off .stl .gltf .glb) with vertex normals.",
                jobOptions(), run, 1, 1};
  c.options.insert(c.options.begin() + 1, {"--output|-o", "FILE", "output mesh (.obj .ply .off .stl .gltf .glb)"});
  c.options.insert(c.options.begin() + 2, {"--binary", nullptr, ".ply and .stl: write binary (little-endian float; double PLY with --precision double)"});
  c.options.insert(c.options.begin() + 3, {"--patches", "FILE", "smooth: also write the Bezier patches (docs/CLI.md)"});
  return c;
}

}  // namespace sffd::cli
