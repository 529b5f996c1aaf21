// Conformance: the classic, PN, clip and deform kernels on every backend (Vulkan, GL through EGL and
// OSMesa, the CPU backend itself) against the CPU backend, in every variant (docs/CONFORMANCE.md states
// the tolerances).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <sstream>

#include "backends/backend_select.h"
#include "backends/backend_test_support.h"
#include "analysis/buffer_compare.h"
#include "kernels/classic/classic_ffd.h"
#include <sffd/error.h>
#include "kernels/pn/pn_triangles.h"
#include "kernels/clip/regular_clip.h"
#include "kernels/smooth/smooth_deform.h"
#include "kernels/clip/split_pattern_table.h"
#include "backends/vulkan/vk_backend.h"
#include "core/job_budget.h"

using namespace sffd;

namespace {

// A closed UV sphere with unit normals, partly outside the lattice box when `radius` > box.
Mesh sphereMesh(int rings, int segments, double radius) {
  Mesh m;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s < segments; ++s) {
      double th = M_PI * r / rings, ph = 2 * M_PI * s / segments;
      glm::dvec3 n(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
      m.positions.push_back(radius * n + glm::dvec3(0.1, -0.05, 0.02));
      m.normals.push_back(n);
    }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      uint32_t a = r * segments + s, b = r * segments + (s + 1) % segments;
      m.triangles.push_back({a, a + segments, b});
      m.triangles.push_back({b, a + uint32_t(segments), b + uint32_t(segments)});
    }
  return m;
}

Lattice deformedLattice(OutsideMode outside) {
  Lattice L = makeIdentityLattice({-1, -1, -1}, {1, 1, 1}, {5, 6, 4}, {2, 3, 2});
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-0.15, 0.15);
  for (auto& p : L.controlPoints) p += glm::dvec3(u(rng), u(rng), u(rng));
  L.outside = outside;
  return L;
}

void expectClose(const ClassicOutput& a, const ClassicOutput& b, bool float32, const CompareTolerance& tol,
                 const std::string& what) {
  CompareResult p = compareBuffers(a.positions, b.positions, float32, tol);
  CompareResult n = compareBuffers(a.normals, b.normals, float32, tol);
  EXPECT_EQ(p.mismatched, 0u) << what << " positions: max_abs " << p.maxAbs << " max_ulp " << p.maxUlp;
  EXPECT_EQ(n.mismatched, 0u) << what << " normals: max_abs " << n.maxAbs << " max_ulp " << n.maxUlp;
}

class ClassicConformance : public ::testing::TestWithParam<std::string> {};

TEST_P(ClassicConformance, AgreesWithCpuReferenceInEveryVariant) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  ASSERT_TRUE(b.backend);
  Mesh mesh = sphereMesh(40, 64, 1.05);   // the caps stick out of the box: outside rules are exercised
  for (OutsideMode outside : {OutsideMode::Extrapolate, OutsideMode::Keep}) {
    PackedLattice P = packLattice(deformedLattice(outside));
    ClassicOutput cpuDouble = classicFfd(sffd::testing::cpuBackend(), mesh, P, {false, true});
    ClassicOutput cpuStrictFloat = classicFfd(sffd::testing::cpuBackend(), mesh, P, {true, false});

    // Fast float kernels against the double reference: 64 ulp or 2e-6 of the largest value.
    expectClose(classicFfd(*b.backend, mesh, P, {false, false}), cpuDouble, true, {false, 64, 2e-6}, "fast float");
    // Strict float kernels: bit-identical to the C++ reference's float path.
    expectClose(classicFfd(*b.backend, mesh, P, {true, false}), cpuStrictFloat, true, {true, 0, 0}, "strict float");
    if (b.info.limits.float64) {
      // Double kernels: within 1e-12 of the largest value; strict: bit-identical to the double reference.
      expectClose(classicFfd(*b.backend, mesh, P, {false, true}), cpuDouble, false, {false, 0, 1e-12}, "fast double");
      expectClose(classicFfd(*b.backend, mesh, P, {true, true}), cpuDouble, false, {true, 0, 0}, "strict double");
    }
  }
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

TEST_P(ClassicConformance, ChunkedJobEqualsOneDispatch) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  Mesh mesh = sphereMesh(30, 50, 0.9);
  PackedLattice P = packLattice(deformedLattice(OutsideMode::Extrapolate));
  ClassicOutput whole = classicFfd(*b.backend, mesh, P, {true, false});
  ClassicOutput chunked = classicFfd(*b.backend, mesh, P, {true, false}, 97);   // many small chunks, last one partial
  EXPECT_EQ(whole.positions, chunked.positions);
  EXPECT_EQ(whole.normals, chunked.normals);
}

TEST_P(ClassicConformance, IdentityLatticeLeavesVerticesAndNormals) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  Mesh mesh = sphereMesh(20, 32, 0.95);
  PackedLattice P = packLattice(makeIdentityLattice({-1, -1, -1}, {1, 1, 1}, {5, 5, 5}, {2, 2, 2}));
  ClassicOutput out = classicFfd(*b.backend, mesh, P, {false, false});
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    EXPECT_NEAR(glm::length(glm::dvec3(out.positions[4 * v], out.positions[4 * v + 1], out.positions[4 * v + 2]) - mesh.positions[v]), 0, 1e-6);
    EXPECT_NEAR(glm::length(glm::dvec3(out.normals[4 * v], out.normals[4 * v + 1], out.normals[4 * v + 2]) - mesh.normals[v]), 0, 1e-6);
  }
}

TEST_P(ClassicConformance, PnKernelAgreesWithCpuReference) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  for (const char* file : {"/cube2.obj", "/torus.obj"}) {
    SCOPED_TRACE(file);
    PreparedMesh P = prepareMesh(readMesh(std::string(SFFD_TEST_DATA) + file));
    PnOutput cpuDouble = pnTriangles(sffd::testing::cpuBackend(), P, {false, true}), cpuFloat = pnTriangles(sffd::testing::cpuBackend(), P, {true, false});
    // Fast kernels against the C++ float path: the same float inputs, so the ill-conditioned spots
    // (normals of very short edges) agree too; the double reference would differ there by 1e-4.
    CompareResult fast = compareBuffers(pnTriangles(*b.backend, P, {false, false}).records, cpuFloat.records, true, {false, 64, 2e-6});
    EXPECT_EQ(fast.mismatched, 0u) << "fast float: max_abs " << fast.maxAbs << " max_ulp " << fast.maxUlp;
    CompareResult strict = compareBuffers(pnTriangles(*b.backend, P, {true, false}).records, cpuFloat.records, true, {true, 0, 0});
    EXPECT_EQ(strict.mismatched, 0u) << "strict float: max_abs " << strict.maxAbs << " max_ulp " << strict.maxUlp;
    // Several chunks, the last one partial.
    CompareResult chunked = compareBuffers(pnTriangles(*b.backend, P, {true, false}, 1000).records, cpuFloat.records, true, {true, 0, 0});
    EXPECT_EQ(chunked.mismatched, 0u);
    if (b.info.limits.float64) {
      CompareResult d = compareBuffers(pnTriangles(*b.backend, P, {true, true}).records, cpuDouble.records, false, {true, 0, 0});
      EXPECT_EQ(d.mismatched, 0u) << "strict double";
    }
  }
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

TEST_P(ClassicConformance, ClipKernelsAgreeWithCpuReference) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  for (auto [file, l] : {std::pair{"/cube2.obj", 0.09}, std::pair{"/torus.obj", 0.04}}) {
    SCOPED_TRACE(file);
    Mesh m = readMesh(std::string(SFFD_TEST_DATA) + file);
    PreparedMesh P = prepareMesh(m);
    ClipTriangles C = buildClipTriangles(m, l, splitPatternTable().nmax());
    for (KernelVariant v : {KernelVariant{true, false}, KernelVariant{false, false}}) {
      PnOutput pn = pnTriangles(sffd::testing::cpuBackend(), P, {true, false});   // the same PN input for both sides
      SubTriangleRecords cpu = regularClip(sffd::testing::cpuBackend(), P, pn, C, l, {true, false});
      SubTriangleRecords gpu = regularClip(*b.backend, P, pn, C, l, v);
      ASSERT_EQ(gpu.headers, cpu.headers) << "sub-triangle topology differs (strict " << v.strict << ")";
      CompareResult r = compareBuffers(gpu.records, cpu.records, true, crossDeviceTolerance("clip.records", v.strict, false));
      EXPECT_EQ(r.mismatched, 0u) << "strict " << v.strict << ": max_abs " << r.maxAbs << " max_ulp " << r.maxUlp;
    }
    // Written in several chunks, the output is the same.
    PnOutput pn = pnTriangles(sffd::testing::cpuBackend(), P, {true, false});
    SubTriangleRecords chunked = regularClip(*b.backend, P, pn, C, l, {true, false}, 777);
    EXPECT_EQ(chunked.records, regularClip(sffd::testing::cpuBackend(), P, pn, C, l, {true, false}).records);
  }
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

TEST_P(ClassicConformance, SmoothDeformKernelAgreesWithCpuReference) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  Mesh m = readMesh(std::string(SFFD_TEST_DATA) + "/cube2.obj");
  PreparedMesh P = prepareMesh(m);
  PnOutput pn = pnTriangles(sffd::testing::cpuBackend(), P, {true, false});
  double l = 0.5;
  SubTriangleRecords subs = regularClip(sffd::testing::cpuBackend(), P, pn, buildClipTriangles(m, l, splitPatternTable().nmax()), l, {true, false});
  PackedLattice L = packLattice(deformedLattice(OutsideMode::Extrapolate));
  FitTable fit = makeFitTable(6);
  SmoothOutput cpu = smoothDeform(sffd::testing::cpuBackend(), L, subs, fit, 10, {true, false});
  for (KernelVariant v : {KernelVariant{true, false}, KernelVariant{false, false}}) {
    SmoothOutput gpu = smoothDeform(*b.backend, L, subs, fit, 10, v);
    CompareResult p = compareBuffers(gpu.patches, cpu.patches, true, crossDeviceTolerance("deform.patches", v.strict, false)),
                  t = compareBuffers(gpu.tess, cpu.tess, true, crossDeviceTolerance("deform.tess.positions", v.strict, false));
    EXPECT_EQ(p.mismatched, 0u) << "patches, strict " << v.strict << ": max_abs " << p.maxAbs << " max_ulp " << p.maxUlp;
    EXPECT_EQ(t.mismatched, 0u) << "tessellation, strict " << v.strict << ": max_abs " << t.maxAbs << " max_ulp " << t.maxUlp;
  }
  // The split form (one dispatch per step) gives the fused kernel's output, bit for bit in strict mode.
  SmoothOutput split = smoothDeform(*b.backend, L, subs, fit, 10, {true, false}, /*split=*/true);
  EXPECT_EQ(split.patches, cpu.patches);
  EXPECT_EQ(split.tess, cpu.tess);
  EXPECT_EQ(split.timings.size(), 4u);
  SmoothOutput chunked = smoothDeform(*b.backend, L, subs, fit, 10, {true, false}, false, 50);
  EXPECT_EQ(chunked.tess, cpu.tess);
  EXPECT_EQ(vk::validationMessageCount(), 0u);
}

// The tessellation at every level a job may ask for (1..kMaxTessLevel): the twin runs its vertices eight
// at a time (smooth_tessellate_cpu.h), so each level has its own full groups and tail.
TEST_P(ClassicConformance, SmoothTessellationAgreesAtEveryLevel) {
  SFFD_OPEN_OR_SKIP(b, GetParam());
  Mesh m = readMesh(std::string(SFFD_TEST_DATA) + "/cube.obj");
  PreparedMesh P = prepareMesh(m);
  PnOutput pn = pnTriangles(sffd::testing::cpuBackend(), P, {true, false});
  const double l = 4;   // one sub-triangle a triangle
  SubTriangleRecords subs = regularClip(sffd::testing::cpuBackend(), P, pn, buildClipTriangles(m, l, splitPatternTable().nmax()), l, {true, false});
  PackedLattice L = packLattice(deformedLattice(OutsideMode::Extrapolate));
  FitTable fit = makeFitTable(6);
  for (int level = 1; level <= kMaxTessLevel; ++level) {
    SmoothOutput cpu = smoothDeform(sffd::testing::cpuBackend(), L, subs, fit, level, {true, false});
    SmoothOutput gpu = smoothDeform(*b.backend, L, subs, fit, level, {true, false});
    ASSERT_EQ(gpu.tess.size(), cpu.tess.size()) << "level " << level;
    EXPECT_EQ(gpu.tess, cpu.tess) << "level " << level;
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, ClassicConformance, ::testing::ValuesIn(sffd::testing::testBackends()),
                         [](const auto& info) { return sffd::testing::backendTestName(info.param); });

TEST(CrossApi, GlAndVulkanFastKernelsAgreeWithinUlpBound) {
  SFFD_OPEN_OR_SKIP(vkb, "vulkan");
  SFFD_OPEN_OR_SKIP(glb, "gl");
  Mesh mesh = sphereMesh(40, 64, 1.0);
  PackedLattice P = packLattice(deformedLattice(OutsideMode::Extrapolate));
  expectClose(classicFfd(*vkb.backend, mesh, P, {false, false}), classicFfd(*glb.backend, mesh, P, {false, false}), true,
              {false, 64, 1e-6}, "GL vs Vulkan fast float");
}

TEST(BackendSelect, UnknownBackendIsAUsageError) {
  BackendRequest r;
  r.name = "metal";
  try {
    openBackend(r);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input);
  }
}

TEST(BackendSelect, DeviceSubstringThatMatchesNothingIsADeviceError) {
  BackendRequest r;
  r.name = "vulkan";
  r.device = "no-such-gpu-xyz";
  try {
    openBackend(r);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Device);
  }
}

}  // namespace
