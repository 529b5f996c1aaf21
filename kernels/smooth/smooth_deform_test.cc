// Smooth FFD deform stage (METHOD.md 3.4, 3.5): the identity lattice reproduces the PN triangles;
// closed inputs give closed, consistently oriented outputs (bitwise C0 along every shared edge).
#include <gtest/gtest.h>

#include <map>

#include "backends/backend_test_support.h"
#include "model/lattice.h"
#include "model/mesh.h"
#include "io/lattice_io.h"
#include "kernels/common/shader_layout.h"
#include "kernels/smooth/smooth_deform.h"
#include "kernels/clip/split_pattern_table.h"

using namespace sffd;

namespace {

const std::string kData = SFFD_TEST_DATA;

struct SmoothRun {
  Mesh mesh;
  PreparedMesh prepared;
  PnOutput pn;
  SubTriangleRecords subs;
  SmoothOutput out;
};

SmoothRun smooth(const Mesh& m, const Lattice& L, double l, KernelVariant v, int s = 6, int level = 10) {
  SmoothRun r;
  r.mesh = m;
  r.prepared = prepareMesh(m);
  r.pn = pnTriangles(sffd::testing::cpuBackend(), r.prepared, v);
  r.subs = regularClip(sffd::testing::cpuBackend(), r.prepared, r.pn, buildClipTriangles(m, l, splitPatternTable().nmax()), l, v);
  r.out = smoothDeform(sffd::testing::cpuBackend(), packLattice(L), r.subs, makeFitTable(s), level, v);
  return r;
}

Lattice boxLattice(const Mesh& m, std::array<int, 3> counts = {5, 5, 5}) {
  glm::dvec3 lo(1e30), hi(-1e30);
  for (const auto& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  glm::dvec3 pad = 0.01 * (hi - lo);
  return makeIdentityLattice(lo - pad, hi + pad, counts, {2, 2, 2});
}

void expectClosedOutput(const Mesh& out) {
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (const auto& t : out.triangles)
    for (int e = 0; e < 3; ++e) ++directed[{out.weldId[t[e]], out.weldId[t[(e + 1) % 3]]}];
  size_t bad = 0;
  for (const auto& [edge, n] : directed) {
    auto back = directed.find({edge.second, edge.first});
    if (n != 1 || back == directed.end() || back->second != 1) ++bad;
  }
  EXPECT_EQ(bad, 0u) << "of " << directed.size() << " directed edges";
  for (const auto& [edge, n] : directed) {
    auto back = directed.find({edge.second, edge.first});
    if (n != 1 || back == directed.end() || back->second != 1) {
      auto find = [&](uint32_t w) { for (size_t v = 0; v < out.weldId.size(); ++v) if (out.weldId[v] == w) return out.positions[v]; return glm::dvec3(0); };
      glm::dvec3 a = find(edge.first), b = find(edge.second);
      std::printf("bad edge %u-%u uses %d: (%.9g %.9g %.9g) (%.9g %.9g %.9g)\n", edge.first, edge.second, n, a.x, a.y, a.z, b.x, b.y, b.z);
      break;
    }
  }
}

}  // namespace

TEST(SmoothDeform, FitTableMatchesTheClosedForm) {
  // METHOD.md 3.4: for s = 6 the centre weights on the raw interior samples are 18/41, 27/41, 36/41.
  FitTable F = makeFitTable(6);
  ASSERT_EQ(F.points, 10);
  double sum = 0;
  for (int i = 0; i < F.points; ++i) {
    const double* f = &F.data[SFFD_FIT_STRIDE * i];
    int a = int(std::lround(f[0] * 6)), b = int(std::lround(f[1] * 6)), c = int(std::lround(f[2] * 6));
    int mx = std::max({a, b, c}), mn = std::min({a, b, c});
    double want = mx == 4 ? 18.0 / 41 : (mx == 2 && mn == 2 ? 36.0 / 41 : 27.0 / 41);
    EXPECT_NEAR(f[3], want, 1e-15) << a << " " << b << " " << c;
    sum += f[3] * 6 * f[0] * f[1] * f[2];
  }
  EXPECT_NEAR(sum, 1.0, 1e-14);   // sum of w * B111 over the interior points
}

TEST(SmoothDeform, IdentityLatticeReproducesPnTriangles) {
  for (const char* file : {"/sphere.obj", "/cube2.obj", "/torus.obj"}) {
    SCOPED_TRACE(file);
    Mesh m = readMesh(kData + file);
    SmoothRun r = smooth(m, boxLattice(m), 1e3, {false, true});   // no splitting: one patch per triangle
    ASSERT_EQ(r.subs.size(), m.triangles.size());
    double worst = 0;
    for (size_t t = 0; t < m.triangles.size(); ++t)
      for (int k = 0; k < 10; ++k)
        for (int a = 0; a < 3; ++a)
          worst = std::max(worst, std::abs(r.out.patches[(t * SFFD_PATCH_STRIDE + k) * 4 + a] - r.pn.records[(t * SFFD_PN_STRIDE + k) * 4 + a]));
    EXPECT_LT(worst, 1e-12);
  }
}

TEST(SmoothDeform, ClosedInputsGiveClosedOutputs) {
  struct Case { const char* mesh; const char* lattice; double l; };
  for (const Case& c : {Case{"/cube2.obj", "/lattices/cube2_twist.npy", 0.2},
                        Case{"/torus.obj", "/lattices/torus_twist.npy", 0.2},
                        Case{"/sphere.obj", "/lattices/sphere_twist.npy", 0.1}}) {
    SCOPED_TRACE(c.mesh);
    Mesh m = readMesh(kData + c.mesh);
    // The .npy convention: mesh at 0.99 inside the box normalised to half-extent 1.
    glm::dvec3 lo(1e30), hi(-1e30);
    for (const auto& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
    glm::dvec3 ctr = 0.5 * (lo + hi);
    double half = 0.5 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    for (auto& p : m.positions) p = (p - ctr) * (0.99 / half);
    LatticeReadOptions o;
    o.haveMeshBox = true;
    o.meshBoxLo = (lo - ctr) / half;
    o.meshBoxHi = (hi - ctr) / half;
    Lattice L = readLattice(kData + c.lattice, o);
    for (KernelVariant v : {KernelVariant{false, true}, KernelVariant{true, false}}) {
      SmoothRun r = smooth(m, L, c.l, v);
      PatchVertices pv = patchVerticesOf(r.subs, r.out);
      carryAttributes(pv, m);
      Mesh out = weldPatchVertices(pv);
      EXPECT_EQ(out.triangles.size(), r.subs.size() * 100);
      expectClosedOutput(out);
      // Closed also welded by position bits alone: the two sides of every shared edge agree bit for bit.
      Mesh bits = unweldedPatchMesh(pv);
      weldPositions(bits);
      expectClosedOutput(bits);
    }
  }
}
