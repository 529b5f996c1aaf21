// sffd clip MESH -l LATTICE: the pre-compute stage alone (PN triangles, then regular or knot-box
// clipping); writes the sub-triangles and their shape statistics.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>

#include <nlohmann/json.hpp>

#include "io/atomic_file.h"
#include "apps/sffd/deform_job.h"
#include <sffd/error.h>
#include "kernels/clip/knot_box_clip.h"
#include "model/mesh_topology.h"
#include "kernels/clip/regular_clip.h"
#include "kernels/common/shader_layout.h"
#include "kernels/clip/split_pattern_table.h"
#include "analysis/triangle_quality.h"

namespace sffd::cli {
namespace {

// The sub-triangles as a mesh: corners welded where position and normal bits agree.
Mesh subTriangleMesh(const SubTriangleRecords& R, bool flat) {
  Mesh m;
  std::map<std::array<uint64_t, 6>, uint32_t> ids;
  std::map<std::array<uint64_t, 3>, uint32_t> welds;
  int posSlot = flat ? SFFD_SUB_XFLAT : SFFD_SUB_XPN, nrmSlot = flat ? SFFD_SUB_NLIN : SFFD_SUB_NPN;
  for (size_t s = 0; s < R.size(); ++s) {
    std::array<uint32_t, 3> tri;
    for (int c = 0; c < 3; ++c) {
      const double* p = &R.records[(s * SFFD_SUB_STRIDE + posSlot + c) * 4];
      const double* n = &R.records[(s * SFFD_SUB_STRIDE + nrmSlot + c) * 4];
      std::array<uint64_t, 6> key;
      std::memcpy(key.data(), p, 24);
      std::memcpy(key.data() + 3, n, 24);
      auto [it, fresh] = ids.emplace(key, uint32_t(m.positions.size()));
      if (fresh) {
        m.positions.push_back({p[0], p[1], p[2]});
        m.normals.push_back({n[0], n[1], n[2]});
        std::array<uint64_t, 3> wk{key[0], key[1], key[2]};
        m.weldId.push_back(welds.emplace(wk, uint32_t(welds.size())).first->second);
      }
      tri[c] = it->second;
    }
    m.triangles.push_back(tri);
  }
  m.normalsFromFile = true;
  return m;
}

nlohmann::ordered_json statsJson(const QualityStats& q) {
  return {{"count", q.count},
          {"min_angle_deg", q.minAngleDeg},
          {"quality", {{"min", q.quality[0]}, {"p1", q.quality[1]}, {"median", q.quality[2]}, {"mean", q.quality[3]}, {"max", q.quality[4]}}},
          {"share_below_0_3", q.shareBelow03},
          {"aspect_ratio", {{"p50", q.aspect[0]}, {"p90", q.aspect[1]}, {"p99", q.aspect[2]}, {"max", q.aspect[3]}}},
          {"area_ratio", {{"min", q.areaRatio[0]}, {"max", q.areaRatio[1]}, {"cv", q.areaRatio[2]}}},
          {"quality_histogram", q.histogram}};
}


int run(const ParsedArgs& args) {
  std::string out = args.requireValue("--output");
  args.requireValue("--lattice");
  std::string clip = args.get("--clip", "regular");
  if (clip != "regular" && clip != "knot-box") throw Error(ErrorKind::Input, "--clip must be regular or knot-box");
  checkOutputPath(out, {args.positional[0], args.get("--lattice")});
  if (args.has("--stats")) checkOutputPath(args.get("--stats"), {args.positional[0], args.get("--lattice"), out});

  auto t0 = std::chrono::steady_clock::now();
  Job job = loadJob(args);
  if (!job.mesh.normalsFromFile) applyCreaseAngle(job.mesh, creaseAngleOf(args));
  double l = edgeLengthOf(args, job.mesh);
  checkEdgeLength(job.mesh, l);
  Device device = openDeviceFromArgs(args);
  KernelVariant variant;
  variant.strict = args.has("--strict");
  variant.f64 = wantDouble(args, device.info(), /*autoDouble=*/false);
  // The kernels one by one (the Deformer runs them all), on the device's backend.
  Backend& backend = device.backend();

  PreparedMesh prepared = prepareMesh(job.mesh);
  PnOutput pn = pnTriangles(backend, prepared, variant, chunkFromEnvironment("SFFD_MAX_CHUNK_TRIANGLES"));
  SubTriangleRecords subs;
  size_t presplit = 0, clipTriangles = 0;
  auto tc = std::chrono::steady_clock::now();
  if (clip == "regular") {
    if (!clipTargetFits(l)) {
      char text[32];
      std::snprintf(text, sizeof text, "%.3g", l);
      throw Error(ErrorKind::Input, std::string("--edge-length ") + text + " is below the smallest float (1.2e-38) that the clip kernels take it in");
    }
    ClipTriangles C = buildClipTriangles(job.mesh, l, splitPatternTable().nmax());
    presplit = C.presplitParents;
    clipTriangles = C.triangles.size();
    subs = regularClip(backend, prepared, pn, C, l, variant, chunkFromEnvironment("SFFD_MAX_CHUNK_SUBTRIANGLES"));
  } else {
    // The 2015 method runs on the CPU reference (it is the baseline, not a production path).
    subs = recordsFromSubTriangles(prepared, pn, clipAgainstKnotBoxes(job.mesh, job.lattice), variant);
  }
  double clipMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tc).count();
  Mesh result = subTriangleMesh(subs, args.has("--flat"));
  WrittenFiles written;   // as they were again when a --stats cannot be written
  written.willWrite(out);
  writeMesh(out, result, variant.f64 ? 17 : 9);

  if (args.has("--stats")) {
    std::vector<std::array<glm::dvec3, 3>> flatTris;
    flatTris.reserve(subs.size());
    for (size_t s = 0; s < subs.size(); ++s) {
      std::array<glm::dvec3, 3> t;
      for (int c = 0; c < 3; ++c) {
        const double* p = &subs.records[(s * SFFD_SUB_STRIDE + SFFD_SUB_XFLAT + c) * 4];
        t[c] = {p[0], p[1], p[2]};
      }
      flatTris.push_back(t);
    }
    const MeshTopology& topo = prepared.topology;
    double totalMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    nlohmann::ordered_json j = {
        {"backend", device.label()},
        {"device", device.info().name},
        {"clip", clip},
        {"edge_length", l},
        {"input", {{"vertices", job.mesh.positions.size()}, {"triangles", job.mesh.triangles.size()}}},
        {"topology", {{"boundary_edges", topo.boundaryEdges}, {"non_manifold_edges", topo.nonManifoldEdges},
                      {"crease_edges", topo.creaseEdges}, {"degenerate_triangles", topo.degenerateTriangles}}},
        {"sub_triangles", subs.size()},
        {"clip_triangles", clipTriangles},
        {"presplit_parents", presplit},
        {"split_nmax", splitPatternTable().nmax()},
        {"quality", statsJson(qualityStats(flatTris))},
        {"output", {{"vertices", result.positions.size()}, {"triangles", result.triangles.size()}}},
        {"timings_ms", {{"pn", pn.wallMs}, {"clip", clipMs}, {"total", totalMs}}},
    };
    std::string text = j.dump(1) + "\n";
    written.willWrite(args.get("--stats"));
    writeFileAtomically(args.get("--stats"), [&](std::ostream& o) { o << text; });
  }
  written.keep();
  note(args, "wrote " + out + " (" + std::to_string(subs.size()) + " sub-triangles, " + clip + " clipping, " + device.label() + ")");
  return 0;
}

}  // namespace

CommandSpec clipCommand() {
  // The job options less those of the deform stage, which clip does not run (taken and ignored before).
  std::vector<OptionSpec> options;
  for (const OptionSpec& o : jobOptions())
    if (std::string n = o.name; n != "--method" && n != "--tess" && n != "--split" && n != "--samples") options.push_back(o);
  CommandSpec c{"clip", "MESH -l LATTICE -o SUB.obj [--edge-length L] [--clip regular|knot-box] [--stats S.json]",
                "Runs the pre-compute stage (PN triangles and clipping) and writes the sub-triangles and their statistics.",
                options, run, 1, 1};
  c.options.insert(c.options.begin() + 1, {"--output|-o", "FILE", "sub-triangle mesh to write (.obj .ply .off .stl)"});
  c.options.insert(c.options.begin() + 2, {"--flat", nullptr, "write the sub-triangles on the flat parents instead of the PN surface"});
  return c;
}

}  // namespace sffd::cli
