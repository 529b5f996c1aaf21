// sffd view MESH [-l LATTICE]: the interactive viewer (apps/view/view_app.h). This file is the glue to
// the command line: options, the job (mesh and lattice, or an identity lattice fitted to the mesh),
// the window, the backend (by default GL on the window's own context, so the smooth result is drawn
// where the kernels wrote it), and the host deformation functions the other methods run through.
#include <charconv>
#include <cmath>
#include <filesystem>

#include "apps/sffd/cli.h"
#include "apps/sffd/deform_job.h"
#include <sffd/deformer.h>
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
  ro.up = gl::upAxisFor(args.get("--up", "auto"), args.positional.at(0));
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
  if (args.has("--draft-tess")) {
    const std::string d = args.get("--draft-tess");
    int n = -1;
    auto [p, ec] = std::from_chars(d.data(), d.data() + d.size(), n);
    if (ec != std::errc() || p != d.data() + d.size() || n < 0 || n > kMaxTessLevel)
      throw usageError("--draft-tess must be an integer 0.." + std::to_string(kMaxTessLevel) + ", not '" + d +
                       "' (0: full quality while dragging too)");
    cfg.draftLevel = n;
  }

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
  std::optional<Device> device;
  if (name == "auto" || name == "gl" || name == "gl-glfw") {
    device.emplace("gl-glfw", gl::createBackendOn(cfg.window));
    cfg.zeroCopy = true;
  } else {
    device.emplace(openDeviceFromArgs(args));
  }
  cfg.device = &*device;
  cfg.backendLabel = device->label();
  note(args, "view: " + cfg.meshName + " on " + device->label() + " (" + device->info().name + ")");
  // The job options as `deform` reads them; the method and clipping change with the viewer's keys.
  DeformOptions& o = cfg.options;
  o.strict = args.has("--strict");
  o.edgeLength = l;
  o.tess = args.getInt("--tess", 10);
  o.samples = samplesOf(args);
  o.split = args.has("--split");
  o.creaseAngleDeg = creaseAngleOf(args);
  o.memoryLimit = memoryLimitFromEnvironment();   // each Deformer the viewer makes is checked against it
  const std::string precision = args.get("--precision", "auto");
  if (precision != "auto" && precision != "float" && precision != "double")
    throw usageError("--precision must be auto, float or double");
  o.precision = precision == "double" ? Precision::Double : precision == "float" ? Precision::Float : Precision::Auto;
  return view::runViewer(cfg);
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
      {"--up", "AXIS", "the model's up axis: x, y, z, -x, -y, -z or auto (default: y for glTF, z otherwise; y-up scans: y)"},
      {"--wireframe", nullptr, "start with the triangle edges drawn"},
      {"--replay", "SCRIPT", "run the commands of SCRIPT (one a line, see docs/CLI.md), then exit"},
      {"--out-dir", "DIR", "where screenshots and saved files go, and relative script paths point (default .)"},
      {"--draft-tess", "N", "tessellation level while dragging lattice points, drawn without multisampling; full quality on release (default 3; 0: always full)"},
  };
  for (const OptionSpec& o : jobOptions()) {
    std::string n = o.name;
    if (n == "--stats") c.options.push_back({"--stats", "FILE", "frame-time statistics as JSON at exit"});
    else if (n == "--backend") c.options.push_back({"--backend", "NAME", "gl (default: the window's context, zero copy)|vulkan|gl-egl|gl-osmesa|gles|cpu"});
    else c.options.push_back(o);
  }
  return c;
}

}  // namespace sffd::cli
