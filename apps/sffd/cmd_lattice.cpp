// sffd lattice: an identity lattice fitted to a mesh, or a lattice read with --from; then optionally
// refined (knot insertion), elevated (degree) and deformed by a preset; written in the format its
// extension names.
#include <algorithm>
#include <charconv>

#include "apps/sffd/cli.h"
#include <sffd/error.h>
#include "io/io_util.h"
#include "io/lattice_io.h"

namespace sffd::cli {
namespace {

void applyPreset(Lattice& lattice, std::string p) {
  double amount = 1.0;
  size_t colon = p.find(':');
  if (colon != std::string::npos) {
    std::string a = p.substr(colon + 1);
    auto [e, ec] = std::from_chars(a.data(), a.data() + a.size(), amount);
    if (ec != std::errc() || e != a.data() + a.size()) throw Error(ErrorKind::Input, "--preset amount must be a number: " + p);
    p = p.substr(0, colon);
  }
  applyLatticePreset(lattice, p, amount);
}

Lattice fittedLattice(const ParsedArgs& args) {
  std::array<int, 3> counts = args.getTriple("--counts", {5, 5, 5}, 2, 64);
  std::array<int, 3> degree = args.getTriple("--degree", {2, 2, 2}, 1, 5);
  for (int a = 0; a < 3; ++a)
    if (counts[a] <= degree[a]) throw Error(ErrorKind::Input, "--counts must exceed --degree on every axis");
  Mesh mesh = readMeshWarning(args.positional[0]);
  if (args.has("--normalize")) {
    double s = args.getDouble("--normalize", 1.0);
    if (!(s > 0)) throw Error(ErrorKind::Input, "--normalize needs a positive scale");
    normalizeMesh(mesh, s);
  }
  const double margin = args.getDouble("--margin", 0.005);
  if (!(margin >= 0)) throw Error(ErrorKind::Input, "option --margin needs a fraction >= 0, not '" + args.get("--margin") + "'");
  return fitLattice(mesh, counts, degree, margin);
}

// --from FILE: read as `deform -l FILE` reads it (a .npy lattice needs MESH for its box, as there).
Lattice latticeFrom(const ParsedArgs& args) {
  for (const char* made : {"--counts", "--margin"})
    if (args.has(made))
      throw Error(ErrorKind::Input, std::string(made) + " fits a new lattice; with --from the lattice's own is kept (--refine and --elevate change it)");
  const std::string from = args.get("--from");
  // Options that would be ignored are refused, as --counts and --margin are.
  if (args.has("--degree") && io::lowerExtension(from) != ".npy")
    throw Error(ErrorKind::Input, "--degree is a fitted or .npy lattice's; " + from + " keeps its own (--elevate raises it)");
  if (args.has("--normalize") && args.positional.empty())
    throw Error(ErrorKind::Input, "--normalize normalises the MESH, and none is given (sffd lattice MESH --from L --normalize S)");
  if (args.positional.empty()) {
    LatticeReadOptions read;
    read.memoryLimit = memoryLimitFromEnvironment();
    read.npyDegree = args.getTriple("--degree", {2, 2, 2}, 1, 5);
    if (io::lowerExtension(from) == ".npy")
      throw Error(ErrorKind::Input, from + ": a .npy lattice has no box of its own: give the MESH it belongs to (sffd lattice MESH --from " + from + " ...)");
    return withToolLimitName([&] { return readLattice(from, read); });
  }
  ParsedArgs jobArgs = args;
  jobArgs.values["--lattice"] = from;
  Job job = loadJob(jobArgs);
  if (job.normalizedTo)
    note(args, "the lattice is in the coordinates of " + job.meshPath + " normalised to " + std::to_string(*job.normalizedTo) +
                   ": deform with --normalize " + std::to_string(*job.normalizedTo));
  return job.lattice;
}

int run(const ParsedArgs& args) {
  std::string out = args.requireValue("--output");
  std::vector<std::string> inputs = args.positional;
  if (args.has("--from")) inputs.push_back(args.get("--from"));
  checkOutputPath(out, inputs);
  if (!args.has("--from") && args.positional.empty())
    throw Error(ErrorKind::Input, "sffd lattice needs a MESH to fit a lattice to, or --from LATTICE");
  Lattice lattice = args.has("--from") ? latticeFrom(args) : fittedLattice(args);
  const std::string source = args.has("--from") ? args.get("--from") : out;
  const uint64_t limit = memoryLimitFromEnvironment();
  if (args.has("--refine"))
    lattice = withToolLimitName([&] { return refineLattice(lattice, args.getTriple("--refine", {1, 1, 1}, 1, 64), source, limit); });
  if (args.has("--elevate"))
    lattice = withToolLimitName([&] { return elevateLattice(lattice, args.getTriple("--elevate", {0, 0, 0}, 0, 4), source, limit); });
  if (args.has("--preset")) applyPreset(lattice, args.get("--preset"));
  writeLattice(out, lattice);
  note(args, "wrote " + out + " (" + std::to_string(lattice.counts[0]) + "x" + std::to_string(lattice.counts[1]) + "x" +
                 std::to_string(lattice.counts[2]) + " control points, degree " + std::to_string(lattice.degree[0]) + "," +
                 std::to_string(lattice.degree[1]) + "," + std::to_string(lattice.degree[2]) + ")");
  return 0;
}

}  // namespace

CommandSpec latticeCommand() {
  return {"lattice", "[MESH] -o LATTICE.json|.npy|.prm|.vtk [--from LATTICE] [options]",
          "Makes an identity lattice fitted to the mesh's bounding box (or reads one with --from), optionally refined, "
          "elevated and deformed by a preset.",
          {
              {"--output|-o", "FILE", "lattice to write: .json (native), .npy (control points), .prm (PyGeM; one Bezier box), .vtk (control net for ParaView)"},
              {"--from", "LATTICE", "start from this lattice (.json, .prm; .npy with the MESH it belongs to) instead of fitting one"},
              {"--refine", "U,V,W", "split every knot span into U, V, W equal spans (knot insertion: the same deformation, more control points)"},
              {"--elevate", "U,V,W", "raise the degree by U, V, W (exact: the same deformation, more control points; degrees up to 5)"},
              {"--counts", "U,V,W", "control points per axis of a fitted lattice (default 5,5,5)"},
              {"--degree", "U,V,W", "B-spline degree per axis of a fitted lattice (or of a .npy --from), 1..5 (default 2,2,2)"},
              {"--preset", "NAME[:AMOUNT]", "twist, bend, taper, bulge or noise, with an optional amount (default 1), applied last"},
              {"--margin", "F", "box margin of a fitted lattice as a fraction of the largest extent (default 0.005)"},
              {"--normalize", "S", "normalise the mesh first, as `deform --normalize S` will"},
              {"--quiet", nullptr, "no notes on stderr"},
              {"--help|-h", nullptr, "show this help"},
          },
          run, 0, 1};
}

}  // namespace sffd::cli
