// Conformance of the accurate FFD kernel (kernels/accurate/accurate_patches.comp) on every backend against
// the CPU backend, which runs its C++ twin (accurate_patches_cpu.cpp): strict variants bit-identical, fast variants within the
// tolerances of docs/CONFORMANCE.md; chunked jobs equal one dispatch; the identity lattice reproduces
// the flat mesh; the largest patch degree (5,5,5 -> n = 15) runs.
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <random>
#include <sstream>

#include "kernels/accurate/accurate_patches.h"
#include "backends/backend_select.h"
#include "backends/backend_test_support.h"
#include "analysis/buffer_compare.h"
#include "kernels/clip/knot_box_clip.h"
#include "backends/vulkan/vk_backend.h"
#include "tests/support/test_lattices.h"

using namespace sffd;

namespace {

const std::string kData = SFFD_TEST_DATA;

Lattice latticeFor(const Mesh& m, std::array<int, 3> counts, std::array<int, 3> degree, double amount, OutsideMode outside,
                   double margin) {
  Lattice L = test::boxLattice(m, counts, degree, margin);
  test::perturb(L, amount, 17);
  L.outside = outside;
  return L;
}

// `cpTol`: the control points' tolerance when it differs (fast float: A_n^{-1} amplifies the samples'
// rounding by up to |A_n^{-1}|_inf, 412 for n = 7, where the tessellated values do not).
void expectBuffers(const AccurateOutput& a, const AccurateOutput& b, bool float32, const CompareTolerance& tol, const std::string& what,
                   std::optional<CompareTolerance> cpTol = std::nullopt) {
  const std::pair<const char*, std::pair<const std::vector<double>*, const std::vector<double>*>> buffers[] = {
      {"control points", {&a.controlPoints, &b.controlPoints}},
      {"positions", {&a.positions, &b.positions}},
      {"normals", {&a.normals, &b.normals}}};
  for (const auto& [name, ab] : buffers) {
    ASSERT_EQ(ab.first->size(), ab.second->size()) << what << " " << name;
    CompareResult r = compareBuffers(*ab.first, *ab.second, float32, ab.first == &a.controlPoints && cpTol ? *cpTol : tol);
    EXPECT_EQ(r.mismatched, 0u) << what << " " << name << ": max_abs " << r.maxAbs << " max_ulp " << r.maxUlp << " mismatched "
                                << r.mismatched << "/" << r.total;
    std::printf("%-28s %-15s max_abs=%.3g max_ulp=%llu mismatched=%zu/%zu\n", what.c_str(), name, r.maxAbs,
                (unsigned long long)r.maxUlp, r.mismatched, r.total);
  }
}

class AccurateConformance : public ::testing::TestWithParam<std::string> {};

TEST_P(AccurateConformance, AgreesWithCpuTwinInEveryVariant) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  ASSERT_TRUE(b.backend);
  Mesh mesh = readMesh(kData + "/sphere.obj");
  // Extrapolate: a margin-less box; Keep: a box smaller than the sphere, so the outside rule is exercised.
  for (auto [outside, margin] : {std::pair{OutsideMode::Extrapolate, 0.0}, std::pair{OutsideMode::Keep, -0.05}}) {
    Lattice L = latticeFor(mesh, {5, 6, 4}, {2, 3, 2}, 0.1, outside, margin);
    PackedLattice P = packLattice(L);
    AccurateJob job = makeAccurateJob(mesh, L, clipAgainstKnotBoxes(mesh, L), 10);
    ASSERT_GT(job.count(), 1000u);
    std::string o = outside == OutsideMode::Keep ? " keep" : "";
    AccurateOutput cpuDouble = accurateFfd(sffd::testing::cpuBackend(), job, P, {false, true}), cpuFloat = accurateFfd(sffd::testing::cpuBackend(), job, P, {true, false});
    // Strict float: bit-identical to the C++ float path.
    expectBuffers(accurateFfd(*b.backend, job, P, {true, false}), cpuFloat, true, {true, 0, 0}, "strict float" + o);
    // Fast float against the double reference: positions and normals within 1e-5 of the largest value,
    // control points within 2 |A_7^{-1}|_inf 2^-24 = 5e-5, rounded up to 1e-4 (patch degree 2+3+2 = 7).
    expectBuffers(accurateFfd(*b.backend, job, P, {false, false}), cpuDouble, true, {false, 64, 1e-5}, "fast float" + o,
                  CompareTolerance{false, 64, 1e-4});
    if (b.info.limits.float64) {
      expectBuffers(accurateFfd(*b.backend, job, P, {true, true}), cpuDouble, false, {true, 0, 0}, "strict double" + o);
      expectBuffers(accurateFfd(*b.backend, job, P, {false, true}), cpuDouble, false, {false, 0, 1e-12}, "fast double" + o);
    }
  }
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

// Float variants read the lattice and the two tables from the parameter block where they fit
// (accurateParamsFor), else from the storage buffers: each placement against the double reference, with
// fast float's tolerances (a table or lattice read from a wrong place is far outside them).
TEST_P(AccurateConformance, InlineAndStorageLatticeAndTablesAgreeWithDouble) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  Mesh mesh = readMesh(kData + "/sphere.obj");
  struct Case {
    const char* what;
    std::array<int, 3> controlPoints;
    int level;
    bool latticeInline, matrixInline, basisInline;
  };
  for (const Case& c : {Case{"all inline", {5, 5, 5}, 3, true, true, true}, Case{"basis in storage", {5, 5, 5}, 10, true, true, false},
                        Case{"tables in storage", {5, 5, 6}, 3, true, false, false},
                        Case{"all in storage", {13, 13, 13}, 3, false, false, false}}) {
    Lattice L = latticeFor(mesh, c.controlPoints, {2, 2, 2}, 0.05, OutsideMode::Extrapolate, 0.01);
    PackedLattice P = packLattice(L);
    AccurateJob job = makeAccurateJob(mesh, L, clipAgainstKnotBoxes(mesh, L), c.level);
    const gpu::AccurateParams params = accurateParamsFor(P, false, accurateFrame(P.frame, job.degree, job.level));
    ASSERT_EQ(params.lattice.break_offset.w != 0, c.latticeInline) << c.what;
    ASSERT_EQ(params.tables.z != 0, c.matrixInline) << c.what;
    ASSERT_EQ(params.tables.w != 0, c.basisInline) << c.what;
    EXPECT_EQ(accurateParamsFor(P, true, accurateFrame(P.frame, job.degree, job.level)).lattice.break_offset.w, 0u) << "never in double";
    expectBuffers(accurateFfd(*b.backend, job, P, {false, false}), accurateFfd(sffd::testing::cpuBackend(), job, P, {false, true}),
                  true, {false, 64, 1e-5}, c.what, CompareTolerance{false, 64, 1e-4});
  }
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

TEST_P(AccurateConformance, LargestPatchDegree) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  Mesh mesh = readMesh(kData + "/cube2.obj");
  Lattice L = latticeFor(mesh, {7, 6, 7}, {5, 5, 5}, 0.05, OutsideMode::Extrapolate, 0.01);
  PackedLattice P = packLattice(L);
  AccurateJob job = makeAccurateJob(mesh, L, clipAgainstKnotBoxes(mesh, L), 10);
  ASSERT_EQ(job.degree, 15);
  expectBuffers(accurateFfd(*b.backend, job, P, {true, false}), accurateFfd(sffd::testing::cpuBackend(), job, P, {true, false}), true, {true, 0, 0}, "n=15 strict float");
  if (b.info.limits.float64)
    expectBuffers(accurateFfd(*b.backend, job, P, {true, true}), accurateFfd(sffd::testing::cpuBackend(), job, P, {false, true}), false, {true, 0, 0}, "n=15 strict double");
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

TEST_P(AccurateConformance, HighestTessellationLevel) {
  // --tess 64 (2145 vertices a patch): one invocation per patch would run past llvmpipe's 65535 loop
  // iterations and leave the last vertices unwritten; the staged kernel must not.
  SFFD_OPEN_OR_SKIP(b, GetParam());
  Mesh mesh = readMesh(kData + "/cube2.obj");
  Lattice L = latticeFor(mesh, {5, 5, 5}, {2, 2, 2}, 0.1, OutsideMode::Extrapolate, 0.01);
  PackedLattice P = packLattice(L);
  AccurateJob job = makeAccurateJob(mesh, L, clipAgainstKnotBoxes(mesh, L), 64);
  expectBuffers(accurateFfd(*b.backend, job, P, {true, false}), accurateFfd(sffd::testing::cpuBackend(), job, P, {true, false}), true, {true, 0, 0}, "tess 64 strict float");
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

TEST_P(AccurateConformance, ChunkedJobEqualsOneDispatch) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  Mesh mesh = readMesh(kData + "/sphere.obj");
  Lattice L = latticeFor(mesh, {5, 5, 5}, {2, 2, 2}, 0.1, OutsideMode::Extrapolate, 0.01);
  PackedLattice P = packLattice(L);
  AccurateJob job = makeAccurateJob(mesh, L, clipAgainstKnotBoxes(mesh, L), 10);
  AccurateOutput whole = accurateFfd(*b.backend, job, P, {true, false});
  AccurateOutput chunked = accurateFfd(*b.backend, job, P, {true, false}, 97);   // many chunks, the last one partial
  EXPECT_EQ(whole.controlPoints, chunked.controlPoints);
  EXPECT_EQ(whole.positions, chunked.positions);
  EXPECT_EQ(whole.normals, chunked.normals);
}

TEST_P(AccurateConformance, IdentityLatticeReproducesTheFlatMesh) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  Mesh mesh = readMesh(kData + "/sphere.obj");
  Lattice L = latticeFor(mesh, {5, 5, 5}, {2, 2, 2}, 0.0, OutsideMode::Extrapolate, 0.0);
  AccurateJob job = makeAccurateJob(mesh, L, clipAgainstKnotBoxes(mesh, L), 10);
  PatchVertices pv = accuratePatchVertices(job, accurateFfd(*b.backend, job, packLattice(L), {false, false}));
  double worstPos = 0, worstNrm = 0;
  const int nv = tessVertexCount(10);
  for (size_t p = 0; p < pv.patchCount(); ++p) {
    const auto& t = mesh.triangles[pv.parent[p]];
    glm::dvec3 nf = glm::normalize(glm::cross(mesh.positions[t[1]] - mesh.positions[t[0]], mesh.positions[t[2]] - mesh.positions[t[0]]));
    for (int v = 0; v < nv; ++v) {
      size_t g = p * nv + v;
      const double* l = &pv.lamParent[3 * g];
      glm::dvec3 x = l[0] * mesh.positions[t[0]] + l[1] * mesh.positions[t[1]] + l[2] * mesh.positions[t[2]];
      worstPos = std::max(worstPos, glm::length(glm::dvec3(pv.position[3 * g], pv.position[3 * g + 1], pv.position[3 * g + 2]) - x));
      worstNrm = std::max(worstNrm, glm::length(glm::dvec3(pv.normal[3 * g], pv.normal[3 * g + 1], pv.normal[3 * g + 2]) - nf));
    }
  }
  std::printf("%s identity, fast float: max position error %.3g, max normal error %.3g\n", GetParam().c_str(), worstPos, worstNrm);
  EXPECT_LT(worstPos, 5e-6);   // interior vertices pass through A_6^{-1} (|.|_inf = 169) in float
  EXPECT_LT(worstNrm, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Backends, AccurateConformance, ::testing::ValuesIn(sffd::testing::testBackends()),
                         [](const auto& info) { return sffd::testing::backendTestName(info.param); });

}  // namespace

