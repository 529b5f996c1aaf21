// sffd animate MESH -l L0 -l L1 [...] --frames N [--fps F] -o OUT.glb|frame_%04d.ply: one Deformer
// (one pre-compute), then one deform per frame with the control points interpolated linearly between
// the given lattices (same structure), written as a glTF with morph targets and an animation, or as
// numbered mesh files.
#include <cmath>
#include <cstdio>
#include <limits>

#include <sffd/error.h>

#include "apps/sffd/cli.h"
#include "apps/sffd/deform_job.h"
#include "core/job_budget.h"
#include "io/gltf_io.h"
#include "io/io_util.h"

namespace sffd::cli {
namespace {

// The file name of frame f for a pattern with one printf integer conversion ("frame_%04d.ply").
std::string frameName(const std::string& pattern, int f) {
  char name[4096];
  const int n = std::snprintf(name, sizeof name, pattern.c_str(), f);
  if (n < 0 || size_t(n) >= sizeof name) throw Error(ErrorKind::Input, "-o: the frame pattern makes no usable file name");
  return name;
}

// Whether -o numbers its frames, read as printf would: "%%" is a '%', and one "%d" or "%0Nd" (zero-padded
// to N digits, N up to 99) the frame number. Any other '%' is refused rather than taken literally or passed
// to printf: "%5d" padded with spaces into the names, and "100%%_%d.obj" was refused as no pattern.
bool isFramePattern(const std::string& out) {
  int numbers = 0;
  for (size_t p = out.find('%'); p != std::string::npos; p = out.find('%', p)) {
    size_t i = p + 1;
    if (i < out.size() && out[i] == '%') {
      p = i + 1;
      continue;
    }
    while (i < out.size() && std::isdigit(static_cast<unsigned char>(out[i]))) ++i;
    if (i >= out.size() || out[i] != 'd' || (i > p + 1 && out[p + 1] != '0') || i - p > 4 || ++numbers > 1)
      throw Error(ErrorKind::Input, "-o " + out + ": numbered files take one frame number, %d or %0Nd (zero-padded to N digits, "
                                    "like frame_%04d.ply), and %% for a literal %");
    p = i + 1;
  }
  return numbers == 1;
}

// Frame f of `frames`: key lattices spread evenly over the frames, control points interpolated
// linearly between the two keys around it (the first and last frames are the first and last keys).
Lattice frameLattice(const std::vector<Lattice>& keys, int f, int frames) {
  const double t = double(f) * double(keys.size() - 1) / double(frames - 1);
  const size_t s = std::min(size_t(t), keys.size() - 2);
  const double a = t - double(s);
  Lattice L = keys[s];
  if (a == 0.0) return L;
  for (size_t i = 0; i < L.controlPoints.size(); ++i)
    L.controlPoints[i] = (1.0 - a) * keys[s].controlPoints[i] + a * keys[s + 1].controlPoints[i];
  return L;
}

int run(const ParsedArgs& args) {
  const std::string out = args.requireValue("--output");
  checkJobOptions(args);
  const std::vector<std::string> paths = args.all("--lattice");
  if (paths.size() < 2) throw Error(ErrorKind::Input, "animate needs at least two lattices (-l L0 -l L1 ...)");
  if (!args.has("--frames")) throw Error(ErrorKind::Input, "animate needs --frames N (2..10000): how many frames to make");
  const int frames = args.getInt("--frames", 0, 2, 10000);
  const double fps = args.getDouble("--fps", 24.0);
  if (!std::isfinite(fps) || !(fps > 0) || fps > 1000) throw Error(ErrorKind::Input, "--fps must be a number in (0, 1000]");
  const bool numbered = isFramePattern(out);
  const std::string gltf = numbered ? "" : frameName(out, 0);   // "%%" is a '%' there too
  if (numbered && args.has("--fps")) throw Error(ErrorKind::Input, "--fps times a glTF animation; numbered files have no times");
  // glTF keeps the key times as floats: the last frame's, (N-1)/F seconds, must be one.
  if (!numbered && !(double(frames - 1) / fps <= std::numeric_limits<float>::max()))
    throw Error(ErrorKind::Input, "--fps " + args.get("--fps") + " puts the last frame past the seconds a glTF key time (a float) holds");
  const std::string ext = io::lowerExtension(out);
  if (!numbered && ext != ".glb" && ext != ".gltf")
    throw Error(ErrorKind::Input, "-o must name a .glb or .gltf file, or numbered files such as frame_%04d.ply");
  if (args.has("--binary") && ext != ".ply" && ext != ".stl") throw Error(ErrorKind::Input, "--binary writes .ply and .stl, not '" + ext + "'");
  std::vector<std::string> inputs = paths;
  inputs.push_back(args.positional[0]);
  for (int f = 0; f < (numbered ? frames : 1); ++f) checkOutputPath(numbered ? frameName(out, f) : gltf, inputs);

  Job job = loadJob(args);
  std::vector<Lattice> keys = {job.lattice};
  for (size_t i = 1; i < paths.size(); ++i) {
    keys.push_back(loadJobLattice(args, job, paths[i]));
    if (!sameLatticeStructure(keys[0], keys[i]))
      throw Error(ErrorKind::Input, paths[i] + ": its degrees, counts, knots, frame or outside rule differ from " + paths[0] +
                                        "'s (animate interpolates the control points of one lattice structure)");
  }
  Device device = openDeviceFromArgs(args);
  DeformRun run = runDeformJob(args, job, device);   // the pre-compute, and frame 0 (the first key)
  const MeshWriteOptions write{.significantDigits = run.deformer.resultDigits(), .binary = args.has("--binary")};
  // A glTF keeps every frame, and its buffer them again as floats: frame 0's size, `frames` times, must fit
  // before the others are made (10,000 frames of a smooth cube took 80 GB).
  if (!numbered)
    checkKeptFits(run.deformer, uint64_t(frames) * (meshHeldBytes(run.mesh) + 6 * sizeof(float) * run.mesh.positions.size()),
                  "the " + std::to_string(frames) + " frames of " + gltf,
                  "use fewer --frames, or numbered files (frame_%04d.ply), written one at a time");
  std::vector<Mesh> meshes;
  // Numbered frames: as they were again when a later one fails; kept on an interrupt, as finished files (there
  // may be thousands: more than the handler's fixed storage holds).
  WrittenFiles written(/*keptOnInterrupt=*/numbered);
  for (int f = 0; f < frames; ++f) {
    if (f > 0) {
      run.deformer.deform(frameLattice(keys, f, frames));
      run.mesh = run.deformer.result();
    }
    if (numbered) {
      written.willWrite(frameName(out, f));
      writeMesh(frameName(out, f), run.mesh, write);
    } else {
      meshes.push_back(std::move(run.mesh));
    }
  }
  if (!numbered) {
    written.willWrite(gltf);   // a .gltf's .bin is written first
    meshio::writeGltfAnimation(gltf, meshes, fps);
  }
  written.keep();
  note(args, "wrote " + (numbered ? std::to_string(frames) + " frames " + out : gltf + " (" + std::to_string(frames) + " frames)") + " (" +
                 device.label() + ", " + device.info().name + ")");
  return 0;
}

}  // namespace

CommandSpec animateCommand() {
  CommandSpec c{"animate", "MESH -l L0 -l L1 [-l L2 ...] --frames N -o OUT [options]",
                "Deforms a mesh by lattices interpolated frame by frame: a glTF animation or numbered mesh files.",
                {}, run, 1, 1};
  for (const OptionSpec& o : jobOptions())
    if (std::string(o.name) != "--stats") c.options.push_back(o);   // no run statistics are written
  for (OptionSpec& o : c.options)
    if (std::string(o.name) == "--lattice|-l") {
      o.help = "a key lattice (give two or more, same structure; .json, .prm or .npy)";
      o.repeatable = true;
    }
  c.options.insert(c.options.begin() + 1, {"--output|-o", "FILE", ".glb or .gltf (morph targets and an animation), or frame_%04d.EXT (one mesh a frame)"});
  c.options.insert(c.options.begin() + 2, {"--frames", "N", "frames, 2..10000: the first is the first lattice, the last the last"});
  c.options.insert(c.options.begin() + 3, {"--fps", "F", "glTF: frames per second (default 24)"});
  c.options.insert(c.options.begin() + 4, {"--binary", nullptr, "numbered .ply and .stl frames in binary"});
  return c;
}

}  // namespace sffd::cli
