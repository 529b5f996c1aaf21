// Warnings about what a lattice does to the mesh at hand: most of the mesh outside the lattice's box,
// knots that make the deformation discontinuous, and a mesh too small for float within the lattice's knot
// spans. One "sffd: warning:" line each, exit 0.
#include <gtest/gtest.h>

#include "tests/support/cli_runner.h"

namespace sffd::test {
namespace {

TEST(LatticeWarnings, MeshOutsideTheBoxAndDiscontinuousKnots) {
  fs::path dir = tempDir("lattice_warnings");
  writeBoxObj(dir / "box.obj", 0, 0, 0, 1);
  writeBoxObj(dir / "far.obj", 40, -25, 10, 1);
  const std::string box = (dir / "box.obj").string(), far = (dir / "far.obj").string();
  const std::string fitted = (dir / "fitted.json").string();
  ASSERT_EQ(runSffd("lattice " + box + " -o " + fitted + " --preset bend:0.3 --quiet").status, 0);

  // The lattice fits the mesh: nothing to say.
  RunResult clean = runSffd("deform " + box + " -l " + fitted + " --backend cpu -o " + (dir / "a.obj").string() + " --quiet");
  EXPECT_EQ(clean.status, 0) << clean.err;
  EXPECT_EQ(clean.err, "");

  // The same lattice on a mesh 40 units away: every vertex outside, extrapolated.
  RunResult outside = runSffd("deform " + far + " -l " + fitted + " --method classic --backend cpu -o " + (dir / "b.obj").string() + " --quiet");
  EXPECT_EQ(outside.status, 0) << outside.err;
  EXPECT_NE(outside.err.find("sffd: warning: 100% of the mesh's vertices lie outside the box of lattice " + fitted +
                             ": they follow the nearest knot box's polynomial"),
            std::string::npos)
      << outside.err;

  // A degree-1 lattice whose interior knot is doubled: the map jumps at u = 0.5.
  std::ofstream(dir / "jump.json") << R"({"format": "sffd-lattice", "version": 1, "degree": [1, 1, 1], "counts": [4, 2, 2],
    "box": {"min": [-1.5, -1.5, -1.5], "max": [1.5, 1.5, 1.5]},
    "knots": {"u": [-1.5, -1.5, 0, 0, 1.5, 1.5]}})";
  RunResult jump = runSffd("deform " + box + " -l " + (dir / "jump.json").string() + " --method classic --backend cpu -o " +
                           (dir / "c.obj").string() + " --quiet");
  EXPECT_EQ(jump.status, 0) << jump.err;
  EXPECT_NE(jump.err.find("the knot 0 of axis u is repeated 2 times, more than the degree 1"), std::string::npos) << jump.err;
  EXPECT_EQ(std::count(jump.err.begin(), jump.err.end(), '\n'), 1) << jump.err;
  fs::remove_all(dir);
}

// A box 2e-6 across in the middle of a lattice whose knot spans are 1 wide: float kernels evaluate from
// the distance to the knots, resolving about 6e-8: 3 % of the box, which came out faceted without a word.
TEST(LatticeWarnings, MeshTooSmallForFloatInTheKnotSpans) {
  fs::path dir = tempDir("lattice_warnings_small");
  writeBoxObj(dir / "unit.obj", 0, 0, 0, 1);
  writeBoxObj(dir / "tiny.obj", 0, 0, 0, 1e-6);
  const std::string unit = (dir / "unit.obj").string(), tiny = (dir / "tiny.obj").string();
  const std::string lattice = (dir / "l.json").string();
  ASSERT_EQ(runSffd("lattice " + unit + " -o " + lattice + " --counts 4 --degree 1 --margin 0.25 --preset twist:0.3 --quiet").status, 0);
  const std::string job = " -l " + lattice + " --backend cpu --tess 2 --quiet -o " + (dir / "o.obj").string();
  RunResult small = runSffd("deform " + tiny + job);
  EXPECT_EQ(small.status, 0) << small.err;
  EXPECT_EQ(small.err, "sffd: warning: the mesh is 2e-06 across, and the knot spans of lattice " + lattice +
                           " that hold it 1: float kernels resolve the result to about 6e-08, 3% of the mesh; use --precision double\n");
  for (const std::string& quiet : {"deform " + tiny + job + " --precision double", "deform " + unit + job, "deform " + tiny + job + " --method classic"}) {
    RunResult r = runSffd(quiet);
    EXPECT_EQ(r.status, 0) << quiet << r.err;
    EXPECT_EQ(r.err, "") << quiet;
  }
  fs::remove_all(dir);
}

// The same in double, 2e-15 inside spans 1 wide (2^-53 of them is 6 % of it); and a mesh 2e-40 of its
// lattice, whose edge length the clip kernels cannot take as a float (0 on a GPU, where it made every edge
// the table's most segments, and a NaN count on the CPU device, which failed with an internal error).
TEST(LatticeWarnings, MeshTooSmallForDoubleAndAnEdgeLengthBelowFloat) {
  fs::path dir = tempDir("lattice_warnings_double");
  writeBoxObj(dir / "unit.obj", 0, 0, 0, 1);
  writeBoxObj(dir / "tiny.obj", 0, 0, 0, 1e-15);
  writeBoxObj(dir / "tinier.obj", 0, 0, 0, 1e-40);
  const std::string lattice = (dir / "l.json").string();
  ASSERT_EQ(runSffd("lattice " + (dir / "unit.obj").string() + " -o " + lattice + " --counts 4 --degree 1 --margin 0.25 --quiet").status, 0);
  const std::string job = " -l " + lattice + " --backend cpu --tess 1 --quiet -o " + (dir / "o.obj").string();
  RunResult small = runSffd("deform " + (dir / "tiny.obj").string() + job + " --precision double");
  EXPECT_EQ(small.status, 0) << small.err;
  EXPECT_EQ(small.err, "sffd: warning: the mesh is 2e-15 across, and the knot spans of lattice " + lattice +
                           " that hold it 1: double kernels resolve the result to about 1.1e-16, 5.6% of the mesh; use a lattice "
                           "closer to the mesh's size\n");
  // In float the advice is the same: double would not resolve it either.
  RunResult floats = runSffd("deform " + (dir / "tiny.obj").string() + job);
  EXPECT_EQ(floats.status, 0) << floats.err;
  EXPECT_NE(floats.err.find("float kernels resolve the result to about 6e-08, 3e+07 times its size; use a lattice closer"), std::string::npos)
      << floats.err;
  fs::remove(dir / "o.obj");
  for (const char* precision : {"", " --precision double"}) {
    RunResult r = runSffd("deform " + (dir / "tinier.obj").string() + job + precision);
    EXPECT_EQ(r.status, 2) << precision << r.err;
    EXPECT_NE(r.err.find("below the smallest float (1.2e-38) that the clip kernels take it in"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "o.obj"));
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sffd::test
