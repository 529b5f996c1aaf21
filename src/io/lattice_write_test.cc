// Lattices written in the format the extension names (writeLattice): .prm and .npy read back to the
// same lattice under their readers' conventions; other extensions and lattices a format cannot hold
// are refused with nothing written.
#include <gtest/gtest.h>

#include <filesystem>

#include <sffd/error.h>

#include "io/lattice_io.h"
#include "tests/support/cli_runner.h"

namespace sffd {
namespace {

namespace fs = std::filesystem;

void expectSamePoints(const Lattice& a, const Lattice& b, double tol) {
  ASSERT_EQ(a.controlPoints.size(), b.controlPoints.size());
  for (size_t i = 0; i < a.controlPoints.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a.controlPoints[i][c], b.controlPoints[i][c], tol) << i;
}

TEST(LatticeWrite, PygemPrmReadsBackToTheSameLattice) {
  fs::path dir = test::tempDir("lattice_write_prm");
  // PyGeM's own case: a rotated 3x2x2 box with one moved point.
  Lattice L = readLattice(std::string(SFFD_TEST_DATA) + "/pygem/sphere_ffd/parameters_test_ffd_sphere.prm");
  writeLattice((dir / "again.prm").string(), L);
  Lattice R = readLattice((dir / "again.prm").string());
  EXPECT_EQ(R.counts, L.counts);
  EXPECT_EQ(R.degree, L.degree);
  EXPECT_EQ(R.outside, OutsideMode::Keep);
  expectSamePoints(L, R, 1e-9);
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(R.frameLinear[c][r], L.frameLinear[c][r], 1e-12);
  fs::remove_all(dir);
}

TEST(LatticeWrite, NpyHoldsTheControlPoints) {
  fs::path dir = test::tempDir("lattice_write_npy");
  Lattice L = makeIdentityLattice({-1, -2, -3}, {1, 2, 3}, {4, 5, 3}, {2, 2, 2});
  L.controlPoints[7] += glm::dvec3(0.1, -0.25, 1.0 / 3.0);
  writeLattice((dir / "l.npy").string(), L);
  LatticeReadOptions o;
  o.haveMeshBox = true;
  o.meshBoxLo = {-1, -2, -3};
  o.meshBoxHi = {1, 2, 3};
  Lattice R = readLattice((dir / "l.npy").string(), o);
  EXPECT_EQ(R.counts, L.counts);
  expectSamePoints(L, R, 0);   // float64: exact
  fs::remove_all(dir);
}

TEST(LatticeWrite, RefusesWhatTheFormatCannotHold) {
  fs::path dir = test::tempDir("lattice_write_refused");
  Lattice L = makeIdentityLattice({0, 0, 0}, {1, 1, 1}, {5, 5, 5}, {2, 2, 2});   // 3 knot boxes an axis
  for (const char* name : {"l.txt", "l", "l.vtk.gz", "l.vtu"}) {
    try {
      writeLattice((dir / name).string(), L);
      ADD_FAILURE() << name << " was written";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Input);
      EXPECT_NE(std::string(e.what()).find("expected .json, .npy, .prm or .vtk"), std::string::npos) << e.what();
    }
  }
  try {
    writeLattice((dir / "l.prm").string(), L);
    ADD_FAILURE() << "a 3-box lattice was written as .prm";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("one Bezier box"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_empty(dir));
  // One box on every axis (degree = counts - 1) is what .prm holds.
  Lattice B = makeIdentityLattice({0, 0, 0}, {2, 1, 1}, {3, 2, 4}, {2, 1, 3});
  B.controlPoints[5].z += 0.5;
  writeLattice((dir / "b.prm").string(), B);
  expectSamePoints(B, readLattice((dir / "b.prm").string()), 1e-12);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sffd
