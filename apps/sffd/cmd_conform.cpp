// sffd conform MESH -l LATTICE: runs the same job on several backends and compares every output
// buffer pairwise; exit 1 past tolerance (tolerances: docs/CONFORMANCE.md).
#include <algorithm>
#include <cstdio>
#include <sstream>

#include "analysis/buffer_compare.h"
#include "kernels/classic/classic_ffd.h"
#include "kernels/pn/pn_triangles.h"
#include "kernels/clip/regular_clip.h"
#include "kernels/clip/split_pattern_table.h"
#include "apps/sffd/cli.h"
#include <sffd/error.h>
#include "model/mesh_topology.h"

namespace sffd::cli {
namespace {

struct BackendRun {
  std::string label;
  bool isCpu = false;
  std::vector<std::pair<std::string, std::vector<double>>> buffers;
};

// Tolerance for a pair of backends (documented in docs/CONFORMANCE.md; measured figures there).
CompareTolerance toleranceFor(bool strict, bool f64, bool withCpu) {
  CompareTolerance t;
  if (strict) {
    t.bitExact = true;
  } else if (withCpu) {
    // GPU arithmetic against the double reference: a few float roundings per coefficient.
    t.maxUlp = f64 ? 1e6 : 64;
    t.absOfScale = f64 ? 1e-12 : 2e-6;
  } else {
    // GPU against GPU: the front ends reassociate differently (PLATFORM.md).
    t.maxUlp = f64 ? 1e6 : 64;
    t.absOfScale = f64 ? 1e-12 : 1e-6;
  }
  return t;
}

int run(const ParsedArgs& args) {
  std::vector<std::string> names;
  std::stringstream ss(args.get("--backends", "vulkan,gl-egl,gl-osmesa,cpu"));
  for (std::string n; std::getline(ss, n, ',');)
    if (!n.empty()) names.push_back(n);
  if (names.size() < 2) throw Error(ErrorKind::Input, "--backends needs at least two backends to compare");
  Job job = loadJob(args);
  PackedLattice packed = packLattice(job.lattice);
  if (!job.mesh.normalsFromFile) applyCreaseAngle(job.mesh, args.getDouble("--crease-angle", 40.0));
  PreparedMesh prepared = prepareMesh(job.mesh);
  glm::dvec3 lo, hi;
  meshBounds(job.mesh, lo, hi);
  double l = args.has("--edge-length") ? args.getDouble("--edge-length", 0) : 0.1 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  checkEdgeLength(job.mesh, l);
  ClipTriangles clip = buildClipTriangles(job.mesh, l, splitPatternTable().nmax());
  KernelVariant variant;
  variant.strict = args.has("--strict");
  std::string precision = args.get("--precision", "float");
  if (precision != "float" && precision != "double") throw Error(ErrorKind::Input, "--precision must be float or double");
  variant.f64 = precision == "double";

  std::vector<BackendRun> runs;
  for (const std::string& name : names) {
    DeviceRequest req;
    req.name = name;
    req.deviceSubstring = args.get("--device");
    Device device = Device::open(req);
    Backend& backend = device.backend();
    BackendRun r;
    r.label = device.label();
    r.isCpu = device.info().api == "cpu";
    // The CPU backend runs in the kernels' precision (in float, in the strict kernels' operation
    // order): conformance compares the same arithmetic on the same inputs. Accuracy against the
    // double reference is a separate matter (docs/CONFORMANCE.md).
    ClassicOutput classic = classicFfd(backend, job.mesh, packed, variant, chunkFromEnvironment("SFFD_MAX_CHUNK_VERTICES"));
    r.buffers.push_back({"classic.positions", std::move(classic.positions)});
    r.buffers.push_back({"classic.normals", std::move(classic.normals)});
    PnOutput pn = pnTriangles(backend, prepared, variant, chunkFromEnvironment("SFFD_MAX_CHUNK_TRIANGLES"));
    // Each backend clips from its own PN records: the whole pre-compute stage is compared.
    SubTriangleRecords subs =
        regularClip(backend, prepared, pn, clip, l, variant, chunkFromEnvironment("SFFD_MAX_CHUNK_SUBTRIANGLES"));
    r.buffers.push_back({"pn.records", std::move(pn.records)});
    r.buffers.push_back({"clip.headers", std::vector<double>(subs.headers.begin(), subs.headers.end())});
    r.buffers.push_back({"clip.records", std::move(subs.records)});
    runs.push_back(std::move(r));
  }

  bool pass = true;
  for (size_t i = 0; i < runs.size(); ++i)
    for (size_t j = i + 1; j < runs.size(); ++j)
      for (size_t k = 0; k < runs[i].buffers.size(); ++k) {
        bool withCpu = runs[i].isCpu || runs[j].isCpu;
        CompareResult c = compareBuffers(runs[i].buffers[k].second, runs[j].buffers[k].second, !variant.f64,
                                         toleranceFor(variant.strict, variant.f64, withCpu));
        std::printf("%s %s vs %s: max_abs=%.3g max_ulp=%llu mismatched=%zu/%zu\n", runs[i].buffers[k].first.c_str(),
                    runs[i].label.c_str(), runs[j].label.c_str(), c.maxAbs, (unsigned long long)c.maxUlp, c.mismatched,
                    c.total);
        if (c.mismatched) pass = false;
      }
  std::printf("conform: %s\n", pass ? "PASS" : "FAIL");
  return pass ? 0 : 1;
}

}  // namespace

CommandSpec conformCommand() {
  CommandSpec c{"conform", "MESH -l LATTICE [--backends vulkan,gl,cpu] [--strict]",
                "Runs the same job on several backends and compares every output buffer; exit 1 past tolerance.",
                jobOptions(), run, 1, 1};
  c.options.insert(c.options.begin() + 1,
                   {"--backends", "LIST", "comma-separated backends to compare (default vulkan,gl-egl,gl-osmesa,cpu)"});
  return c;
}

}  // namespace sffd::cli
