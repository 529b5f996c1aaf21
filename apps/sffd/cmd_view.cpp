// sffd view MESH [-l LATTICE]: the interactive viewer (apps/view/view_app.h). This file is the glue to
// the command line: options, the job (mesh and lattice, or an identity lattice fitted to the mesh),
// the window, the backend (by default GL on the window's own context, so the smooth result is drawn
// where the kernels wrote it), and the host deformation functions the other methods run through.
#include <charconv>
#include <cmath>
#include <filesystem>

#include "apps/sffd/cli.h"
#include "apps/sffd/deform_job.h"
#include <sffd/error.h>
#include "backends/opengl/gl_backend.h"
#include "backends/opengl/gl_context.h"
#include "core/job_budget.h"
#include "model/mesh_topology.h"
#include "apps/view/view_app.h"
#include "apps/view/view_script.h"

namespace sffd::cli {


namespace {

Error usageError(const std::string& what) { return Error(ErrorKind::Input, what); }



int run(const ParsedArgs& args) {
  // The request is checked before any work (and before a window is asked for).
  view::ViewConfig cfg;
  gl::RenderOptions& ro = cfg.render;
  ro.width = sizeOption(args, "--width", 1200);
  ro.height = sizeOption(args, "--height", 900);
  if (args.has("--view")) parseView(args.get("--view"), ro.azimuthDeg, ro.elevationDeg);
  if (args.has("--up")) ro.up = gl::parseUpAxis(args.get("--up"));
  ro.wireframe = args.has("--wireframe");
  cfg.settings.method = args.get("--method", "smooth");
  if (cfg.settings.method != "smooth" && cfg.settings.method != "accurate" && cfg.settings.method != "classic")
    throw usageError("--method must be smooth, accurate or classic, not '" + cfg.settings.method + "'");
  cfg.settings.clip = args.get("--clip", "regular");
  if (cfg.settings.clip != "regular" && cfg.settings.clip != "knot-box") throw usageError("--clip must be regular or knot-box");
  cfg.replayPath = args.get("--replay");
  if (!cfg.replayPath.empty()) view::readScript(cfg.replayPath);   // a bad line is reported before any work
  cfg.outDir = args.get("--out-dir", ".");
  if (!std::filesystem::is_directory(cfg.outDir)) throw usageError("--out-dir " + cfg.outDir + ": no such directory");
  cfg.statsPath = args.get("--stats");
  cfg.quiet = args.has("--quiet");
  auto opt = [&](const char* o) { return args.has(o) ? std::optional<std::string>(args.get(o)) : std::nullopt; };
  checkSizeOptions(opt("--edge-length"), opt("--tess"));
  cfg.level = args.getInt("--tess", 10);

  // The job: the mesh and its lattice, or an identity 5x5x5 quadratic lattice around the mesh.
  Job job;
  if (args.has("--lattice")) {
    job = loadJob(args);
  } else {
    job.meshPath = args.positional[0];
    job.mesh = readMeshWarning(job.meshPath);
    if (args.has("--normalize")) {
      double s = args.getDouble("--normalize", 1.0);
      if (!(s > 0)) throw usageError("--normalize needs a positive scale");
      normalizeMesh(job.mesh, s);
    }
    glm::dvec3 lo, hi;
    meshBounds(job.mesh, lo, hi);
    if (job.mesh.positions.empty()) throw Error(ErrorKind::Input, job.meshPath + ": no vertices");
    const double margin = 0.005 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 1e-9});
    job.lattice = makeIdentityLattice(lo - margin, hi + margin, {5, 5, 5}, {2, 2, 2});
    job.latticePath = "identity lattice";
  }
  if (job.mesh.triangles.empty()) throw Error(ErrorKind::Input, job.meshPath + ": no triangles to draw");
  cfg.sessionMesh = job.mesh;
  const double l = edgeLengthOf(args, cfg.sessionMesh);
  checkEdgeLength(cfg.sessionMesh, l);
  cfg.lattice = job.lattice;
  cfg.meshName = std::filesystem::path(job.meshPath).filename().string();
  cfg.latticeName = job.latticePath;

  // The window, then the backend: GL on the window's context unless another is named.
  gl::GlfwWindowOptions wo;
  wo.visible = true;
  wo.width = ro.width;
  wo.height = ro.height;
  wo.title = "sffd view - " + cfg.meshName;
  cfg.window = std::shared_ptr<gl::Context>(gl::createGlfwContext(wo));
  const std::string name = args.get("--backend", "gl");
  OpenedBackend backend;
  if (name == "auto" || name == "gl" || name == "gl-glfw") {
    backend.backend = gl::createBackendOn(cfg.window);
    backend.info = backend.backend->info();
    backend.label = "gl-glfw";
    cfg.zeroCopy = true;
  } else {
    backend = openBackendFromArgs(args);
  }
  cfg.gpu = backend.backend.get();
  cfg.backendLabel = backend.label;
  note(args, "view: " + cfg.meshName + " on " + backend.label + " (" + backend.info.name + ")");
  DeformSessionOptions so;
  so.variant.strict = args.has("--strict");
  so.edgeLength = l;
  so.level = cfg.level;
  so.samples = args.getInt("--samples", 0);
  so.split = args.has("--split");
  so.creaseAngleDeg = args.getDouble("--crease-angle", 40.0);
  cfg.session = so;
  const Mesh raw = job.mesh;
  cfg.host = [&args, &backend, &raw, &job](const Lattice& lattice, const std::string& method, const std::string& clip) {
    ParsedArgs a = args;
    a.values["--method"] = method;
    a.values["--clip"] = clip;
    Job j;
    j.meshPath = job.meshPath;
    j.latticePath = job.latticePath;
    j.mesh = raw;
    j.lattice = lattice;
    DeformRun r = method == "classic" ? runClassic(a, j, backend) : method == "accurate" ? runAccurate(a, j, backend)
                                                                                         : runSmooth(a, j, backend);
    view::HostResult h;
    h.input = std::move(j.mesh);
    h.mesh = std::move(r.mesh);
    h.patches = std::move(r.patches);
    h.pnMs = r.pnMs, h.clipMs = r.clipMs, h.deformMs = r.deformMs;
    return h;
  };
  int status = view::runViewer(cfg);
  cfg.host = nullptr;
  return status;
}

}  // namespace

CommandSpec viewCommand() {
  CommandSpec c{"view", "MESH [-l LATTICE] [options]",
                "Interactive viewer: drag lattice points and see the deformation (GLFW window; --replay for scripts).",
                {}, run, 1, 1};
  c.options = {
      {"--width", "W", "window width in pixels (default 1200)"},
      {"--height", "H", "window height in pixels (default 900)"},
      {"--view", "AZ,EL", "view direction in degrees, as for render (default 30,20)"},
      {"--up", "AXIS", "the model's up axis: x, y, z, -x, -y, -z (default z)"},
      {"--wireframe", nullptr, "start with the triangle edges drawn"},
      {"--replay", "SCRIPT", "run the commands of SCRIPT (one a line, see docs/CLI.md), then exit"},
      {"--out-dir", "DIR", "where screenshots and saved files go, and relative script paths point (default .)"},
  };
  for (const OptionSpec& o : jobOptions()) {
    std::string n = o.name;
    if (n == "--stats") c.options.push_back({"--stats", "FILE", "frame-time statistics as JSON at exit"});
    else if (n == "--backend") c.options.push_back({"--backend", "NAME", "gl (default: the window's context, zero copy)|vulkan|gl-egl|gl-osmesa|cpu"});
    else c.options.push_back(o);
  }
  return c;
}

}  // namespace sffd::cli
