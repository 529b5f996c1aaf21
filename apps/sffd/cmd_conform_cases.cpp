// sffd conform: the cases (from the command line or a case file) and what one case runs on a device:
// every kernel of its method, every output buffer downloaded.
#include <algorithm>
#include <fstream>
#include <sstream>

#include <sffd/error.h>

#include "apps/sffd/conform.h"
#include "apps/sffd/deform_job.h"
#include "core/fnv1a.h"
#include "core/job_budget.h"
#include "kernels/accurate/accurate_patches.h"
#include "kernels/classic/classic_ffd.h"
#include "kernels/common/layout.h"
#include "kernels/clip/knot_box_clip.h"
#include "kernels/clip/regular_clip.h"
#include "kernels/clip/split_pattern_table.h"
#include "kernels/pn/pn_triangles.h"
#include "kernels/smooth/smooth_deform.h"
#include "model/lattice_pack.h"
#include "model/mesh_topology.h"

namespace sffd::cli::conform {

std::string Case::variant() const { return std::string(strict() ? "strict " : "fast ") + (f64() ? "double" : "float"); }

const CommandSpec& caseSpec() {
  static const CommandSpec spec = [] {
    CommandSpec c{"conform", "MESH -l LATTICE [options]", "", {}, nullptr, 1, 1};
    for (const OptionSpec& o : jobOptions()) {
      std::string n = o.name;
      if (n == "--backend" || n == "--device" || n == "--stats" || n == "--quiet" || n == "--help|-h") continue;
      if (n == "--precision") c.options.push_back({o.name, o.value, "float|double kernel arithmetic (default float)"});
      else if (n == "--split") c.options.push_back({o.name, o.value, "smooth: the deform steps' kernels (deform_step_*) instead of the fused one"});
      else c.options.push_back(o);
    }
    return c;
  }();
  return spec;
}

namespace {

// Refuses what a case cannot mean before any backend runs (exit 2 rather than a Fail on every backend).
void checkCase(const Case& c) {
  const std::string m = c.method(), clip = c.args.get("--clip", "regular"), p = c.args.get("--precision", "float");
  if (m != "smooth" && m != "accurate" && m != "classic")
    throw Error(ErrorKind::Input, c.name + ": --method must be smooth, accurate or classic, not '" + m + "'");
  if (clip != "regular" && clip != "knot-box") throw Error(ErrorKind::Input, c.name + ": --clip must be regular or knot-box");
  if (p != "float" && p != "double") throw Error(ErrorKind::Input, c.name + ": --precision must be float or double");
  try {
    c.args.getInt("--tess", 10, 1, kMaxTessLevel);
  } catch (const Error& e) {
    throw Error(ErrorKind::Input, c.name + ": " + e.what());
  }
  for (const std::string& f : {c.args.positional.at(0), c.args.requireValue("--lattice")})
    if (!fs::is_regular_file(f)) throw Error(ErrorKind::Input, c.name + ": " + f + ": no such file");
}

Case makeCase(const std::string& name, std::vector<std::string> argv) {
  Case c;
  c.name = name;
  c.argv = std::move(argv);
  std::vector<char*> raw;
  for (std::string& a : c.argv) raw.push_back(a.data());
  c.args = parseArgs(caseSpec(), int(raw.size()), raw.data());
  checkCase(c);
  return c;
}

std::string fnv1a(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  uint64_t h = kFnv1aSeed;
  char buf[65536];
  while (f.read(buf, sizeof buf) || f.gcount()) h = fnv1a64(buf, size_t(f.gcount()), h);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", (unsigned long long)h);
  return hex;
}

}  // namespace

Case caseFromArgs(const ParsedArgs& args) {
  std::vector<std::string> argv{args.positional.at(0)};
  for (const OptionSpec& o : caseSpec().options) {
    const std::string name = std::string(o.name).substr(0, std::string(o.name).find('|'));
    if (!args.has(name)) continue;
    argv.push_back(name);
    if (o.value) argv.push_back(args.get(name));
  }
  // The mesh's stem names the case, unless it is no folder name ("...obj": "..", whose buffers would land in the
  // folder above the backend's, where every backend's are the same files).
  const std::string stem = fs::path(args.positional[0]).stem().string();
  return makeCase(stem.empty() || stem == "." || stem == ".." ? "mesh" : stem, argv);
}

std::vector<Case> readCases(const std::string& spec, const std::string& dataDir) {
  fs::path file = spec == "default" ? fs::path(dataDir) / "conform" / "default.cases" : fs::path(spec);
  std::ifstream in(file);
  if (!in) throw Error(ErrorKind::Input, file.string() + ": cannot read the case file");
  std::vector<Case> cases;
  std::string line;
  for (size_t n = 1; std::getline(in, line); ++n) {
    line = line.substr(0, line.find('#'));
    std::istringstream ss(line);
    std::vector<std::string> words;
    for (std::string w; ss >> w;) words.push_back(w);
    if (words.empty()) continue;
    if (words.size() < 2) throw inputError(file.string(), n, "a case is NAME MESH -l LATTICE [options]");
    for (const Case& c : cases)
      if (c.name == words[0]) throw inputError(file.string(), n, "case '" + words[0] + "' is named twice");
    // A case's buffers go to the folder named after it in each backend's: "." and ".." would be the same for all.
    if (words[0].find_first_of("/,\"<>& ") != std::string::npos || words[0] == "." || words[0] == "..")
      throw inputError(file.string(), n, "a case name has no / , \" < > & or spaces and is not . or ..");
    // Paths are relative to the case file: the mesh and the lattice.
    auto resolve = [&](std::string& p) { if (fs::path(p).is_relative()) p = (file.parent_path() / p).lexically_normal().string(); };
    std::vector<std::string> argv(words.begin() + 1, words.end());
    resolve(argv[0]);
    for (size_t i = 1; i + 1 < argv.size(); ++i)
      if (argv[i] == "-l" || argv[i] == "--lattice") resolve(argv[i + 1]);
    try {
      cases.push_back(makeCase(words[0], argv));
    } catch (const Error& e) {
      throw inputError(file.string(), n, e.what());
    }
  }
  if (cases.empty()) throw Error(ErrorKind::Input, file.string() + ": no cases");
  return cases;
}

std::map<std::string, std::string> inputHashes(const Case& c) {
  return {{"mesh", fnv1a(c.args.positional.at(0))}, {"lattice", fnv1a(c.args.get("--lattice"))}};
}

std::vector<std::string> bufferNames(const Case& c) {
  if (c.method() == "classic") return {"classic.positions", "classic.normals"};
  if (c.method() == "accurate") return {"accurate.patches", "accurate.tess.positions", "accurate.tess.normals"};
  return {"pn.records", "clip.headers", "clip.records", "deform.patches", "deform.tess.positions", "deform.tess.normals"};
}

CaseOutput runCase(Device& device, const Case& c) {
  Backend& backend = device.backend();
  const ParsedArgs& args = c.args;
  Job job = loadJob(args);
  if (c.f64() && !device.info().limits.float64) throw deviceError(device.info().name + " has no double-precision shaders");
  const KernelVariant variant{c.strict(), c.f64()};
  const PackedLattice packed = packLattice(job.lattice);
  const int level = args.getInt("--tess", 10);
  const Lattice& L = job.lattice;
  CaseOutput out;
  auto add = [&](const char* name, const char* unit, size_t perUnit, std::vector<double> v) {
    out.buffers.push_back({name, unit, perUnit, std::move(v)});
  };
  if (c.method() == "classic") {
    ClassicOutput r = classicFfd(backend, job.mesh, packed, variant, chunkFromEnvironment("SFFD_MAX_CHUNK_VERTICES"));
    add("classic.positions", "vertex", 4, std::move(r.positions));
    add("classic.normals", "vertex", 4, std::move(r.normals));
    return out;
  }
  const size_t nv = size_t(tessVertexCount(level));
  // The tessellation holds per patch its nv positions, then its nv normals: two buffers.
  auto splitTess = [&](const std::vector<double>& t, const char* pos, const char* nrm) {
    std::vector<double> p, n;
    for (size_t at = 0; at < t.size(); at += 8 * nv) {
      p.insert(p.end(), t.begin() + at, t.begin() + at + 4 * nv);
      n.insert(n.end(), t.begin() + at + 4 * nv, t.begin() + at + 8 * nv);
    }
    add(pos, "sub-triangle", 4 * nv, std::move(p));
    add(nrm, "sub-triangle", 4 * nv, std::move(n));
  };
  if (c.method() == "accurate") {
    AccurateJob aj = makeAccurateJob(job.mesh, L, clipAgainstKnotBoxes(job.mesh, L), level);
    AccurateOutput r = accurateFfd(backend, aj, packed, variant, chunkFromEnvironment("SFFD_MAX_CHUNK_PATCHES"));
    add("accurate.patches", "patch", 4 * size_t(triangleControlPoints(aj.degree)), std::move(r.controlPoints));
    add("accurate.tess.positions", "patch", 4 * nv, std::move(r.positions));
    add("accurate.tess.normals", "patch", 4 * nv, std::move(r.normals));
    for (const SubTriangle& s : aj.subs) out.parents.push_back(s.parent);
    return out;
  }
  // Smooth: the PN records, the clipping (regular on the device, or knot-box from this backend's PN
  // records), the deform kernels fused or split; each stage reads this backend's previous output.
  if (!job.mesh.normalsFromFile) applyCreaseAngle(job.mesh, creaseAngleOf(args));
  PreparedMesh prepared = prepareMesh(job.mesh);
  PnOutput pn = pnTriangles(backend, prepared, variant, chunkFromEnvironment("SFFD_MAX_CHUNK_TRIANGLES"));
  SubTriangleRecords subs;
  if (args.get("--clip", "regular") == "knot-box") {
    subs = recordsFromSubTriangles(prepared, pn, clipAgainstKnotBoxes(job.mesh, L), variant);
  } else {
    const double l = edgeLengthOf(args, job.mesh);
    checkEdgeLength(job.mesh, l);
    subs = regularClip(backend, prepared, pn, buildClipTriangles(job.mesh, l, splitPatternTable().nmax()), l, variant,
                       chunkFromEnvironment("SFFD_MAX_CHUNK_SUBTRIANGLES"));
  }
  const int s = std::max(3, samplesOf(args) > 0 ? samplesOf(args) : L.degree[0] + L.degree[1] + L.degree[2]);   // as the Deformer
  SmoothOutput d = smoothDeform(backend, packed, subs, makeFitTable(s), level, variant, args.has("--split"),
                                chunkFromEnvironment("SFFD_MAX_CHUNK_SUBTRIANGLES"));
  for (size_t i = 0; i < subs.size(); ++i) out.parents.push_back(subs.headers[4 * i]);
  add("pn.records", "triangle", SFFD_PN_STRIDE * 4, std::move(pn.records));
  add("clip.headers", "sub-triangle", 4, std::vector<double>(subs.headers.begin(), subs.headers.end()));
  add("clip.records", "sub-triangle", SFFD_SUB_STRIDE * 4, std::move(subs.records));
  add("deform.patches", "sub-triangle", SFFD_PATCH_STRIDE * 4, std::move(d.patches));
  splitTess(d.tess, "deform.tess.positions", "deform.tess.normals");
  return out;
}

}  // namespace sffd::cli::conform
