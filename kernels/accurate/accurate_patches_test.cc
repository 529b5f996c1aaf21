// Accurate FFD (accurate_patches.h, METHOD.md 2): the interpolation matrix and its inverse, the patches
// against the blossom product (Method B) and against the lattice itself, identity and affine lattices
// reproduced exactly, bit-identical shared boundaries (closed output) and the float twin.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include "backends/backend_test_support.h"
#include "kernels/accurate/accurate_patches.h"
#include <sffd/error.h>
#include "kernels/clip/knot_box_clip.h"
#include "kernels/common/lattice_eval.h"
#include "model/lattice_pack.h"
#include "model/mesh.h"
#include "model/mesh_topology.h"
#include "tests/support/test_lattices.h"

using namespace sffd;

namespace {

const std::string kData = SFFD_TEST_DATA;

int linearIndex(int d, int i, int k) { return (d - i) * (d - i + 1) / 2 + k; }

// ---- Method B: the blossom product (DeRose 1988; METHOD.md 2.2), for a single Bezier box ----
using Tri = std::vector<double>;   // triangular Bernstein coefficients of one degree, linear index order

// Coefficients (degree p) of B^p_r(alpha . lambda): the blossom of B^p_r at {alpha0 x mu0, alpha1 x mu1, alpha2 x mu2}.
Tri axisFactor(int p, int r, const glm::dvec3& alpha) {
  Tri out(triangleControlPoints(p));
  for (int idx = 0; idx < int(out.size()); ++idx) {
    int mu[3];
    triangleMultiIndex(p, idx, mu[0], mu[1], mu[2]);
    // Coefficient of z^r in prod_i ((1 - x_i) + x_i z).
    std::vector<double> poly(p + 1, 0.0);
    poly[0] = 1;
    int deg = 0;
    for (int c = 0; c < 3; ++c)
      for (int e = 0; e < mu[c]; ++e) {
        double x = alpha[c];
        for (int q = deg + 1; q >= 0; --q) poly[q] = (q <= deg ? poly[q] * (1 - x) : 0.0) + (q > 0 ? poly[q - 1] * x : 0.0);
        ++deg;
      }
    out[idx] = poly[r];
  }
  return out;
}

double multinomial(int m, int a, int b, int c) { return std::tgamma(m + 1.0) / (std::tgamma(a + 1.0) * std::tgamma(b + 1.0) * std::tgamma(c + 1.0)); }

Tri multiply(const Tri& f, int m, const Tri& g, int k) {
  Tri out(triangleControlPoints(m + k), 0.0);
  for (int a = 0; a < int(f.size()); ++a) {
    int mu[3];
    triangleMultiIndex(m, a, mu[0], mu[1], mu[2]);
    for (int b = 0; b < int(g.size()); ++b) {
      int nu[3];
      triangleMultiIndex(k, b, nu[0], nu[1], nu[2]);
      int ka[3] = {mu[0] + nu[0], mu[1] + nu[1], mu[2] + nu[2]};
      double w = multinomial(m, mu[0], mu[1], mu[2]) * multinomial(k, nu[0], nu[1], nu[2]) / multinomial(m + k, ka[0], ka[1], ka[2]);
      out[linearIndex(m + k, ka[0], ka[2])] += w * f[a] * g[b];
    }
  }
  return out;
}

double bern1(int p, int r, double x) { return std::tgamma(p + 1.0) / (std::tgamma(r + 1.0) * std::tgamma(p - r + 1.0)) * std::pow(x, r) * std::pow(1 - x, p - r); }

struct BezierBox {
  std::array<int, 3> deg;
  std::vector<glm::dvec3> b;   // (p*(nv+1)+q)*(nw+1)+r
  glm::dvec3 eval(const glm::dvec3& s) const {
    glm::dvec3 v(0.0);
    for (int p = 0; p <= deg[0]; ++p)
      for (int q = 0; q <= deg[1]; ++q)
        for (int r = 0; r <= deg[2]; ++r)
          v += b[(p * (deg[1] + 1) + q) * (deg[2] + 1) + r] * (bern1(deg[0], p, s.x) * bern1(deg[1], q, s.y) * bern1(deg[2], r, s.z));
    return v;
  }
};

// Angle between two unit vectors, accurate also near 0 (acos is not).
double angleBetween(const glm::dvec3& a, const glm::dvec3& b) { return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)); }

// ---- meshes and lattices ----
Mesh load(const std::string& name) { return readMesh(kData + "/" + name); }

using sffd::test::boxLattice;
using sffd::test::perturb;

struct AccRun {
  AccurateJob job;
  AccurateOutput out;
  PatchVertices pv;
};

AccRun runAccurateCpu(const Mesh& mesh, const Lattice& L, KernelVariant v, int level = 10) {
  AccRun r;
  r.job = makeAccurateJob(mesh, L, clipAgainstKnotBoxes(mesh, L), level);
  r.out = accurateFfd(sffd::testing::cpuBackend(), r.job, packLattice(L), v);
  r.pv = accuratePatchVertices(r.job, r.out);
  return r;
}

glm::dvec3 flatPoint(const Mesh& m, uint32_t parent, const double* lam) {
  const auto& t = m.triangles[parent];
  return lam[0] * m.positions[t[0]] + lam[1] * m.positions[t[1]] + lam[2] * m.positions[t[2]];
}

glm::dvec3 faceNormal(const Mesh& m, uint32_t parent) {
  const auto& t = m.triangles[parent];
  return glm::normalize(glm::cross(m.positions[t[1]] - m.positions[t[0]], m.positions[t[2]] - m.positions[t[0]]));
}

// Largest distance between each tessellation vertex and the exact FFD of its pre-image, and largest
// angle (degrees) between its normal and cof(J) n_face of its parent.
void exactness(const Mesh& mesh, const Lattice& L, const PatchVertices& pv, double& maxDist, double& maxAngle) {
  PackedLattice P = packLattice(L);
  LatticeEvaluator<double> eval(P.params, P.frame, P.coeffs);
  maxDist = maxAngle = 0;
  const int nv = tessVertexCount(pv.level);
  for (size_t p = 0; p < pv.patchCount(); ++p) {
    glm::dvec3 nf = faceNormal(mesh, pv.parent[p]);
    for (int v = 0; v < nv; ++v) {
      size_t g = p * nv + v;
      glm::dvec3 x = flatPoint(mesh, pv.parent[p], &pv.lamParent[3 * g]);
      LatticeSampleT<double> S = eval.evaluate(RVec3<double>::from(x));
      glm::dvec3 ref = S.value.glm(), refN = glm::normalize(eval.cofactorNormal(S, RVec3<double>::from(nf)).glm());
      glm::dvec3 got(pv.position[3 * g], pv.position[3 * g + 1], pv.position[3 * g + 2]);
      glm::dvec3 gotN(pv.normal[3 * g], pv.normal[3 * g + 1], pv.normal[3 * g + 2]);
      maxDist = std::max(maxDist, glm::length(got - ref));
      maxAngle = std::max(maxAngle, angleBetween(gotN, refN) * 180 / M_PI);
    }
  }
}

// Every edge of the welded output (by weldId) is shared by exactly two triangles, in opposite directions.
void expectClosed(const Mesh& out) {
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (const auto& t : out.triangles)
    for (int e = 0; e < 3; ++e) ++directed[{out.weldId[t[e]], out.weldId[t[(e + 1) % 3]]}];
  size_t bad = 0;
  for (const auto& [e, c] : directed)
    if (c != 1 || directed.count({e.second, e.first}) == 0 || directed.at({e.second, e.first}) != 1) ++bad;
  EXPECT_EQ(bad, 0u) << "edges without exactly one opposite partner";
}

}  // namespace

TEST(AccurateFfd, MultiIndexOrder) {
  // METHOD.md 0: 0:300 1:210 2:201 3:120 4:111 5:102 6:030 7:021 8:012 9:003.
  const char* expected[] = {"300", "210", "201", "120", "111", "102", "030", "021", "012", "003"};
  for (int idx = 0; idx < 10; ++idx) {
    int i, j, k;
    triangleMultiIndex(3, idx, i, j, k);
    EXPECT_EQ(std::to_string(i) + std::to_string(j) + std::to_string(k), expected[idx]);
    EXPECT_EQ(linearIndex(3, i, k), idx);
  }
}

TEST(AccurateFfd, InverseMatrixIsTheInverseForEveryDegree) {
  for (int n = 1; n <= SFFD_ACC_MAX_DEGREE; ++n) {
    const int m = triangleControlPoints(n);
    std::vector<double> A = interpolationMatrix(n);
    const std::vector<double>& X = interpolationInverse(n);
    double worst = 0, normA = 0, normX = 0;
    for (int r = 0; r < m; ++r) {
      double ra = 0, rx = 0;
      for (int c = 0; c < m; ++c) {
        ra += std::abs(A[size_t(r) * m + c]);
        rx += std::abs(X[size_t(r) * m + c]);
        double s = 0;
        for (int k = 0; k < m; ++k) s += A[size_t(r) * m + k] * X[size_t(k) * m + c];
        worst = std::max(worst, std::abs(s - (r == c ? 1.0 : 0.0)));
      }
      normA = std::max(normA, ra);
      normX = std::max(normX, rx);
    }
    std::printf("n=%2d m=%3d cond_inf(A_n)=%.3g |A_n^-1|_inf=%.3g max|A A^-1 - I|=%.2g\n", n, m, normA * normX, normX, worst);
    EXPECT_LT(worst, 1e-15 * normA * normX * m) << "n = " << n;
    EXPECT_LT(worst, 1e-9) << "n = " << n;
  }
}

TEST(AccurateFfd, InterpolationEqualsBlossomProduct) {
  // Method A (A_n^{-1} S) against Method B (products of blossoms) for a random Bezier box and a random
  // triangle inside it, for several degree triples up to the largest (5,5,5): n = 15.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1), s01(0, 1);
  for (std::array<int, 3> deg : {std::array{2, 2, 1}, std::array{2, 2, 2}, std::array{3, 3, 3}, std::array{4, 3, 5}, std::array{5, 5, 5}}) {
    const int n = deg[0] + deg[1] + deg[2], m = triangleControlPoints(n);
    BezierBox box{deg, {}};
    for (int i = 0; i < (deg[0] + 1) * (deg[1] + 1) * (deg[2] + 1); ++i) box.b.push_back({u(rng), u(rng), u(rng)});
    glm::dvec3 a(s01(rng), s01(rng), s01(rng)), b(s01(rng), s01(rng), s01(rng)), c(s01(rng), s01(rng), s01(rng));
    // Method A.
    const std::vector<double>& X = interpolationInverse(n);
    std::vector<glm::dvec3> S(m), PA(m, glm::dvec3(0.0));
    for (int l = 0; l < m; ++l) {
      int i, j, k;
      triangleMultiIndex(n, l, i, j, k);
      S[l] = box.eval((double(i) * a + double(j) * b + double(k) * c) / double(n));
    }
    for (int k = 0; k < m; ++k)
      for (int l = 0; l < m; ++l) PA[k] += X[size_t(k) * m + l] * S[l];
    // Method B.
    std::vector<glm::dvec3> PB(m, glm::dvec3(0.0));
    glm::dvec3 au(a.x, b.x, c.x), av(a.y, b.y, c.y), aw(a.z, b.z, c.z);
    for (int p = 0; p <= deg[0]; ++p)
      for (int q = 0; q <= deg[1]; ++q)
        for (int r = 0; r <= deg[2]; ++r) {
          Tri f = multiply(multiply(axisFactor(deg[0], p, au), deg[0], axisFactor(deg[1], q, av), deg[1]), deg[0] + deg[1],
                           axisFactor(deg[2], r, aw), deg[2]);
          for (int k = 0; k < m; ++k) PB[k] += f[k] * box.b[(p * (deg[1] + 1) + q) * (deg[2] + 1) + r];
        }
    double worst = 0, scale = 0;
    for (int k = 0; k < m; ++k) {
      worst = std::max(worst, glm::length(PA[k] - PB[k]));
      scale = std::max(scale, glm::length(PB[k]));
    }
    std::printf("degree (%d,%d,%d) n=%d: max |P_interp - P_blossom| = %.3g (control points up to %.3g)\n", deg[0], deg[1], deg[2], n, worst, scale);
    EXPECT_LT(worst, n <= 9 ? 1e-12 : 1e-9) << "n = " << n;
    // And the patch evaluates to R(T(lambda)) at a random point.
    glm::dvec3 lam(0.2, 0.3, 0.5), val(0.0);
    for (int k = 0; k < m; ++k) {
      int i, j, kk;
      triangleMultiIndex(n, k, i, j, kk);
      val += triangleBernstein(n, i, j, kk, lam) * PB[k];
    }
    EXPECT_LT(glm::length(val - box.eval(lam.x * a + lam.y * b + lam.z * c)), 1e-12);
  }
}

TEST(AccurateFfd, TessellationBasisSumsToOne) {
  for (int n : {3, 6, 15})
    for (int L : {1, 10, 64}) {
      std::vector<double> B = tessellationBasis(n, L);
      const int nb = triangleControlPoints(n);
      ASSERT_EQ(B.size(), size_t(tessVertexCount(L)) * nb);
      for (int v = 0; v < tessVertexCount(L); ++v) {
        double s = 0;
        for (int k = 0; k < nb; ++k) s += B[size_t(v) * nb + k];
        EXPECT_NEAR(s, 1.0, 1e-14);
      }
    }
}

TEST(AccurateFfd, IdentityLatticeReproducesTheFlatMesh) {
  for (const char* file : {"cube2.obj", "sphere.obj"}) {
    SCOPED_TRACE(file);
    Mesh mesh = load(file);
    Lattice L = boxLattice(mesh, {5, 5, 5}, {2, 2, 2});
    AccRun r = runAccurateCpu(mesh, L, {false, true});
    ASSERT_GT(r.pv.patchCount(), mesh.triangles.size());   // the knot planes cut triangles
    double worstPos = 0, worstNrm = 0;
    const int nv = tessVertexCount(10);
    for (size_t p = 0; p < r.pv.patchCount(); ++p) {
      glm::dvec3 nf = faceNormal(mesh, r.pv.parent[p]);
      for (int v = 0; v < nv; ++v) {
        size_t g = p * nv + v;
        glm::dvec3 x = flatPoint(mesh, r.pv.parent[p], &r.pv.lamParent[3 * g]);
        worstPos = std::max(worstPos, glm::length(glm::dvec3(r.pv.position[3 * g], r.pv.position[3 * g + 1], r.pv.position[3 * g + 2]) - x));
        worstNrm = std::max(worstNrm, glm::length(glm::dvec3(r.pv.normal[3 * g], r.pv.normal[3 * g + 1], r.pv.normal[3 * g + 2]) - nf));
      }
    }
    EXPECT_LT(worstPos, 1e-12);
    EXPECT_LT(worstNrm, 1e-14);
  }
}

TEST(AccurateFfd, AffineLatticeIsExactlyThatAffineMap) {
  Mesh mesh = load("sphere.obj");
  Lattice L = boxLattice(mesh, {5, 6, 4}, {2, 3, 2});
  const glm::dmat3 A(1.1, 0.2, -0.1, 0.3, 0.9, 0.05, -0.2, 0.1, 1.3);   // columns
  const glm::dvec3 c(0.3, -0.2, 0.5);
  for (auto& p : L.controlPoints) p = A * p + c;
  AccRun r = runAccurateCpu(mesh, L, {false, true});
  const glm::dmat3 cofA = cofactor(A);
  double worstPos = 0, worstAngle = 0;
  const int nv = tessVertexCount(10);
  for (size_t p = 0; p < r.pv.patchCount(); ++p) {
    glm::dvec3 nf = glm::normalize(cofA * faceNormal(mesh, r.pv.parent[p]));
    for (int v = 0; v < nv; ++v) {
      size_t g = p * nv + v;
      glm::dvec3 x = A * flatPoint(mesh, r.pv.parent[p], &r.pv.lamParent[3 * g]) + c;
      worstPos = std::max(worstPos, glm::length(glm::dvec3(r.pv.position[3 * g], r.pv.position[3 * g + 1], r.pv.position[3 * g + 2]) - x));
      glm::dvec3 n(r.pv.normal[3 * g], r.pv.normal[3 * g + 1], r.pv.normal[3 * g + 2]);
      worstAngle = std::max(worstAngle, angleBetween(n, nf));
    }
  }
  EXPECT_LT(worstPos, 1e-12);
  EXPECT_LT(worstAngle, 1e-12);
}

TEST(AccurateFfd, DeformedLatticeIsExactAtEveryTessellationVertex) {
  for (std::array<int, 3> deg : {std::array{2, 2, 2}, std::array{3, 3, 3}, std::array{5, 5, 5}}) {
    SCOPED_TRACE(deg[0]);
    Mesh mesh = load("sphere.obj");
    Lattice L = boxLattice(mesh, {deg[0] + 3, deg[1] + 2, deg[2] + 3}, deg, 0.01);
    perturb(L, 0.12, 3);
    AccRun r = runAccurateCpu(mesh, L, {false, true});
    double dist, angle;
    exactness(mesh, L, r.pv, dist, angle);
    std::printf("degree %d: %zu patches, max distance to exact FFD %.3g, max normal angle to cof(J) n_face %.3g deg\n", deg[0],
                r.pv.patchCount(), dist, angle);
    EXPECT_LT(dist, deg[0] == 5 ? 1e-9 : 1e-12);
    EXPECT_LT(angle, 1e-9);
  }
}

TEST(AccurateFfd, OutputIsClosedAndSharedBoundariesAreBitIdentical) {
  for (const char* file : {"cube2.obj", "sphere.obj"}) {
    SCOPED_TRACE(file);
    Mesh mesh = load(file);
    Lattice L = boxLattice(mesh, {5, 5, 5}, {2, 2, 2}, 0.02);
    perturb(L, 0.1, 11);
    for (KernelVariant v : {KernelVariant{false, true}, KernelVariant{true, false}}) {
      AccRun r = runAccurateCpu(mesh, L, v);
      carryAttributes(r.pv, mesh);
      Mesh out = weldPatchVertices(r.pv);
      expectClosed(out);
      EXPECT_EQ(buildTopology(out).boundaryEdges, 0u);
      // Closed also welded by position bits alone: the two sides of every shared edge agree bit for bit.
      Mesh bits = unweldedPatchMesh(r.pv);
      weldPositions(bits);
      EXPECT_EQ(buildTopology(bits).boundaryEdges, 0u);
    }
  }
}

TEST(AccurateFfd, StrictFloatTwinIsCloseToDouble) {
  Mesh mesh = load("sphere.obj");
  Lattice L = boxLattice(mesh, {5, 5, 5}, {2, 2, 2}, 0.02);
  perturb(L, 0.1, 5);
  AccRun d = runAccurateCpu(mesh, L, {false, true}), f = runAccurateCpu(mesh, L, {true, false});
  double worst = 0, worstN = 0;
  for (size_t i = 0; i < d.pv.position.size(); ++i) worst = std::max(worst, std::abs(d.pv.position[i] - f.pv.position[i]));
  for (size_t i = 0; i < d.pv.normal.size(); ++i) worstN = std::max(worstN, std::abs(d.pv.normal[i] - f.pv.normal[i]));
  std::printf("float vs double: positions %.3g, normals %.3g\n", worst, worstN);
  EXPECT_LT(worst, 2e-6);
  EXPECT_LT(worstN, 1e-5);
}

TEST(AccurateFfd, NormalIsThePatchsGeometricNormal) {
  // P_l1 x P_l2 from the control points (derivatives of the Bernstein form) against the output normal,
  // at every tessellation vertex of every patch that is not a sliver, in double.
  Mesh mesh = load("sphere.obj");
  Lattice L = boxLattice(mesh, {5, 6, 5}, {2, 3, 2}, 0.02);
  perturb(L, 0.12, 9);
  AccRun r = runAccurateCpu(mesh, L, {false, true}, 4);
  const int n = r.job.degree, m = triangleControlPoints(n), nv = tessVertexCount(4);
  double worst = 0;
  size_t checked = 0;
  for (size_t p = 0; p < r.pv.patchCount(); ++p) {
    const double* c = &r.job.corners[4 * SFFD_ACC_CORNER_STRIDE * p];
    glm::dvec3 c0(c[0], c[1], c[2]), c1(c[4], c[5], c[6]), c2(c[8], c[9], c[10]);
    if (glm::length(glm::cross(c1 - c0, c2 - c0)) < 1e-4) continue;
    auto cp = [&](int i, int k) {
      const double* q = &r.out.controlPoints[4 * (p * m + linearIndex(n, i, k))];
      return glm::dvec3(q[0], q[1], q[2]);
    };
    for (int v = 0; v < nv; ++v) {
      const double* lp = &r.pv.lamParent[3 * (p * nv + v)];
      (void)lp;
      int rr = 0;
      while ((rr + 1) * (rr + 2) / 2 <= v) ++rr;
      int t = v - rr * (rr + 1) / 2;
      glm::dvec3 lam(double(4 - rr) / 4, double(rr - t) / 4, double(t) / 4), d1(0.0), d2(0.0);
      for (int idx = 0; idx < triangleControlPoints(n - 1); ++idx) {
        int i, j, k;
        triangleMultiIndex(n - 1, idx, i, j, k);
        double b = triangleBernstein(n - 1, i, j, k, lam);
        d1 += b * (cp(i, k) - cp(i + 1, k));
        d2 += b * (cp(i, k + 1) - cp(i + 1, k));
      }
      glm::dvec3 geo = glm::normalize(glm::cross(d1, d2));
      const double* o = &r.pv.normal[3 * (p * nv + v)];
      worst = std::max(worst, angleBetween(geo, glm::dvec3(o[0], o[1], o[2])));
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000u);
  EXPECT_LT(worst, 1e-8);
}

TEST(AccurateFfd, PatchDegreeAndLevelAreChecked) {
  Mesh mesh = load("cube2.obj");
  Lattice L = boxLattice(mesh, {5, 5, 5}, {2, 2, 2});
  EXPECT_THROW(makeAccurateJob(mesh, L, {}, 0), Error);
  EXPECT_THROW(makeAccurateJob(mesh, L, {}, 65), Error);
  AccurateJob empty = makeAccurateJob(mesh, L, {}, 10);
  EXPECT_EQ(accurateFfd(sffd::testing::cpuBackend(), empty, packLattice(L), {false, true}).positions.size(), 0u);
}
