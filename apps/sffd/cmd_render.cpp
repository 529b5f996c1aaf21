// sffd render MESH [-l LATTICE] -o IMAGE.png: a headless picture of the mesh, or of its deformation by
// the lattice with any --method (apps/render/gl_renderer.h draws it on its own GL context, apart from the
// compute backend). --compare classic|input puts the classic FFD result or the input on the left.
#include <algorithm>
#include <cmath>
#include <charconv>
#include <filesystem>

#include "apps/sffd/cli.h"
#include "analysis/error_metrics.h"
#include "pipelines/patch_output.h"
#include "apps/sffd/deform_job.h"
#include <sffd/error.h>
#include "apps/render/gl_renderer.h"
#include "core/job_budget.h"
#include "model/mesh_topology.h"

namespace sffd::cli {
namespace {


Error usageError(const std::string& what) { return Error(ErrorKind::Input, what); }

}  // namespace

int sizeOption(const ParsedArgs& args, const char* name, int fallback) {
  return args.getInt(name, fallback, 16, 8192);
}

// --view AZ,EL in degrees.
void parseView(const std::string& text, double& az, double& el) {
  size_t comma = text.find(',');
  auto number = [&](const std::string& s, double& out) {
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && p == s.data() + s.size() && std::isfinite(out);
  };
  if (comma == std::string::npos || !number(text.substr(0, comma), az) || !number(text.substr(comma + 1), el))
    throw usageError("option --view needs AZIMUTH,ELEVATION in degrees like 30,20, not '" + text + "'");
  if (el < -90 || el > 90) throw usageError("--view: elevation must be within -90..90 degrees");
}

namespace {

std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), ::toupper);
  return s;
}

int run(const ParsedArgs& args) {
  // Everything about the request is checked before any work.
  const std::string out = args.requireValue("--output");
  std::string ext = std::filesystem::path(out).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  if (ext != ".png") throw usageError(out + ": render writes .png pictures only");
  gl::RenderOptions ro;
  ro.width = sizeOption(args, "--width", 1200);
  ro.height = sizeOption(args, "--height", 900);
  if (args.has("--view")) parseView(args.get("--view"), ro.azimuthDeg, ro.elevationDeg);
  ro.up = gl::upAxisFor(args.get("--up", "auto"), args.positional.at(0));
  ro.wireframe = args.has("--wireframe");
  const bool deform = args.has("--lattice");
  const std::string method = args.get("--method", "smooth");
  methodOf(method);   // an input Error for another name, before any work
  const std::string clip = args.get("--clip", "regular");
  if (clip != "regular" && clip != "knot-box") throw usageError("--clip must be regular or knot-box");
  const std::string colorBy = args.get("--color-by");
  if (args.has("--color-by") && colorBy != "geometry" && colorBy != "normal")
    throw usageError("--color-by must be geometry or normal, not '" + colorBy + "'");
  if (args.has("--color-by") && !args.has("--lattice")) throw usageError("--color-by needs a lattice (-l)");
  std::vector<float> errorScalars;
  const std::string compare = args.get("--compare");
  if (args.has("--compare") && compare != "classic" && compare != "input")
    throw usageError("--compare must be classic or input, not '" + compare + "'");
  if (args.has("--compare") && !deform) throw usageError("--compare needs a lattice (-l)");
  auto opt = [&](const char* o) { return args.has(o) ? std::optional<std::string>(args.get(o)) : std::nullopt; };
  checkSizeOptions(opt("--edge-length"), opt("--tess"));
  checkOutputPath(out, {args.positional[0], args.get("--lattice")});

  // The meshes: the input alone, or the result (beside the classic result or the input).
  std::vector<Mesh> meshes;
  std::vector<std::string> captions;
  std::string computedOn;
  if (!deform) {
    Mesh mesh = readMeshWarning(args.positional[0]);
    if (args.has("--normalize")) {
      double s = args.getDouble("--normalize", 1.0);
      if (!(s > 0)) throw usageError("--normalize needs a positive scale");
      normalizeMesh(mesh, s);
    }
    // Shaded with the creases the methods keep (a cube without normals was drawn smooth across its edges).
    if (!mesh.normalsFromFile) applyCreaseAngle(mesh, creaseAngleOf(args));
    meshes.push_back(std::move(mesh));
    captions.push_back("");
  } else {
    JobAndDevice opened = loadJobAndOpenDevice(args);
    Job& job = opened.job;
    Device& device = opened.device;
    computedOn = ", deformed on " + device.label();
    if (compare == "input") {
      meshes.push_back(job.mesh);
      if (!job.mesh.normalsFromFile) applyCreaseAngle(meshes.back(), creaseAngleOf(args));
      captions.push_back("input");
    } else if (compare == "classic") {
      Job classicJob = job;   // the methods may prepare the job's mesh in place
      meshes.push_back(runMethod(args, classicJob, device, Method::Classic).mesh);
      captions.push_back("classic FFD");
    }
    DeformRun run = runDeformJob(args, job, device);
    if (colorBy.empty()) {
      meshes.push_back(std::move(run.mesh));
    } else {
      // Every tessellation vertex coloured by its error against the exact FFD of its pre-image.
      std::optional<PatchVertices> patches = run.patches();
      PatchVertices pv = patches ? std::move(*patches) : linearPatchVertices(run.mesh, args.getInt("--tess", 10));
      PackedLattice packed = packLattice(job.lattice);
      ExactReference ref(job.mesh, packed);
      meshes.push_back(unweldedPatchMesh(pv));
      errorScalars.resize(pv.vertexCount());
      for (size_t v = 0; v < pv.vertexCount(); ++v) {
        glm::dvec3 x, n, xr, nr;
        ref.preImage(pv.parent[v / tessVertexCount(pv.level)], glm::dvec3(pv.lamParent[3 * v], pv.lamParent[3 * v + 1], pv.lamParent[3 * v + 2]), x, n);
        ref.deform(x, n, xr, nr);
        glm::dvec3 p(pv.position[3 * v], pv.position[3 * v + 1], pv.position[3 * v + 2]);
        glm::dvec3 q(pv.normal[3 * v], pv.normal[3 * v + 1], pv.normal[3 * v + 2]);
        errorScalars[v] = colorBy == "geometry" ? float(glm::length(p - xr))
                                                : float(std::atan2(glm::length(glm::cross(q, nr)), glm::dot(q, nr)) * 180 / M_PI);
      }
    }
    captions.push_back(args.has("--compare") ? method + " FFD" : (colorBy.empty() ? "" : colorBy + " error"));
  }
  for (const Mesh& m : meshes)
    if (m.triangles.empty()) throw Error(ErrorKind::Input, args.positional[0] + ": no triangles to draw");

  std::unique_ptr<gl::Renderer> renderer = gl::Renderer::createHeadless();
  std::vector<gl::RenderItem> items;
  for (size_t i = 0; i < meshes.size(); ++i)
    items.push_back({&meshes[i], i + 1 == meshes.size() ? errorScalars : std::vector<float>{}, upper(captions[i])});
  gl::Image image = renderer->render(items, ro);
  writePng(out, image);
  size_t triangles = 0;
  for (const Mesh& m : meshes) triangles += m.triangles.size();
  note(args, "wrote " + out + " (" + std::to_string(ro.width) + "x" + std::to_string(ro.height) + ", " +
                 std::to_string(triangles) + " triangles" + computedOn + ", drawn with " +
                 renderer->context().name() + " on " + renderer->deviceName() + ")");
  return 0;
}

}  // namespace

CommandSpec renderCommand() {
  CommandSpec c{"render", "MESH [-l LATTICE] -o IMAGE.png [options]",
                "Draws the mesh, or its deformation by a lattice, into a PNG picture (headless GL).",
                {}, run, 1, 1};
  c.options = {
      {"--output|-o", "FILE.png", "the picture (PNG)"},
      {"--width", "W", "picture width in pixels (default 1200)"},
      {"--height", "H", "picture height in pixels (default 900)"},
      {"--view", "AZ,EL", "view direction in degrees: azimuth around the up axis, elevation (default 30,20)"},
      {"--up", "AXIS", "the model's up axis: x, y, z, -x, -y, -z or auto (default: y for glTF, z otherwise; y-up scans: y)"},
      {"--wireframe", nullptr, "draw the triangle edges over the shading"},
      {"--compare", "WHAT", "classic|input: draw it on the left, the --method result on the right"},
      {"--color-by", "WHAT", "geometry|normal: colour the result by its error against the exact FFD (sffd error's metrics)"},
  };
  for (const OptionSpec& o : jobOptions())
    if (std::string(o.name) != "--stats") c.options.push_back(o);   // render writes a picture only
  return c;
}

}  // namespace sffd::cli
