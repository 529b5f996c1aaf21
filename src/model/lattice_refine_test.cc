// refineLattice and elevateLattice change the basis, never the volume: random lattices of every degree,
// uniform and non-uniform knots, evaluated inside and outside the box (extrapolation) before and after.
#include <gtest/gtest.h>

#include <random>

#include <sffd/error.h>

#include "model/lattice_test_support.h"

namespace sffd {
namespace {

using test::Evaluated;
using test::randomLattice;

// Largest distance between the two volumes at points inside the box (outside: up to a quarter of it
// beyond, where extrapolating a smaller knot box's polynomial further out magnifies rounding, so the
// tests allow more there).
double largestDifference(const Lattice& a, const Lattice& b, std::mt19937& rng, bool outside = false) {
  Evaluated ea(a), eb(b);
  const double m = outside ? 0.25 : 0.0;
  std::uniform_real_distribution<double> x(-1 - 2.5 * m, 1.5 + 2.5 * m), y(-2 - 3 * m, 1 + 3 * m), z(-0.5 - m, 0.5 + m);
  double worst = 0;
  for (int n = 0; n < 400; ++n) {
    glm::dvec3 p(x(rng), y(rng), z(rng));
    if (n < 8) p = {n & 1 ? 1.5 : -1.0, n & 2 ? 1.0 : -2.0, n & 4 ? 0.5 : -0.5};   // the box's corners
    worst = std::max(worst, glm::length(ea.at(p) - eb.at(p)));
  }
  return worst;
}

TEST(LatticeRefine, KnotInsertionKeepsTheVolume) {
  std::mt19937 rng(7);
  for (int p = 1; p <= 5; ++p)
    for (bool nonUniform : {false, true}) {
      Lattice L = randomLattice(rng, {p, p == 5 ? 1 : p + 1, 2}, {p + 3, p + 4, 4}, nonUniform);
      Lattice R = refineLattice(L, {2, 3, 1});
      const int spans0 = L.counts[0] - L.degree[0], spans1 = L.counts[1] - L.degree[1];
      EXPECT_EQ(R.counts[0], L.counts[0] + spans0);
      EXPECT_EQ(R.counts[1], L.counts[1] + 2 * spans1);
      EXPECT_EQ(R.counts[2], L.counts[2]);
      EXPECT_EQ(R.degree, L.degree);
      EXPECT_LT(largestDifference(L, R, rng), 1e-12) << "degree " << p << (nonUniform ? " non-uniform" : "");
      EXPECT_LT(largestDifference(L, R, rng, true), 1e-9) << "degree " << p << (nonUniform ? " non-uniform" : "");
    }
}

TEST(LatticeRefine, DegreeElevationKeepsTheVolume) {
  std::mt19937 rng(11);
  for (int p = 1; p <= 4; ++p)
    for (bool nonUniform : {false, true}) {
      Lattice L = randomLattice(rng, {p, 1, 2}, {p + 3, 3, 5}, nonUniform);
      Lattice E = elevateLattice(L, {1, 5 - 1, 0});
      EXPECT_EQ(E.degree, (std::array<int, 3>{p + 1, 5, 2}));
      // Each of the spans adds one control point a degree raised.
      EXPECT_EQ(E.counts[0], L.counts[0] + (L.counts[0] - L.degree[0]));
      EXPECT_EQ(E.counts[1], L.counts[1] + 4 * (L.counts[1] - L.degree[1]));
      EXPECT_EQ(E.counts[2], L.counts[2]);
      EXPECT_LT(largestDifference(L, E, rng), 1e-12) << "degree " << p << (nonUniform ? " non-uniform" : "");
      EXPECT_LT(largestDifference(L, E, rng, true), 1e-9) << "degree " << p << (nonUniform ? " non-uniform" : "");
    }
}

TEST(LatticeRefine, RepeatedKnotsKeepTheirContinuity) {
  std::mt19937 rng(3);
  Lattice L = randomLattice(rng, {3, 2, 2}, {7, 4, 4}, false);
  L.knots[0][5] = L.knots[0][4];   // a double interior knot: C1 there
  Lattice E = elevateLattice(L, {2, 0, 0});
  EXPECT_EQ(std::count(E.knots[0].begin(), E.knots[0].end(), L.knots[0][4]), 4);
  EXPECT_LT(largestDifference(L, E, rng), 1e-12);
  EXPECT_LT(largestDifference(L, refineLattice(E, {3, 2, 2}), rng), 1e-12);
}

TEST(LatticeRefine, RefusesWhatItCannotDoExactly) {
  std::mt19937 rng(5);
  Lattice L = randomLattice(rng, {2, 2, 2}, {5, 5, 5}, false);
  EXPECT_THROW(elevateLattice(L, {4, 0, 0}), Error);   // degree 6
  EXPECT_THROW(refineLattice(L, {0, 1, 1}), Error);
  EXPECT_THROW(refineLattice(L, {65, 1, 1}), Error);
  Lattice D = randomLattice(rng, {2, 2, 2}, {7, 5, 5}, false);
  D.knots[0][3] = D.knots[0][5] = D.knots[0][4];   // multiplicity 3 > degree 2: discontinuous
  try {
    elevateLattice(D, {1, 0, 0}, "d.json");
    ADD_FAILURE() << "a discontinuous lattice was elevated";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input);
    EXPECT_NE(std::string(e.what()).find("d.json: knot u"), std::string::npos) << e.what();
  }
  // Knot insertion stays exact there.
  EXPECT_LT(largestDifference(D, refineLattice(D, {2, 1, 1}), rng), 1e-12);
}

// The new control net is checked against the memory limit before it is made (it was bounded by the 2^24
// points of kMaxLatticeControlPoints only: about 1.9 GB for `sffd lattice --refine`): 5^3 points refined
// to 17^3 take the caller's net and, at the last axis, 17x17x5 and 17^3 points at once.
TEST(LatticeRefine, TheNewNetIsCheckedAgainstTheMemoryLimit) {
  std::mt19937 rng(7);
  const Lattice L = randomLattice(rng, {2, 2, 2}, {5, 5, 5}, false);
  const uint64_t need = (125 + 17 * 17 * 5 + 17 * 17 * 17) * sizeof(glm::dvec3);
  EXPECT_EQ(refineLattice(L, {5, 5, 5}, "l.json", need).counts, (std::array<int, 3>{17, 17, 17}));
  try {
    refineLattice(L, {5, 5, 5}, "l.json", need - 1);
    ADD_FAILURE() << "refined past the limit";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input);
    EXPECT_NE(std::string(e.what()).find("l.json: the lattice of 4913 control points needs about"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("(the memoryLimit of refineLattice or elevateLattice)"), std::string::npos) << e.what();
  }
  EXPECT_THROW(elevateLattice(L, {3, 3, 3}, "l.json", 1024), Error);
}

}  // namespace
}  // namespace sffd
