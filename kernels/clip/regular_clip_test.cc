// Regular clipping (METHOD.md 4.2): crack-free sub-triangles (the welded result of a closed mesh is
// closed and consistently oriented), exact cover of every parent, pre-split of long edges.
#include <gtest/gtest.h>

#include <cstring>
#include <map>

#include "backends/backend_test_support.h"
#include "kernels/clip/knot_box_clip.h"
#include "model/lattice.h"
#include "kernels/clip/regular_clip.h"
#include "analysis/triangle_quality.h"
#include "kernels/common/shader_layout.h"
#include "kernels/clip/split_pattern_table.h"

using namespace sffd;

namespace {

const std::string kData = SFFD_TEST_DATA;

glm::dvec3 rec(const SubTriangleRecords& R, size_t s, int slot) {
  const double* p = &R.records[(s * SFFD_SUB_STRIDE + slot) * 4];
  return {p[0], p[1], p[2]};
}

SubTriangleRecords clipMesh(const Mesh& m, double l, KernelVariant v, ClipTriangles* clipOut = nullptr) {
  PreparedMesh P = prepareMesh(m);
  PnOutput pn = pnTriangles(sffd::testing::cpuBackend(), P, v);
  ClipTriangles C = buildClipTriangles(m, l, splitPatternTable().nmax());
  if (clipOut) *clipOut = C;
  return regularClip(sffd::testing::cpuBackend(), P, pn, C, l, v);
}

// Welds sub-triangle corners by the exact bits of `slot` and checks every edge is used exactly twice,
// in opposite directions: no crack, no T-junction, consistent winding.
void expectClosed(const SubTriangleRecords& R, int slot) {
  std::map<std::array<uint64_t, 3>, uint32_t> ids;
  auto id = [&](glm::dvec3 p) {
    std::array<uint64_t, 3> k;
    std::memcpy(k.data(), &p[0], 24);
    return ids.emplace(k, uint32_t(ids.size())).first->second;
  };
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (size_t s = 0; s < R.size(); ++s) {
    uint32_t v[3] = {id(rec(R, s, slot)), id(rec(R, s, slot + 1)), id(rec(R, s, slot + 2))};
    for (int e = 0; e < 3; ++e) ++directed[{v[e], v[(e + 1) % 3]}];
  }
  size_t bad = 0;
  for (const auto& [edge, n] : directed) {
    auto back = directed.find({edge.second, edge.first});
    if (n != 1 || back == directed.end() || back->second != 1) ++bad;
  }
  EXPECT_EQ(bad, 0u) << "directed edges without exactly one opposite partner, of " << directed.size();
}

void expectCoversParents(const Mesh& m, const SubTriangleRecords& R) {
  std::vector<double> area(m.triangles.size(), 0.0);
  for (size_t s = 0; s < R.size(); ++s) {
    uint32_t p = R.headers[4 * s];
    glm::dvec3 a = rec(R, s, SFFD_SUB_XFLAT), b = rec(R, s, SFFD_SUB_XFLAT + 1), c = rec(R, s, SFFD_SUB_XFLAT + 2);
    const auto& t = m.triangles[p];
    glm::dvec3 pn = glm::cross(m.positions[t[1]] - m.positions[t[0]], m.positions[t[2]] - m.positions[t[0]]);
    glm::dvec3 sn = glm::cross(b - a, c - a);
    EXPECT_GE(glm::dot(pn, sn), -1e-12 * glm::dot(pn, pn)) << "sub-triangle " << s << " winds against its parent";
    area[p] += 0.5 * glm::length(sn);
  }
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    const auto& tr = m.triangles[t];
    double want = 0.5 * glm::length(glm::cross(m.positions[tr[1]] - m.positions[tr[0]], m.positions[tr[2]] - m.positions[tr[0]]));
    EXPECT_NEAR(area[t], want, 1e-6 * want + 1e-15) << "parent " << t;
  }
}

}  // namespace

TEST(RegularClip, ClosedMeshesStayClosedAndCovered) {
  for (auto [file, l] : {std::pair{"/cube2.obj", 0.3}, std::pair{"/sphere.obj", 0.2},
                         std::pair{"/torus.obj", 0.05}}) {
    SCOPED_TRACE(file);
    Mesh m = readMesh(kData + file);
    for (KernelVariant v : {KernelVariant{false, true}, KernelVariant{true, false}}) {
      SubTriangleRecords R = clipMesh(m, l, v);
      EXPECT_GE(R.size(), m.triangles.size());
      expectClosed(R, SFFD_SUB_XPN);
      expectClosed(R, SFFD_SUB_XFLAT);
      if (v.f64) expectCoversParents(m, R);
    }
  }
}

TEST(RegularClip, SubTriangleCountFollowsEdgeLength) {
  Mesh m = readMesh(kData + "/cube2.obj");   // edges of length 2 and 2*sqrt(2)
  SubTriangleRecords coarse = clipMesh(m, 10.0, {false, true});
  EXPECT_EQ(coarse.size(), m.triangles.size());    // every count is 1: the parents themselves
  SubTriangleRecords fine = clipMesh(m, 0.25, {false, true});
  // Counts (8, 8, 12) per face triangle: around 8*8/2*... a near-regular split of ~ area / (sqrt(3)/4 l^2).
  double perParent = double(fine.size()) / m.triangles.size();
  double expected = 2.0 / (std::sqrt(3.0) / 4 * 0.25 * 0.25);
  EXPECT_GT(perParent, 0.6 * expected);
  EXPECT_LT(perParent, 1.6 * expected);
}

TEST(RegularClip, LongEdgesArePresplitNotDropped) {
  Mesh m = readMesh(kData + "/cube2.obj");
  int nmax = splitPatternTable().nmax();
  double l = 2.0 / (2.5 * nmax);   // cube edges need 2.5 Nmax segments
  ClipTriangles C;
  SubTriangleRecords R = clipMesh(m, l, {false, true}, &C);
  EXPECT_EQ(C.presplitParents, m.triangles.size());
  EXPECT_GT(C.triangles.size(), m.triangles.size());
  expectClosed(R, SFFD_SUB_XPN);
  expectCoversParents(m, R);
}

TEST(RegularClip, IdentityCornersLieOnThePnSurface) {
  // Corners of parents come out exactly; normals unit length.
  Mesh m = readMesh(kData + "/sphere.obj");
  SubTriangleRecords R = clipMesh(m, 0.3, {false, true});
  for (size_t s = 0; s < R.size(); ++s)
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(glm::length(rec(R, s, SFFD_SUB_NPN + c)), 1.0, 1e-12);
      EXPECT_NEAR(glm::length(rec(R, s, SFFD_SUB_NLIN + c)), 1.0, 1e-12);
      glm::dvec3 lam = rec(R, s, SFFD_SUB_LAM + c);
      EXPECT_NEAR(lam.x + lam.y + lam.z, 1.0, 1e-12);
    }
}

TEST(KnotBoxRecords, ClosedAndCoveredLikeRegular) {
  for (const char* file : {"/cube2.obj", "/torus.obj"}) {
    SCOPED_TRACE(file);
    Mesh m = readMesh(kData + file);
    glm::dvec3 lo(1e30), hi(-1e30);
    for (const auto& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
    Lattice L = makeIdentityLattice(lo, hi, {5, 5, 5}, {2, 2, 2});
    PreparedMesh P = prepareMesh(m);
    PnOutput pn = pnTriangles(sffd::testing::cpuBackend(), P, {false, true});
    SubTriangleRecords R = recordsFromSubTriangles(P, pn, clipAgainstKnotBoxes(m, L), {false, true});
    EXPECT_GT(R.size(), m.triangles.size());
    expectClosed(R, SFFD_SUB_XPN);
    expectCoversParents(m, R);
  }
}

TEST(RegularClip, FewerSliversThanKnotBoxAtComparableCounts) {
  // METHOD.md 4: the reason for the improved clipping. Rabbit, 5x5x5 knot boxes vs a regular
  // split tuned to a similar sub-triangle count.
  Mesh m = readMesh(kData + "/torus.obj");
  glm::dvec3 lo(1e30), hi(-1e30);
  for (const auto& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  PreparedMesh P = prepareMesh(m);
  PnOutput pn = pnTriangles(sffd::testing::cpuBackend(), P, {false, true});
  SubTriangleRecords kb = recordsFromSubTriangles(P, pn, clipAgainstKnotBoxes(m, makeIdentityLattice(lo, hi, {5, 5, 5}, {2, 2, 2})), {false, true});
  double l = 0.05 * glm::length(hi - lo);
  SubTriangleRecords rg = regularClip(sffd::testing::cpuBackend(), P, pn, buildClipTriangles(m, l, splitPatternTable().nmax()), l, {false, true});
  auto stats = [](const SubTriangleRecords& R) {
    std::vector<std::array<glm::dvec3, 3>> t(R.size());
    for (size_t s = 0; s < R.size(); ++s)
      for (int c = 0; c < 3; ++c) t[s][c] = rec(R, s, SFFD_SUB_XFLAT + c);
    return qualityStats(t);
  };
  QualityStats a = stats(kb), b = stats(rg);
  std::printf("knot-box: %zu sub-triangles, min angle %.4f deg, share < 0.3 %.4f; regular (l = %.4f): %zu, %.4f deg, %.4f\n",
              a.count, a.minAngleDeg, a.shareBelow03, l, b.count, b.minAngleDeg, b.shareBelow03);
  EXPECT_GT(b.minAngleDeg, a.minAngleDeg);
  EXPECT_LT(b.shareBelow03, a.shareBelow03);
}

namespace {

// The words uploadPackedTable writes for `table` into a buffer filled with ones before.
std::vector<uint32_t> uploadedWords(const SplitPatternTable& table) {
  Backend& B = sffd::testing::cpuBackend();
  const PackedTable T = packedTableOf(table);
  std::vector<uint32_t> words(T.wordCount, ~0u);
  const BufferId buffer = B.createBuffer(words.size() * 4);
  B.upload(buffer, 0, words.data(), words.size() * 4);
  uploadPackedTable(B, buffer, table);
  B.download(buffer, 0, words.data(), words.size() * 4);
  B.destroyBuffer(buffer);
  return words;
}

}  // namespace

// The clip kernels read the table as words: the patterns and vertices as they are, the 16-bit triangle
// indices two to a word (low half first), and an odd count's last word with its upper half 0. The compiled-in
// table's count is even (Nmax 24), so an odd one is made here.
TEST(RegularClip, TheTableUploadsAsTheKernelsReadItAtAnyLength) {
  const SplitPattern patterns[] = {{0, 3, 0, 1}};
  const SplitPatternVertex vertices[] = {{{1, 0, 0}, 0, 0, 0}, {{0, 1, 0}, 1, 0, 0}, {{0, 0, 1}, 2, 0, 0}};
  const uint16_t indices[] = {0, 1, 2, 2, 1, 0};
  for (size_t count : {size_t(3), size_t(6)}) {
    SCOPED_TRACE(std::to_string(count) + " indices");
    const SplitPatternTable table(1, patterns, vertices, std::span<const uint16_t>(indices, count));
    const PackedTable T = packedTableOf(table);
    EXPECT_EQ(T.vertexWord, 4u);
    EXPECT_EQ(T.triangleWord, 16u);
    EXPECT_EQ(T.wordCount, 16u + (count + 1) / 2);
    const std::vector<uint32_t> words = uploadedWords(table);
    EXPECT_EQ(std::memcmp(words.data(), patterns, sizeof patterns), 0);
    EXPECT_EQ(std::memcmp(&words[T.vertexWord], vertices, sizeof vertices), 0);
    for (size_t i = 0; i < count; ++i) {
      const uint32_t w = words[T.triangleWord + i / 2];
      EXPECT_EQ(i % 2 ? w >> 16 : w & 0xffffu, indices[i]) << "index " << i;
    }
    if (count % 2) EXPECT_EQ(words.back() >> 16, 0u);
  }
}
