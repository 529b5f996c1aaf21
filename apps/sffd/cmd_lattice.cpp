// sffd lattice MESH -o LATTICE.json: an identity lattice fitted to a mesh, optionally deformed by a preset.
#include <algorithm>
#include <charconv>

#include "apps/sffd/cli.h"
#include <sffd/error.h>
#include "io/lattice_io.h"

namespace sffd::cli {
namespace {

int run(const ParsedArgs& args) {
  std::string out = args.requireValue("--output");
  checkOutputPath(out, {args.positional[0]});
  std::array<int, 3> counts = args.getTriple("--counts", {5, 5, 5});
  std::array<int, 3> degree = args.getTriple("--degree", {2, 2, 2});
  for (int a = 0; a < 3; ++a) {
    if (degree[a] < 1 || degree[a] > 5) throw Error(ErrorKind::Input, "--degree values must be in 1..5");
    if (counts[a] <= degree[a]) throw Error(ErrorKind::Input, "--counts must exceed --degree on every axis");
    if (counts[a] > 64) throw Error(ErrorKind::Input, "--counts above 64 per axis is not supported by `sffd lattice`");
  }
  Mesh mesh = readMeshWarning(args.positional[0]);
  if (args.has("--normalize")) {
    double s = args.getDouble("--normalize", 1.0);
    if (!(s > 0)) throw Error(ErrorKind::Input, "--normalize needs a positive scale");
    normalizeMesh(mesh, s);
  }
  Lattice lattice = fitLattice(mesh, counts, degree, args.getDouble("--margin", 0.005));
  if (args.has("--preset")) {
    std::string p = args.get("--preset");
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
  writeLatticeJson(out, lattice);
  note(args, "wrote " + out);
  return 0;
}

}  // namespace

CommandSpec latticeCommand() {
  return {"lattice", "MESH -o LATTICE.json [options]",
          "Makes an identity lattice fitted to the mesh's bounding box, optionally deformed by a preset.",
          {
              {"--output|-o", "FILE", "lattice to write (.json)"},
              {"--counts", "U,V,W", "control points per axis (default 5,5,5)"},
              {"--degree", "U,V,W", "B-spline degree per axis, 1..5 (default 2,2,2)"},
              {"--preset", "NAME[:AMOUNT]", "twist, bend, taper, bulge or noise, with an optional amount (default 1)"},
              {"--margin", "F", "box margin as a fraction of the largest extent (default 0.005)"},
              {"--normalize", "S", "normalise the mesh first, as `deform --normalize S` will"},
              {"--quiet", nullptr, "no notes on stderr"},
              {"--help|-h", nullptr, "show this help"},
          },
          run, 1, 1};
}

}  // namespace sffd::cli
