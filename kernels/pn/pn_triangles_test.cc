// PN triangles (METHOD.md 3.2, 3.5): interpolation of corners and normals, identical boundary
// curves across shared edges (smooth and crease), flat PN patches for the split-normal cube.
#include <gtest/gtest.h>

#include "kernels/pn/pn_triangles.h"
#include "kernels/pn/pn_eval.h"
#include "kernels/common/shader_layout.h"

using namespace sffd;

namespace {

const std::string kData = SFFD_TEST_DATA;

glm::dvec3 at(const PnOutput& o, size_t tri, int i) {
  const double* p = &o.records[(tri * SFFD_PN_STRIDE + i) * 4];
  return {p[0], p[1], p[2]};
}

// Control points of edge e of triangle t in the order (corner e, near e, near e+1, corner e+1).
std::array<glm::dvec3, 4> edgeCurve(const PnOutput& o, size_t t, int e) {
  static const int corner[3] = {0, 6, 9};
  // slot 2c+1 is corner c on edge c; slot 2(c+1) is corner c+1 on edge c.
  int nearA = kSlotControlPoint[2 * e + 1], nearB = kSlotControlPoint[2 * ((e + 1) % 3)];
  return {at(o, t, corner[e]), at(o, t, nearA), at(o, t, nearB), at(o, t, corner[(e + 1) % 3])};
}

void expectSharedEdgesIdentical(const Mesh& mesh, KernelVariant variant) {
  PreparedMesh P = prepareMesh(mesh);
  PnOutput o = pnTrianglesCpu(P, variant);
  size_t checked = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int e = 0; e < 3; ++e) {
      int u = P.topology.neighbour[t][e], f = P.topology.neighbourEdge[t][e];
      if (u < 0) continue;
      auto a = edgeCurve(o, t, e), b = edgeCurve(o, size_t(u), f);
      // The neighbour runs the edge the other way.
      for (int i = 0; i < 4; ++i) EXPECT_EQ(a[i], b[3 - i]) << "triangle " << t << " edge " << e << " point " << i;
      ++checked;
    }
  EXPECT_GT(checked, 0u);
}

}  // namespace

TEST(PnTriangles, InterpolatesCornersAndNormals) {
  Mesh m = readMesh(kData + "/sphere.obj");
  PnOutput o = pnTrianglesCpu(prepareMesh(m), {false, true});
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    const int corner[3] = {0, 6, 9}, normal[3] = {0, 3, 5};
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(at(o, t, corner[c]), m.positions[m.triangles[t][c]]);
      EXPECT_EQ(at(o, t, SFFD_PN_NORMALS + normal[c]), m.normals[m.triangles[t][c]]);
    }
  }
}

TEST(PnTriangles, SharedEdgesGiveIdenticalCurves) {
  for (const char* file : {"/sphere.obj", "/cube2.obj", "/torus.obj"}) {
    SCOPED_TRACE(file);
    Mesh m = readMesh(kData + file);
    expectSharedEdgesIdentical(m, {false, true});
    expectSharedEdgesIdentical(m, {true, false});
  }
}

TEST(PnTriangles, SplitNormalCubeIsFlat) {
  // METHOD.md 5: cube2's PN triangles are flat (crease projections fall on the edges).
  Mesh m = readMesh(kData + "/cube2.obj");
  PnOutput o = pnTrianglesCpu(prepareMesh(m), {false, true});
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    glm::dvec3 a = m.positions[m.triangles[t][0]], b = m.positions[m.triangles[t][1]], c = m.positions[m.triangles[t][2]];
    glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    for (int i = 0; i < 10; ++i) EXPECT_NEAR(glm::dot(at(o, t, i) - a, n), 0, 1e-14) << "triangle " << t << " cp " << i;
  }
}

TEST(PnTriangles, SmoothEdgePointIsVlachos) {
  // One triangle, no neighbours: b210 = (2 V0 + V1 - ((V1 - V0).N0) N0) / 3.
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.normals = {glm::normalize(glm::dvec3(-0.3, 0, 1)), glm::normalize(glm::dvec3(0.2, 0.1, 1)), {0, 0, 1}};
  m.weldId = {0, 1, 2};
  m.triangles = {{0, 1, 2}};
  PnOutput o = pnTrianglesCpu(prepareMesh(m), {false, true});
  glm::dvec3 V0 = m.positions[0], V1 = m.positions[1], N0 = m.normals[0];
  glm::dvec3 want = (2.0 * V0 + V1 - glm::dot(V1 - V0, N0) * N0) / 3.0;
  EXPECT_NEAR(glm::length(at(o, 0, 1) - want), 0, 1e-15);
}
