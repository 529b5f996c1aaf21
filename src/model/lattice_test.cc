// Properties of the lattice model and its evaluation (METHOD.md 1, 3.5, 6), checked against an
// independent Cox-de Boor evaluation written here from the textbook definition.
#include <gtest/gtest.h>

#include <random>

#include <sffd/error.h>

#include "model/lattice.h"
#include "kernels/common/lattice_eval.h"
#include "model/lattice_pack.h"
#include "model/lattice_test_support.h"

using namespace sffd;

namespace {

// N_{i,p}(t) by the Cox-de Boor recursion, right end of the domain included in the last span.
double basis(const std::vector<double>& U, int i, int p, double t, double hi) {
  if (p == 0) {
    if (U[i] <= t && t < U[i + 1]) return 1;
    // the last non-empty span owns the domain's right end
    if (t == hi && U[i] < U[i + 1] && U[i + 1] == hi) return 1;
    return 0;
  }
  double a = 0, b = 0;
  if (U[i + p] > U[i]) a = (t - U[i]) / (U[i + p] - U[i]) * basis(U, i, p - 1, t, hi);
  if (U[i + p + 1] > U[i + 1]) b = (U[i + p + 1] - t) / (U[i + p + 1] - U[i + 1]) * basis(U, i + 1, p - 1, t, hi);
  return a + b;
}

glm::dvec3 deBoor(const Lattice& L, glm::dvec3 x) {
  glm::dvec3 p = L.frameLinear * x + L.frameOffset;
  glm::dvec3 r(0);
  for (int i = 0; i < L.counts[0]; ++i) {
    double bu = basis(L.knots[0], i, L.degree[0], p.x, L.domainHi(0));
    if (bu == 0) continue;
    for (int j = 0; j < L.counts[1]; ++j) {
      double bv = basis(L.knots[1], j, L.degree[1], p.y, L.domainHi(1));
      if (bv == 0) continue;
      for (int k = 0; k < L.counts[2]; ++k)
        r += bu * bv * basis(L.knots[2], k, L.degree[2], p.z, L.domainHi(2)) * L.controlPoints[L.index(i, j, k)];
    }
  }
  return r;
}

glm::dvec3 toGlm(RVec3<double> v) { return {v.x, v.y, v.z}; }
RVec3<double> fromGlm(glm::dvec3 v) { return {v.x, v.y, v.z}; }

using test::Evaluated;
using test::randomLattice;

}  // namespace

TEST(Lattice, KnotsAndGreville) {
  auto k = clampedUniformKnots(5, 2, -1, 1);
  ASSERT_EQ(k.size(), 8u);
  auto xi = grevilleAbscissae(k, 2);
  std::vector<double> want = {-1, -2.0 / 3, 0, 2.0 / 3, 1};   // METHOD.md 1.1
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(xi[i], want[i], 1e-15);
}

TEST(Lattice, BoxFormMatchesDeBoorForEveryDegree) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(-1, 1.5), uy(-2, 1), uz(-0.5, 0.5);
  for (int d = 1; d <= 5; ++d)
    for (bool nonUniform : {false, true}) {
      std::array<int, 3> degree{d, std::max(1, d - 1), std::min(5, d + 1)};
      std::array<int, 3> counts{degree[0] + 3, degree[1] + 1, degree[2] + 2};
      Lattice L = randomLattice(rng, degree, counts, nonUniform);
      Evaluated E(L);
      for (int t = 0; t < 50; ++t) {
        glm::dvec3 x(ux(rng), uy(rng), uz(rng));
        glm::dvec3 got = toGlm(E.eval.evaluate(fromGlm(x)).value), want = deBoor(L, x);
        EXPECT_NEAR(glm::length(got - want), 0, 1e-12) << "degree " << d << " nonuniform " << nonUniform;
      }
    }
}

TEST(Lattice, RepeatedInteriorKnotIsExtracted) {
  // A double interior knot in a degree-2 axis (C0 there): extraction must still match de Boor.
  Lattice L = makeIdentityLattice({0, 0, 0}, {1, 1, 1}, {6, 3, 3}, {2, 2, 2});
  L.knots[0] = {0, 0, 0, 0.25, 0.5, 0.5, 1, 1, 1};
  setIdentityControlPoints(L);
  L.controlPoints[L.index(3, 1, 1)] += glm::dvec3(0.1, 0.2, -0.1);
  Evaluated E(L);
  EXPECT_EQ(E.packed.params.boxes.x, 3u);
  for (double x : {0.0, 0.1, 0.25, 0.4, 0.5, 0.6, 0.99, 1.0}) {
    glm::dvec3 p(x, 0.3, 0.7);
    EXPECT_NEAR(glm::length(toGlm(E.eval.evaluate(fromGlm(p)).value) - deBoor(L, p)), 0, 1e-13) << x;
  }
}

TEST(Lattice, IdentityLatticeLeavesPointsAndNormals) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int d = 1; d <= 5; ++d) {
    Lattice L = makeIdentityLattice({-1, -1, -1}, {1, 1, 1}, {d + 2, d + 1, d + 3}, {d, d, d});
    Evaluated E(L);
    for (int t = 0; t < 40; ++t) {
      glm::dvec3 x(u(rng), u(rng), u(rng));
      glm::dvec3 n = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
      auto S = E.eval.evaluate(fromGlm(x));
      EXPECT_NEAR(glm::length(toGlm(S.value) - x), 0, 1e-13);
      glm::dvec3 m = toGlm(snormalize(E.eval.cofactorNormal(S, fromGlm(n))));
      EXPECT_NEAR(glm::length(m - n), 0, 1e-13);
    }
  }
}

TEST(Lattice, AffineLatticeGivesThatAffineMap) {
  glm::dmat3 M(1.2, 0.3, -0.1, 0.2, 0.8, 0.4, -0.3, 0.1, 1.5);
  glm::dvec3 t(0.5, -1, 2);
  Lattice L = makeIdentityLattice({-1, -1, -1}, {1, 1, 1}, {5, 4, 6}, {2, 3, 1});
  for (auto& p : L.controlPoints) p = M * p + t;
  Evaluated E(L);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  glm::dmat3 C = cofactor(M);
  for (int i = 0; i < 50; ++i) {
    glm::dvec3 x(u(rng), u(rng), u(rng)), n = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
    auto S = E.eval.evaluate(fromGlm(x));
    EXPECT_NEAR(glm::length(toGlm(S.value) - (M * x + t)), 0, 1e-13);
    glm::dvec3 want = glm::normalize(C * n);
    EXPECT_NEAR(glm::length(toGlm(snormalize(E.eval.cofactorNormal(S, fromGlm(n)))) - want), 0, 1e-13);
  }
}

TEST(Lattice, CornerControlPointsAreInterpolated) {
  std::mt19937 rng(11);
  Lattice L = randomLattice(rng, {2, 3, 2}, {5, 6, 4}, true);
  Evaluated E(L);
  for (int c = 0; c < 8; ++c) {
    int i = (c & 4) ? L.counts[0] - 1 : 0, j = (c & 2) ? L.counts[1] - 1 : 0, k = (c & 1) ? L.counts[2] - 1 : 0;
    glm::dvec3 x(L.knots[0][(c & 4) ? L.counts[0] : L.degree[0]], L.knots[1][(c & 2) ? L.counts[1] : L.degree[1]],
                 L.knots[2][(c & 1) ? L.counts[2] : L.degree[2]]);
    EXPECT_NEAR(glm::length(toGlm(E.eval.evaluate(fromGlm(x)).value) - L.controlPoints[L.index(i, j, k)]), 0, 1e-13);
  }
}

TEST(Lattice, Cgp3SederbergParryValue) {
  // The value of github.com/muhummadPatel/cgp3 test/test_ffd.cpp: 3x3x3 Bernstein lattice on [-10,10]^3.
  Lattice L = makeIdentityLattice({-10, -10, -10}, {10, 10, 10}, {3, 3, 3}, {2, 2, 2});
  EXPECT_NEAR(glm::length(L.controlPoints[0] - glm::dvec3(-10)), 0, 1e-15);
  Evaluated E0(L);
  EXPECT_NEAR(glm::length(toGlm(E0.eval.evaluate({1, 1, 1}).value) - glm::dvec3(1)), 0, 1e-13);
  L.controlPoints[0] += glm::dvec3(15);
  Evaluated E(L);
  glm::dvec3 r = toGlm(E.eval.evaluate({1, 1, 1}).value);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(r[a], 1.124556484375, 1e-12);
}

TEST(Lattice, StrictFloatEvaluationTracksDouble) {
  std::mt19937 rng(13);
  Lattice L = randomLattice(rng, {2, 2, 2}, {5, 5, 5}, false);
  PackedLattice P = packLattice(L);
  std::vector<float> ff = convertReals<float>(P.frame), fc = convertReals<float>(P.coeffs);
  LatticeEvaluator<float> ef(P.params, ff, fc);
  Evaluated E(L);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int i = 0; i < 100; ++i) {
    glm::dvec3 x(u(rng), u(rng), u(rng));
    auto sf = ef.evaluate({float(x.x), float(x.y), float(x.z)});
    auto sd = E.eval.evaluate(fromGlm(x));
    EXPECT_NEAR(sf.value.x, sd.value.x, 2e-6);
    EXPECT_NEAR(sf.value.y, sd.value.y, 2e-6);
    EXPECT_NEAR(sf.value.z, sd.value.z, 2e-6);
  }
}

TEST(Lattice, ValidationRefusesBadLattices) {
  Lattice L = makeIdentityLattice({0, 0, 0}, {1, 1, 1}, {4, 4, 4}, {2, 2, 2});
  EXPECT_NO_THROW(validateLattice(L, "x"));
  Lattice bad = L;
  bad.degree[1] = 4;
  EXPECT_THROW(validateLattice(bad, "x"), std::exception);
  bad = L;
  bad.knots[2][3] = -1;
  EXPECT_THROW(validateLattice(bad, "x"), std::exception);
  bad = L;
  bad.knots[0].pop_back();
  EXPECT_THROW(validateLattice(bad, "x"), std::exception);
  bad = L;
  bad.controlPoints[5].x = NAN;
  EXPECT_THROW(validateLattice(bad, "x"), std::exception);
  // A box of no size is refused where it is made.
  EXPECT_THROW(makeIdentityLattice({0, 0, 0}, {0, 1, 1}, {4, 4, 4}, {2, 2, 2}), Error);
}

// fitLattice says when it cannot make a box (it returned lattices of infinite or NaN knots, or of no size,
// which `sffd lattice` reported as a fault of the file it was writing); a mesh at one point far from the
// origin gets one (its 1e-12 box was lost in the rounding at 1e6).
// The limits of include/sffd/lattice.h hold for every way of making a lattice: refused before the control
// points are allocated (makeIdentityLattice, hence fitLattice) or when checked (validateLattice).
TEST(Lattice, CountsPastTheLimitsAreRefused) {
  for (const std::array<int, 3> counts : {std::array<int, 3>{300, 300, 300}, {4096, 4096, 4096}, {5000, 3, 3}, {0, 3, 3}}) {
    try {
      makeIdentityLattice(glm::dvec3(0), glm::dvec3(1), counts, {2, 2, 2});
      ADD_FAILURE() << "made a lattice of " << counts[0] << "x" << counts[1] << "x" << counts[2];
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Input) << e.what();
    }
  }
  Lattice L = makeIdentityLattice(glm::dvec3(0), glm::dvec3(1), {256, 256, 256}, {2, 2, 2});   // exactly 2^24
  EXPECT_NO_THROW(validateLattice(L, "L"));
  L.counts[2] = 257;   // as a hand-edited lattice could claim
  L.knots[2] = clampedUniformKnots(257, 2, 0, 1);
  L.controlPoints.resize(L.pointCount());
  EXPECT_THROW(validateLattice(L, "L"), Error);
}

TEST(Lattice, FittedBoxIsValidOrRefused) {
  Mesh point;
  point.positions.assign(3, glm::dvec3(1e6, -1e6, 1e6));
  const Lattice L = fitLattice(point);
  EXPECT_NO_THROW(validateLattice(L, "x"));
  for (int a = 0; a < 3; ++a) {
    EXPECT_LT(L.domainLo(a), point.positions[0][a]);
    EXPECT_GT(L.domainHi(a), point.positions[0][a]);
  }
  Mesh flat;
  flat.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_NO_THROW(fitLattice(flat));
  // A tiny mesh gets a box of its own size and margin, as at any other size (it got 1e-12).
  Mesh tiny = flat;
  for (glm::dvec3& p : tiny.positions) p *= 1e-20;
  const Lattice T = fitLattice(tiny);
  EXPECT_DOUBLE_EQ(T.domainHi(0) - T.domainLo(0), 1.01e-20);
  Mesh nan = flat;
  nan.positions[0].x = NAN;   // the first vertex starts the box
  for (const auto& [mesh, margin] : {std::pair{&flat, 0.0}, {&flat, 1e308}, {&nan, 0.005}}) {
    try {
      fitLattice(*mesh, {5, 5, 5}, {2, 2, 2}, margin);
      ADD_FAILURE() << "margin " << margin;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Input);
      EXPECT_EQ(std::string(e.what()).rfind("fitLattice: ", 0), 0u) << e.what();
    }
  }
}

// An audit (2026-12): a default-constructed Lattice (no knots, no control points) crashed
// applyLatticePreset and made setIdentityControlPoints throw std::length_error. Every public function that
// takes a lattice now says what is wrong with it, as validateLattice does.
TEST(Lattice, PublicFunctionsRefuseAnInvalidLatticeWithAnInputError) {
  auto expectInput = [](const char* what, auto&& f) {
    try {
      f();
      ADD_FAILURE() << what << ": nothing was thrown";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Input) << what << ": " << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << what << ": not an sffd::Error: " << e.what();
    }
  };
  Lattice none;   // counts 5x5x5, degree 2, nothing else
  expectInput("applyLatticePreset", [&] { applyLatticePreset(none, "twist", 0.5); });
  expectInput("setIdentityControlPoints", [&] { setIdentityControlPoints(none); });
  none.counts = {3, 3, 3};
  expectInput("setIdentityControlPoints 3x3x3", [&] { setIdentityControlPoints(none); });
  expectInput("refineLattice", [&] { refineLattice(none, {2, 2, 2}); });
  expectInput("elevateLattice", [&] { elevateLattice(none, {1, 1, 1}); });
  expectInput("writeLattice", [&] { writeLattice("never-written.json", none); });
  expectInput("makeIdentityLattice degree 0", [] { makeIdentityLattice(glm::dvec3(0), glm::dvec3(1), {3, 3, 3}, {0, 2, 2}); });
  expectInput("makeIdentityLattice degree 3 of 2 points", [] { makeIdentityLattice(glm::dvec3(0), glm::dvec3(1), {2, 3, 3}, {3, 2, 2}); });
  expectInput("makeIdentityLattice of no size", [] { makeIdentityLattice(glm::dvec3(0), glm::dvec3(0), {3, 3, 3}, {2, 2, 2}); });
  expectInput("clampedUniformKnots", [] { clampedUniformKnots(-1, 2, 0, 1); });
  expectInput("clampedUniformKnots huge", [] { clampedUniformKnots(2000000000, 2, 0, 1); });
  Lattice offset = makeIdentityLattice(glm::dvec3(0), glm::dvec3(1), {3, 3, 3}, {2, 2, 2});
  offset.frameOffset.y = NAN;
  expectInput("validateLattice NaN frame offset", [&] { validateLattice(offset, "lattice"); });
  // Made whole, the same lattice takes every call.
  none.knots = {clampedUniformKnots(3, 2, 0, 1), clampedUniformKnots(3, 2, 0, 1), clampedUniformKnots(3, 2, 0, 1)};
  setIdentityControlPoints(none);
  applyLatticePreset(none, "twist", 0.5);
  EXPECT_NO_THROW(validateLattice(none, "lattice"));
}
