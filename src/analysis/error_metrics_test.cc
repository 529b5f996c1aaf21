// Error analysis (error_metrics.h, METHOD.md 5): statistics, the quadrature, the exact deformed
// volume against exact values and against a very fine classic deformation, the errors of accurate and
// classic FFD, and the .bpt reference on the exact surface.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <map>
#include <random>

#include "backends/backend_test_support.h"
#include "kernels/accurate/accurate_patches.h"
#include "kernels/classic/classic_ffd.h"
#include "analysis/error_metrics.h"
#include "kernels/clip/knot_box_clip.h"
#include "kernels/common/lattice_eval.h"
#include "tests/support/test_lattices.h"

using namespace sffd;

namespace {

const std::string kData = SFFD_TEST_DATA;

Mesh load(const std::string& name) { return readMesh(kData + "/" + name); }

using sffd::test::boxLattice;
using sffd::test::perturb;

struct Accurate {
  PatchVertices pv;
  Mesh out;
};
Accurate accurate(const Mesh& mesh, const Lattice& L, int level = 10) {
  AccurateJob job = makeAccurateJob(mesh, L, clipAgainstKnotBoxes(mesh, L), level);
  Accurate a;
  a.pv = accuratePatchVertices(job, accurateFfd(sffd::testing::cpuBackend(), job, packLattice(L), {false, true}));
  carryAttributes(a.pv, mesh);
  a.out = weldPatchVertices(a.pv);
  return a;
}

Mesh classic(const Mesh& mesh, const Lattice& L) { return applyClassicOutput(mesh, classicFfd(sffd::testing::cpuBackend(), mesh, packLattice(L), {false, true})); }

// Every triangle split into k^2 (vertices welded by their barycentric grid position along shared edges
// through exact position equality: the grid points of a shared edge are computed from the same ends).
Mesh subdivide(const Mesh& m, int k) {
  Mesh out;
  std::map<std::array<double, 3>, uint32_t> ids;
  auto vid = [&](const glm::dvec3& p, const glm::dvec3& n) {
    auto [it, fresh] = ids.emplace(std::array<double, 3>{p.x, p.y, p.z}, uint32_t(out.positions.size()));
    if (fresh) {
      out.positions.push_back(p);
      out.normals.push_back(n);
    }
    return it->second;
  };
  for (const auto& t : m.triangles) {
    glm::dvec3 V[3] = {m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]};
    glm::dvec3 n = glm::normalize(glm::cross(V[1] - V[0], V[2] - V[0]));
    // Points from the two corners of the lower position first, so shared edges give the same bits.
    auto point = [&](int i, int j) {   // (k - i - j, i, j) / k
      int w[3] = {k - i - j, i, j};
      int order[3] = {0, 1, 2};
      std::sort(order, order + 3, [&](int a, int b) { return std::lexicographical_compare(&V[a].x, &V[a].x + 3, &V[b].x, &V[b].x + 3); });
      glm::dvec3 p(0.0);
      for (int o : order) p += (double(w[o]) / k) * V[o];
      return p;
    };
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k - i; ++j) {
        uint32_t a = vid(point(i, j), n), b = vid(point(i + 1, j), n), c = vid(point(i, j + 1), n);
        out.triangles.push_back({a, b, c});
        if (i + j < k - 1) {
          uint32_t d = vid(point(i + 1, j + 1), n);
          out.triangles.push_back({b, d, c});
        }
      }
  }
  weldPositions(out);
  return out;
}

}  // namespace

TEST(ErrorMetrics, Statistics) {
  ErrorStats s = errorStats({1, 2, 3, 6});
  EXPECT_DOUBLE_EQ(s.avg, 3);
  EXPECT_DOUBLE_EQ(s.max, 6);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt((4 + 1 + 0 + 9) / 4.0));   // population standard deviation
  ErrorStats e = errorStats({});
  EXPECT_EQ(e.avg, 0);
}

TEST(ErrorMetrics, GaussLegendreIsExactToDegree2qMinus1) {
  for (int q : {1, 2, 5, 9, 23}) {
    std::vector<double> x, w;
    gaussLegendre01(q, x, w);
    for (int d = 0; d <= 2 * q - 1; ++d) {
      double s = 0;
      for (int i = 0; i < q; ++i) s += w[i] * std::pow(x[i], d);
      EXPECT_NEAR(s, 1.0 / (d + 1), 1e-14) << "q " << q << " degree " << d;
    }
  }
}

TEST(ErrorMetrics, VolumeOfIdentityAndAffineLattices) {
  Mesh cube = load("cube2.obj");
  ASSERT_TRUE(isClosed(cube));
  EXPECT_NEAR(signedVolume(cube), 8.0, 1e-14);
  Lattice L = boxLattice(cube, {5, 5, 5}, {2, 2, 2});
  EXPECT_NEAR(exactDeformedVolume(cube, L), 8.0, 1e-12);
  // An affine map of the control points: exactly det(A) times the volume.
  const glm::dmat3 A(1.1, 0.2, -0.1, 0.3, 0.9, 0.05, -0.2, 0.1, 1.3);
  Lattice La = L;
  for (auto& p : La.controlPoints) p = A * p + glm::dvec3(0.3, -0.2, 0.5);
  EXPECT_NEAR(exactDeformedVolume(cube, La), glm::determinant(A) * 8.0, 1e-12);
  // Degree 3 and a mirror (det < 0): the signed volume changes sign.
  Lattice Lm = boxLattice(cube, {6, 5, 7}, {3, 2, 3}, 0.1);
  for (auto& p : Lm.controlPoints) p.x = -p.x;
  EXPECT_NEAR(exactDeformedVolume(cube, Lm), -8.0, 1e-12);
  // A curved closed mesh: the identity gives the mesh's own volume.
  Mesh sphere = load("sphere.obj");
  EXPECT_NEAR(exactDeformedVolume(sphere, boxLattice(sphere, {5, 5, 5}, {2, 2, 2})), signedVolume(sphere), 1e-12);
}

TEST(ErrorMetrics, ExactVolumeAgreesWithFineClassicAndAccurateDeformations) {
  Mesh cube = load("cube2.obj");
  Lattice L = boxLattice(cube, {5, 5, 5}, {2, 2, 2}, 0.05);
  perturb(L, 0.25, 21);
  const double exact = exactDeformedVolume(cube, L);
  // The rule is exact: more points change nothing.
  EXPECT_NEAR(exactDeformedVolume(cube, L, 14), exact, 1e-12 * std::abs(exact));
  // Classic deformations of finer and finer subdivisions converge to it (second order).
  double prevErr = 0;
  for (int k : {32, 64, 128}) {
    Mesh fine = subdivide(cube, k);
    ASSERT_TRUE(isClosed(fine));
    const double err = std::abs(signedVolume(classic(fine, L)) - exact) / std::abs(exact);
    std::printf("classic, %zu triangles: volume rel. error %.3g\n", fine.triangles.size(), err);
    if (prevErr > 0) {
      EXPECT_LT(err, prevErr / 3);
    }
    prevErr = err;
  }
  EXPECT_LT(prevErr, 1e-4);
  // The tessellated exact patches converge to it too.
  double e10 = std::abs(signedVolume(accurate(cube, L, 10).out) - exact) / std::abs(exact);
  double e40 = std::abs(signedVolume(accurate(cube, L, 40).out) - exact) / std::abs(exact);
  std::printf("accurate patches: volume rel. error %.3g at level 10, %.3g at level 40\n", e10, e40);
  EXPECT_LT(e40, e10 / 10);
  EXPECT_LT(e40, 1e-4);
}

TEST(ErrorMetrics, AccurateIsExactAndClassicIsNot) {
  Mesh cube = load("cube2.obj");
  // Identity lattice: no error at all.
  {
    Lattice L = boxLattice(cube, {5, 5, 5}, {2, 2, 2});
    Accurate a = accurate(cube, L);
    ErrorReport r = measureErrors(cube, packLattice(L), a.pv);
    EXPECT_EQ(r.vertices, a.pv.patchCount() * 66);
    EXPECT_LT(r.geometry.max, 1e-14);
    EXPECT_LT(r.normalDeg.max, 1e-10);
    std::optional<VolumeError> v = measureVolume(cube, L, a.out);
    ASSERT_TRUE(v);
    EXPECT_NEAR(v->reference, 8.0, 1e-12);
    EXPECT_NEAR(v->result, 8.0, 1e-11);   // the sum over 7128 output triangles
  }
  // A deformed lattice: accurate FFD is exact at every tessellation vertex (cube2's vertex normals are
  // its face normals, so the normals are exact too); classic FFD is not, between its vertices.
  Lattice L = boxLattice(cube, {5, 5, 5}, {2, 2, 2}, 0.05);
  perturb(L, 0.25, 21);
  PackedLattice P = packLattice(L);
  Accurate a = accurate(cube, L);
  ErrorReport ra = measureErrors(cube, P, a.pv);
  std::printf("accurate: geometry max %.3g, normal max %.3g deg\n", ra.geometry.max, ra.normalDeg.max);
  EXPECT_LT(ra.geometry.max, 1e-12);
  EXPECT_LT(ra.normalDeg.max, 1e-9);
  Mesh c = classic(cube, L);
  ErrorReport rc = measureErrors(cube, P, linearPatchVertices(c, 10));
  std::printf("classic: geometry avg %.3g max %.3g, normal avg %.3g max %.3g deg\n", rc.geometry.avg, rc.geometry.max,
              rc.normalDeg.avg, rc.normalDeg.max);
  EXPECT_GT(rc.geometry.avg, 1e-3);
  EXPECT_GT(rc.normalDeg.avg, 0.1);
  // At its own vertices (level 1: the corners only) classic FFD is exact by construction.
  ErrorReport rv = measureErrors(cube, P, linearPatchVertices(c, 1));
  EXPECT_LT(rv.geometry.max, 1e-14);
  EXPECT_LT(rv.normalDeg.max, 1e-10);
  // The volume: accurate's tessellation is close, classic's is not.
  EXPECT_LT(measureVolume(cube, L, a.out)->relError, 2e-3);
  EXPECT_GT(measureVolume(cube, L, c)->relError, measureVolume(cube, L, a.out)->relError);
}

TEST(ErrorMetrics, SmoothMeshNormalsAreTheReferenceNotFaceNormals) {
  // On a smooth mesh the reference normal interpolates the vertex normals, so accurate FFD (whose
  // normals are the patches' face normals) has a positive normal error even with the identity lattice.
  Mesh sphere = load("sphere.obj");
  Lattice L = boxLattice(sphere, {5, 5, 5}, {2, 2, 2});
  ErrorReport r = measureErrors(sphere, packLattice(L), accurate(sphere, L).pv);
  EXPECT_LT(r.geometry.max, 1e-14);
  EXPECT_GT(r.normalDeg.avg, 0.5);
}

TEST(ErrorMetrics, BptReferenceIsTheExactSurface) {
  Mesh coarse = load("teapot.bpt");
  ASSERT_FALSE(coarse.patches.empty());
  EXPECT_FALSE(isClosed(coarse));
  Lattice L = boxLattice(coarse, {5, 5, 5}, {2, 2, 2}, 0.01);
  EXPECT_FALSE(measureVolume(coarse, L, coarse).has_value());
  PackedLattice P = packLattice(L);
  ExactReference ref(coarse, P);
  ASSERT_TRUE(ref.exactSurface());
  // The midpoint of a coarse grid edge, inside patch 5, is a vertex of the twice finer tessellation.
  MeshReadOptions o;
  o.bptResolution = 20;
  Mesh fine = readMesh(kData + "/teapot.bpt", o);
  const int patch = 5, i = 3, j = 4;
  const uint32_t tri = uint32_t(patch * 200 + 2 * (i * 10 + j));   // cell (i, j): (i,j) (i+1,j) (i,j+1)
  ASSERT_EQ(coarse.vertexUV[coarse.triangles[tri][0]], glm::dvec2(0.3, 0.4));
  glm::dvec3 x, n;
  ref.preImage(tri, glm::dvec3(0.5, 0.5, 0.0), x, n);
  const uint32_t fv = uint32_t(patch * 21 * 21 + (2 * i + 1) * 21 + 2 * j);
  EXPECT_LT(glm::length(x - fine.positions[fv]), 1e-12);
  EXPECT_LT(glm::length(n - fine.normals[fv]), 1e-12);
  const auto& t = coarse.triangles[tri];
  EXPECT_GT(glm::length(x - 0.5 * (coarse.positions[t[0]] + coarse.positions[t[1]])), 1e-4);   // not the flat point
  // At the mesh's own vertices the reference is the vertex (and its exact normal): classic FFD with the
  // identity lattice has no error there (normals up to the reader's 1e-3 rad seam averaging).
  Mesh c = classic(coarse, L);
  ErrorReport rv = measureErrors(coarse, P, linearPatchVertices(c, 1));
  EXPECT_LT(rv.geometry.max, 1e-12);
  EXPECT_LT(rv.normalDeg.max, 0.06);
  // Between them, the flat triangles miss the curved surface.
  ErrorReport r10 = measureErrors(coarse, P, linearPatchVertices(c, 10));
  EXPECT_GT(r10.geometry.avg, 1e-4);
  EXPECT_GT(r10.geometry.max, 1e-2);
}
