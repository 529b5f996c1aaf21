// `sffd lattice` as a user runs it: every output format, --from, --refine and --elevate, checked by
// deforming with the written lattices (classic FFD on the CPU device in double: the exact map).
#include <gtest/gtest.h>

#include <cmath>

#include <sffd/mesh.h>

#include "tests/support/cli_runner.h"

namespace sffd::test {
namespace {

const std::string kSphere = std::string(SFFD_TEST_DATA) + "/sphere.obj";

// Deforms the sphere with `lattice` (classic, CPU, double) and returns the positions written.
std::vector<glm::dvec3> deformed(const fs::path& dir, const fs::path& lattice) {
  const fs::path out = dir / (lattice.stem().string() + lattice.extension().string().substr(1) + ".obj");
  RunResult r = runSffd("deform " + kSphere + " -l " + lattice.string() +
                        " --method classic --backend cpu --precision double --quiet -o " + out.string());
  EXPECT_EQ(r.status, 0) << r.err;
  return readMesh(out.string()).positions;
}

double largestDistance(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b) {
  EXPECT_EQ(a.size(), b.size());
  double worst = a.size() == b.size() ? 0.0 : INFINITY;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) worst = std::max(worst, glm::length(a[i] - b[i]));
  return worst;
}

TEST(LatticeCommand, RefinedAndElevatedLatticesDeformTheSame) {
  fs::path dir = tempDir("lattice_refine_cli");
  const fs::path base = dir / "base.json", refined = dir / "refined.json", elevated = dir / "elevated.json";
  ASSERT_EQ(runSffd("lattice " + kSphere + " -o " + base.string() + " --counts 4,5,6 --preset twist:0.7 --quiet").status, 0);
  RunResult r = runSffd("lattice --from " + base.string() + " -o " + refined.string() + " --refine 3,2,1");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("(8x8x6 control points, degree 2,2,2)"), std::string::npos) << r.err;
  r = runSffd("lattice --from " + refined.string() + " -o " + elevated.string() + " --elevate 1,0,3");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("(14x8x18 control points, degree 3,2,5)"), std::string::npos) << r.err;
  const auto want = deformed(dir, base);
  EXPECT_GT(largestDistance(want, readMesh(kSphere).positions), 0.1);   // the twist moved it
  EXPECT_LT(largestDistance(want, deformed(dir, refined)), 1e-12);
  EXPECT_LT(largestDistance(want, deformed(dir, elevated)), 1e-12);
  fs::remove_all(dir);
}

TEST(LatticeCommand, OneBoxLatticeAsPrmDeformsLikeItsJson) {
  fs::path dir = tempDir("lattice_prm_cli");
  const fs::path json = dir / "box.json", prm = dir / "box.prm", npy = dir / "box.npy";
  // One Bezier box an axis (counts = degree + 1), bent: what PyGeM's .prm holds.
  ASSERT_EQ(runSffd("lattice " + kSphere + " -o " + json.string() + " --counts 3,4,3 --degree 2,3,2 --preset bend:0.8 --quiet").status, 0);
  ASSERT_EQ(runSffd("lattice --from " + json.string() + " -o " + prm.string() + " --quiet").status, 0);
  EXPECT_LT(largestDistance(deformed(dir, json), deformed(dir, prm)), 1e-9);
  // .npy holds the control points only; read back with the mesh it belongs to they are the same.
  ASSERT_EQ(runSffd("lattice " + kSphere + " --from " + json.string() + " -o " + npy.string() + " --quiet").status, 0);
  EXPECT_EQ(slurp(npy).size(), 128u + 3 * 4 * 3 * 3 * 8);
  fs::remove_all(dir);
}

TEST(LatticeCommand, VtkHoldsTheControlNetForParaView) {
  fs::path dir = tempDir("lattice_vtk_cli");
  const fs::path vtk = dir / "net.vtk";
  ASSERT_EQ(runSffd("lattice " + kSphere + " -o " + vtk.string() + " --counts 2,3,4 --degree 1,1,1 --quiet").status, 0);
  std::istringstream in(slurp(vtk));
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(in, line)) lines.push_back(line);
  ASSERT_GE(lines.size(), 6u + 24 + 2 + 24);
  EXPECT_EQ(lines[0], "# vtk DataFile Version 3.0");
  EXPECT_EQ(lines[2], "ASCII");
  EXPECT_EQ(lines[3], "DATASET STRUCTURED_GRID");
  EXPECT_EQ(lines[4], "DIMENSIONS 2 3 4");
  EXPECT_EQ(lines[5], "POINTS 24 double");
  // VTK's order: x fastest. The identity lattice's first two points differ in x only, and its
  // displacements are all zero.
  double x0, y0, z0, x1, y1, z1;
  std::istringstream(lines[6]) >> x0 >> y0 >> z0;
  std::istringstream(lines[7]) >> x1 >> y1 >> z1;
  EXPECT_LT(x0, x1);
  EXPECT_EQ(y0, y1);
  EXPECT_EQ(z0, z1);
  EXPECT_EQ(lines[30], "POINT_DATA 24");
  EXPECT_EQ(lines[31], "VECTORS displacement double");
  for (size_t i = 32; i < 56; ++i) EXPECT_EQ(lines[i], "0 0 0") << i;
  fs::remove_all(dir);
}

TEST(LatticeCommand, RefusesWithOneLineAndWritesNothing) {
  fs::path dir = tempDir("lattice_refused_cli");
  const fs::path base = dir / "base.json";
  ASSERT_EQ(runSffd("lattice " + kSphere + " -o " + base.string() + " --quiet").status, 0);
  const std::string npy = std::string(SFFD_TEST_DATA) + "/lattices/sphere_twist.npy";
  struct Case {
    std::string args, message;
  } cases[] = {
      {"--from " + base.string() + " -o " + (dir / "x.txt").string(), "expected .json, .npy, .prm or .vtk"},
      {"--from " + base.string() + " -o " + (dir / "x.json").string() + " --elevate 4", "degrees stay within 1..5"},
      {"--from " + base.string() + " -o " + (dir / "x.json").string() + " --refine 0", "option --refine needs one integer 1..64 for all axes or three, not '0'"},
      {"--from " + base.string() + " -o " + (dir / "x.json").string() + " --refine 2,2", "one integer for all axes or three"},
      {"--from " + base.string() + " -o " + (dir / "x.json").string() + " --counts 3", "with --from the lattice's own is kept"},
      // Ignored before: the lattice's own degree kept, nothing normalised.
      {"--from " + base.string() + " -o " + (dir / "x.json").string() + " --degree 3", "keeps its own (--elevate raises it)"},
      {"--from " + base.string() + " -o " + (dir / "x.json").string() + " --normalize 0.5", "none is given"},
      {"--from " + base.string() + " -o " + (dir / "x.prm").string(), "one Bezier box"},
      {"--from " + npy + " -o " + (dir / "x.json").string(), "give the MESH it belongs to"},
      {"-o " + (dir / "x.json").string(), "needs a MESH"},
      {"--from " + base.string() + " -o " + base.string(), "base.json"},
  };
  for (const Case& c : cases) {
    RunResult r = runSffd("lattice " + c.args);
    EXPECT_EQ(r.status, 2) << c.args;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  // A refinement past SFFD_MEMORY_LIMIT: refused before the net is made (1.9 GB peak before, for 240^3 points).
  RunResult big = runSffd("lattice --from " + base.string() + " -o " + (dir / "x.json").string() + " --refine 64",
                          "SFFD_MEMORY_LIMIT=64M");
  EXPECT_EQ(big.status, 2);
  EXPECT_NE(big.err.find("more than the limit of 64.00 MiB (SFFD_MEMORY_LIMIT); refine or elevate less"), std::string::npos) << big.err;
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sffd::test
