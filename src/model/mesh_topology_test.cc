// Mesh topology (mesh_topology.h, METHOD.md 3.1-3.2): adjacency by welded position on the paper's
// own models, crease slots from split normals, non-manifold and degenerate input, and the crease-angle
// fallback for meshes without normals.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <map>
#include <set>

#include "model/mesh.h"
#include "model/mesh_topology.h"

using namespace sffd;

namespace {

const std::string kData = SFFD_TEST_DATA;

Mesh load(const std::string& name) { return readMesh(kData + "/" + name); }

size_t distinctWelds(const Mesh& m) { return std::set<uint32_t>(m.weldId.begin(), m.weldId.end()).size(); }

// A mesh built in code: positions and triangles, welded, with computed (not file) normals.
Mesh makeMesh(std::vector<glm::dvec3> positions, std::vector<std::array<uint32_t, 3>> triangles) {
  Mesh m;
  m.positions = std::move(positions);
  m.triangles = std::move(triangles);
  weldPositions(m);
  computeVertexNormals(m);
  m.normalsFromFile = false;
  return m;
}

// The unit cube [-1,1]^3 as 12 outward-facing triangles on 8 shared positions.
Mesh makeCube() {
  std::vector<glm::dvec3> p;
  for (int i = 0; i < 8; ++i) p.push_back(glm::dvec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  // Each face as a quad (a, b, c, d) counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<std::array<uint32_t, 3>> t;
  for (const auto& q : quads) {
    t.push_back({uint32_t(q[0]), uint32_t(q[1]), uint32_t(q[2])});
    t.push_back({uint32_t(q[0]), uint32_t(q[2]), uint32_t(q[3])});
  }
  return makeMesh(p, t);
}

// The welded key of edge e of triangle t.
std::pair<uint32_t, uint32_t> weldedEdge(const Mesh& m, size_t t, int e) {
  uint32_t a = m.weldId[m.triangles[t][e]], b = m.weldId[m.triangles[t][(e + 1) % 3]];
  return {std::min(a, b), std::max(a, b)};
}

// Properties every topology must have: symmetric neighbours on the same welded edge, neighbour
// vertices at the same welded position, crease slots that agree from both sides.
void expectConsistent(const Mesh& m, const MeshTopology& topo) {
  const size_t T = m.triangles.size();
  ASSERT_EQ(topo.neighbour.size(), T);
  ASSERT_EQ(topo.neighbourEdge.size(), T);
  ASSERT_EQ(topo.creaseSlot.size(), T);
  ASSERT_EQ(topo.neighbourVertex.size(), T);
  size_t creaseEdges = 0;
  for (size_t t = 0; t < T; ++t) {
    for (int e = 0; e < 3; ++e) {
      int32_t u = topo.neighbour[t][e];
      int f = topo.neighbourEdge[t][e];
      if (u < 0) {
        EXPECT_EQ(f, -1);
        continue;
      }
      ASSERT_LT(size_t(u), T);
      ASSERT_GE(f, 0);
      ASSERT_LT(f, 3);
      EXPECT_NE(size_t(u), t);
      EXPECT_EQ(topo.neighbour[size_t(u)][f], int32_t(t)) << "triangle " << t << " edge " << e;
      EXPECT_EQ(topo.neighbourEdge[size_t(u)][f], e) << "triangle " << t << " edge " << e;
      EXPECT_EQ(weldedEdge(m, t, e), weldedEdge(m, size_t(u), f));
      // The two slots on this edge, and the matching slots of the neighbour (same welded corner).
      for (int c : {e, (e + 1) % 3}) {
        int s = c == e ? 2 * c + 1 : 2 * c;
        uint32_t v = m.triangles[t][c];
        uint32_t w = topo.neighbourVertex[t][s];
        EXPECT_EQ(m.weldId[w], m.weldId[v]);
        int uc = m.weldId[m.triangles[size_t(u)][f]] == m.weldId[v] ? f : (f + 1) % 3;
        EXPECT_EQ(m.triangles[size_t(u)][uc], w);
        int us = uc == f ? 2 * uc + 1 : 2 * uc;
        EXPECT_EQ(topo.neighbourVertex[size_t(u)][us], v);
        EXPECT_EQ(topo.creaseSlot[size_t(u)][us], topo.creaseSlot[t][s]);
      }
      if (t < size_t(u) && (topo.creaseSlot[t][2 * e + 1] || topo.creaseSlot[t][2 * ((e + 1) % 3)])) ++creaseEdges;
    }
    for (int s = 0; s < 6; ++s) {
      int e = slotEdge(s);
      if (topo.neighbour[t][e] >= 0) continue;
      // No neighbour: the corner's own normal, own vertex, no crease.
      uint32_t v = m.triangles[t][slotCorner(s)];
      EXPECT_EQ(topo.neighbourVertex[t][s], v);
      EXPECT_EQ(topo.creaseSlot[t][s], 0);
    }
  }
  EXPECT_EQ(topo.creaseEdges, creaseEdges);
}

size_t countNeighbours(const MeshTopology& topo) {
  size_t n = 0;
  for (const auto& a : topo.neighbour)
    for (int32_t u : a) n += u >= 0;
  return n;
}

TEST(MeshTopology, SlotConventions) {
  // Slot 2c: corner c on edge (c+2)%3; slot 2c+1: corner c on edge c.
  const int edges[6] = {2, 0, 0, 1, 1, 2};
  for (int s = 0; s < 6; ++s) {
    EXPECT_EQ(slotCorner(s), s / 2);
    EXPECT_EQ(slotEdge(s), edges[s]);
  }
}

TEST(MeshTopology, Cube2SplitNormalsMakeEveryCubeEdgeACrease) {
  Mesh m = load("cube2.obj");
  ASSERT_EQ(m.triangles.size(), 12u);
  ASSERT_TRUE(m.normalsFromFile);
  EXPECT_EQ(distinctWelds(m), 8u);
  EXPECT_EQ(m.positions.size(), 24u);   // each corner once per face normal
  MeshTopology topo = buildTopology(m);
  expectConsistent(m, topo);
  // Closed: every triangle has three neighbours, 36 / 2 = 18 welded edges (12 cube edges, 6 diagonals).
  EXPECT_EQ(countNeighbours(topo), 36u);
  EXPECT_EQ(countNeighbours(topo) / 2, 18u);
  EXPECT_EQ(topo.boundaryEdges, 0u);
  EXPECT_EQ(topo.nonManifoldEdges, 0u);
  EXPECT_EQ(topo.degenerateTriangles, 0u);
  EXPECT_EQ(topo.creaseEdges, 12u);
  size_t diagonals = 0, cubeEdges = 0;
  for (size_t t = 0; t < 12; ++t)
    for (int e = 0; e < 3; ++e) {
      const auto& tri = m.triangles[t];
      double len = glm::length(m.positions[tri[e]] - m.positions[tri[(e + 1) % 3]]);
      bool diagonal = len > 2.5;   // sides 2, diagonals 2*sqrt(2)
      uint8_t a = topo.creaseSlot[t][2 * e + 1], b = topo.creaseSlot[t][2 * ((e + 1) % 3)];
      if (diagonal) {
        ++diagonals;
        EXPECT_EQ(a, 0) << t << " " << e;
        EXPECT_EQ(b, 0) << t << " " << e;
      } else {
        ++cubeEdges;
        EXPECT_EQ(a, 1) << t << " " << e;
        EXPECT_EQ(b, 1) << t << " " << e;
        // Across a cube edge the neighbour's normal is the other face's: perpendicular to ours.
        EXPECT_NEAR(glm::dot(m.normals[topo.neighbourVertex[t][2 * e + 1]], m.normals[tri[e]]), 0.0, 1e-12);
      }
    }
  EXPECT_EQ(diagonals, 12u);   // 6 diagonal edges seen from both sides
  EXPECT_EQ(cubeEdges, 24u);
}

TEST(MeshTopology, CubeWithSmoothNormalsHasNoCreases) {
  Mesh m = load("cube.obj");
  ASSERT_EQ(m.triangles.size(), 12u);
  EXPECT_EQ(m.positions.size(), 8u);
  MeshTopology topo = buildTopology(m);
  expectConsistent(m, topo);
  EXPECT_EQ(countNeighbours(topo), 36u);
  EXPECT_EQ(topo.boundaryEdges, 0u);
  EXPECT_EQ(topo.nonManifoldEdges, 0u);
  EXPECT_EQ(topo.creaseEdges, 0u);
  for (size_t t = 0; t < 12; ++t)
    for (int s = 0; s < 6; ++s) {
      EXPECT_EQ(topo.creaseSlot[t][s], 0);
      EXPECT_EQ(topo.neighbourVertex[t][s], m.triangles[t][slotCorner(s)]);   // one vertex per position
    }
}

TEST(MeshTopology, SphereAndRabbitAreClosedAndSmooth) {
  struct Case {
    const char* name;
    size_t triangles;
  };
  for (Case c : {Case{"sphere.obj", 720}, Case{"torus.obj", 8400}}) {
    SCOPED_TRACE(c.name);
    Mesh m = load(c.name);
    ASSERT_EQ(m.triangles.size(), c.triangles);
    MeshTopology topo = buildTopology(m);
    expectConsistent(m, topo);
    EXPECT_EQ(topo.boundaryEdges, 0u);
    EXPECT_EQ(topo.nonManifoldEdges, 0u);
    EXPECT_EQ(topo.degenerateTriangles, 0u);
    EXPECT_EQ(countNeighbours(topo), 3 * c.triangles);
    std::cout << "[ stats    ] " << c.name << ": " << m.positions.size() << " vertices, " << distinctWelds(m)
              << " welded positions, " << m.triangles.size() << " triangles, " << countNeighbours(topo) / 2
              << " welded edges, " << topo.boundaryEdges << " boundary, " << topo.nonManifoldEdges
              << " non-manifold, " << topo.creaseEdges << " crease, " << topo.degenerateTriangles << " degenerate\n";
  }
}

TEST(MeshTopology, AdjacencyIsByWeldedPositionNotVertexIndex) {
  // Two triangles folded along the edge (0,1); the second uses its own copies of the edge's
  // vertices with other normals (split normals, as an OBJ with `vn` gives them).
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {1, 0, 0}, {0, -1, 1}};
  m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 1, 1}, {0, 1, 1}, {0, 1, 1}};
  for (auto& n : m.normals) n = glm::normalize(n);
  m.triangles = {{0, 1, 2}, {4, 3, 5}};
  m.normalsFromFile = true;
  weldPositions(m);
  EXPECT_EQ(distinctWelds(m), 4u);
  MeshTopology topo = buildTopology(m);
  expectConsistent(m, topo);
  EXPECT_EQ(topo.neighbour[0][0], 1);
  EXPECT_EQ(topo.neighbourEdge[0][0], 0);
  EXPECT_EQ(topo.boundaryEdges, 4u);
  EXPECT_EQ(topo.creaseEdges, 1u);
  // Corner 0 of triangle 0 on edge 0 is slot 1: its neighbour vertex is vertex 3, at the same place.
  EXPECT_EQ(topo.neighbourVertex[0][1], 3u);
  EXPECT_EQ(topo.creaseSlot[0][1], 1);
  EXPECT_EQ(topo.creaseSlot[0][2], 1);   // corner 1 on edge 0
  EXPECT_EQ(topo.creaseSlot[0][0], 0);   // corner 0 on the boundary edge 2
}

TEST(MeshTopology, NormalsWithinToleranceAreNotACrease) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  m.triangles = {{0, 1, 2}, {2, 1, 3}};
  weldPositions(m);
  // A copy of vertex 1 whose normal differs by less than the tolerance, and one by more.
  m.positions.push_back(m.positions[1]);
  m.weldId.push_back(m.weldId[1]);
  m.normals.push_back(glm::dvec3(0.5e-6, 0, 1));
  m.triangles[1][1] = 4;
  MeshTopology near = buildTopology(m);
  expectConsistent(m, near);
  EXPECT_EQ(near.creaseEdges, 0u);
  m.normals[4] = glm::dvec3(2e-6, 0, 1);
  MeshTopology far = buildTopology(m);
  expectConsistent(m, far);
  EXPECT_EQ(far.creaseEdges, 1u);
  EXPECT_EQ(far.creaseSlot[0][3], 1);   // corner 1 of triangle 0 on the shared edge 1
  EXPECT_EQ(far.creaseSlot[0][2], 0);   // corner 1 on the boundary edge 0
  EXPECT_EQ(far.creaseSlot[0][5], 0);   // corner 2 on edge 1: the same vertex 2 on both sides
}

TEST(MeshTopology, NonManifoldEdgeIsLeftUnconnectedAndCounted) {
  // Three triangles on the edge (0,1): a fan of fins.
  Mesh m = makeMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}},
                    {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  MeshTopology topo = buildTopology(m);
  expectConsistent(m, topo);
  EXPECT_EQ(topo.nonManifoldEdges, 1u);
  EXPECT_EQ(topo.boundaryEdges, 6u);
  EXPECT_EQ(countNeighbours(topo), 0u);
  EXPECT_EQ(topo.degenerateTriangles, 0u);
  // Plus a fourth fin on another edge pair that is manifold: still connected.
  m.positions.push_back({1, 1, 1});
  m.triangles.push_back({4, 1, 5});   // edge (4,1) reversed against triangle 2's (1,4)
  weldPositions(m);
  computeVertexNormals(m);
  MeshTopology topo2 = buildTopology(m);
  expectConsistent(m, topo2);
  EXPECT_EQ(topo2.nonManifoldEdges, 1u);
  EXPECT_EQ(topo2.neighbour[2][1], 3);
  EXPECT_EQ(topo2.neighbourEdge[2][1], 0);
}

TEST(MeshTopology, InconsistentWindingStillConnects) {
  // The second triangle runs the shared edge in the same direction as the first.
  Mesh m = makeMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}}, {{0, 1, 2}, {0, 1, 3}});
  MeshTopology topo = buildTopology(m);
  expectConsistent(m, topo);
  EXPECT_EQ(topo.neighbour[0][0], 1);
  EXPECT_EQ(topo.neighbour[1][0], 0);
  EXPECT_EQ(topo.boundaryEdges, 4u);
}

TEST(MeshTopology, DegenerateTrianglesAreCountedNotFatal) {
  // Triangle 0: two corners at one position (a collapsed edge). Triangle 1: three collinear points.
  // Triangles 2 and 3 share the edge (0,1) that the collapsed triangle also lies on.
  Mesh m = makeMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {2, 0, 0}, {3, 0, 0}, {0, 0, 0}},
                    {{0, 1, 6}, {1, 4, 5}, {0, 1, 2}, {1, 0, 3}});
  MeshTopology topo;
  ASSERT_NO_THROW(topo = buildTopology(m));
  expectConsistent(m, topo);
  EXPECT_EQ(topo.degenerateTriangles, 2u);
  // The collapsed triangle has no neighbours, and does not make (0,1) non-manifold.
  for (int e = 0; e < 3; ++e) EXPECT_EQ(topo.neighbour[0][e], -1);
  EXPECT_EQ(topo.neighbour[2][0], 3);
  EXPECT_EQ(topo.nonManifoldEdges, 0u);
  // The collinear triangle is topologically sound: its edge (1,4) is an ordinary boundary.
  EXPECT_EQ(topo.boundaryEdges, 4u + 3u);
  ASSERT_NO_THROW(applyCreaseAngle(m, 30));
  ASSERT_NO_THROW(topo = buildTopology(m));
  expectConsistent(m, topo);
}

TEST(MeshTopology, EmptyMesh) {
  Mesh m;
  MeshTopology topo = buildTopology(m);
  EXPECT_TRUE(topo.neighbour.empty());
  EXPECT_EQ(topo.boundaryEdges + topo.nonManifoldEdges + topo.creaseEdges + topo.degenerateTriangles, 0u);
  applyCreaseAngle(m, 30);
  EXPECT_TRUE(m.positions.empty());
}

// ---- applyCreaseAngle ----

TEST(MeshTopology, CreaseAngleSplitsTheCubeIntoFaces) {
  Mesh m = makeCube();
  const Mesh before = m;
  ASSERT_EQ(m.positions.size(), 8u);
  EXPECT_EQ(buildTopology(m).creaseEdges, 0u);   // one averaged normal per corner: nothing is sharp
  applyCreaseAngle(m, 40);
  EXPECT_EQ(m.positions.size(), 24u);   // three fans (faces) at each corner
  EXPECT_EQ(m.normals.size(), 24u);
  EXPECT_EQ(m.weldId.size(), 24u);
  EXPECT_EQ(distinctWelds(m), 8u);
  ASSERT_EQ(m.triangles.size(), 12u);
  for (size_t v = 0; v < 8; ++v) EXPECT_EQ(m.positions[v], before.positions[v]);   // kept in place
  for (size_t t = 0; t < 12; ++t) {
    const auto& tri = m.triangles[t];
    glm::dvec3 fn = glm::normalize(glm::cross(m.positions[tri[1]] - m.positions[tri[0]], m.positions[tri[2]] - m.positions[tri[0]]));
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(m.positions[tri[c]], before.positions[before.triangles[t][c]]);
      EXPECT_EQ(m.weldId[tri[c]], before.weldId[before.triangles[t][c]]);
      EXPECT_NEAR(glm::length(m.normals[tri[c]] - fn), 0.0, 1e-15);   // the face normal
    }
  }
  MeshTopology topo = buildTopology(m);
  expectConsistent(m, topo);
  EXPECT_EQ(countNeighbours(topo), 36u);
  EXPECT_EQ(topo.creaseEdges, 12u);
  for (size_t t = 0; t < 12; ++t)
    for (int e = 0; e < 3; ++e) {
      const auto& tri = m.triangles[t];
      bool diagonal = glm::length(m.positions[tri[e]] - m.positions[tri[(e + 1) % 3]]) > 2.5;
      EXPECT_EQ(topo.creaseSlot[t][2 * e + 1], diagonal ? 0 : 1);
      EXPECT_EQ(topo.creaseSlot[t][2 * ((e + 1) % 3)], diagonal ? 0 : 1);
    }
  // Applying it again changes nothing: the fans are already separate vertices.
  Mesh again = m;
  applyCreaseAngle(again, 40);
  EXPECT_EQ(again.positions.size(), 24u);
  EXPECT_EQ(again.triangles, m.triangles);
}

TEST(MeshTopology, CreaseAngleAboveTheDihedralKeepsTheCubeSmooth) {
  Mesh m = makeCube();
  const Mesh before = m;
  applyCreaseAngle(m, 91);   // the cube's dihedral angles are 90 degrees
  EXPECT_EQ(m.positions.size(), 8u);
  EXPECT_EQ(m.triangles, before.triangles);
  for (size_t v = 0; v < 8; ++v) EXPECT_EQ(m.normals[v], before.normals[v]);   // bit for bit
}

TEST(MeshTopology, CreaseAngleLeavesFileNormalsAlone) {
  Mesh m = load("cube.obj");
  ASSERT_TRUE(m.normalsFromFile);
  const Mesh before = m;
  applyCreaseAngle(m, 10);
  EXPECT_EQ(m.positions.size(), before.positions.size());
  EXPECT_EQ(m.normals, before.normals);
  EXPECT_EQ(m.triangles, before.triangles);
}

TEST(MeshTopology, CreaseAngleKeepsASmoothSphereUnsplit) {
  // The shared sphere without its normals: positions welded, normals computed.
  Mesh file = load("sphere.obj");
  std::vector<glm::dvec3> positions(distinctWelds(file));
  for (size_t v = 0; v < file.positions.size(); ++v) positions[file.weldId[v]] = file.positions[v];
  std::vector<std::array<uint32_t, 3>> triangles;
  for (const auto& t : file.triangles) triangles.push_back({file.weldId[t[0]], file.weldId[t[1]], file.weldId[t[2]]});
  Mesh m = makeMesh(positions, triangles);
  const Mesh before = m;
  applyCreaseAngle(m, 40);
  EXPECT_EQ(m.positions.size(), before.positions.size());
  EXPECT_EQ(m.triangles, before.triangles);
  for (size_t v = 0; v < m.positions.size(); ++v) EXPECT_EQ(m.normals[v], before.normals[v]) << v;   // bit for bit
  MeshTopology topo = buildTopology(m);
  expectConsistent(m, topo);
  EXPECT_EQ(topo.creaseEdges, 0u);
  EXPECT_EQ(topo.boundaryEdges, 0u);
  // At 1 degree every edge of the coarse sphere is a crease: every triangle becomes its own fan.
  Mesh faceted = before;
  applyCreaseAngle(faceted, 1);
  EXPECT_EQ(faceted.positions.size(), 3 * faceted.triangles.size());
  EXPECT_EQ(buildTopology(faceted).creaseEdges, 3 * faceted.triangles.size() / 2);
}

TEST(MeshTopology, CreaseAngleEndsFansAtBoundariesAndCreases) {
  // A strip of four triangles folded by 90 degrees along the middle edge (1,4):
  //   3---4---5      z
  //   | / | \ |      the right half is bent up about the line x = 1
  //   0---1---2
  Mesh m = makeMesh({{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 1, 0}, {1, 1, 0}, {1, 1, 1}},
                    {{0, 1, 4}, {0, 4, 3}, {1, 2, 4}, {2, 5, 4}});
  applyCreaseAngle(m, 45);
  // Vertices 1 and 4 lie on the crease: each splits into two; the others have one fan.
  EXPECT_EQ(m.positions.size(), 8u);
  EXPECT_EQ(distinctWelds(m), 6u);
  MeshTopology topo = buildTopology(m);
  expectConsistent(m, topo);
  EXPECT_EQ(topo.creaseEdges, 1u);
  EXPECT_EQ(topo.boundaryEdges, 6u);
  for (const auto& t : std::vector<size_t>{0, 1})
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(glm::length(m.normals[m.triangles[t][c]] - glm::dvec3(0, 0, 1)), 0, 1e-15);
  for (const auto& t : std::vector<size_t>{2, 3})
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(glm::length(m.normals[m.triangles[t][c]] - glm::dvec3(-1, 0, 0)), 0, 1e-15);
}

TEST(MeshTopology, CreaseAngleCopiesPatchData) {
  Mesh m = makeCube();
  m.vertexPatch.resize(8);
  m.vertexUV.resize(8);
  for (uint32_t v = 0; v < 8; ++v) {
    m.vertexPatch[v] = v;
    m.vertexUV[v] = glm::dvec2(v, -double(v));
  }
  applyCreaseAngle(m, 40);
  ASSERT_EQ(m.vertexPatch.size(), 24u);
  ASSERT_EQ(m.vertexUV.size(), 24u);
  for (size_t v = 0; v < 24; ++v) {
    EXPECT_EQ(m.vertexPatch[v], m.weldId[v]);   // cube positions are welded in order 0..7
    EXPECT_EQ(m.vertexUV[v], glm::dvec2(m.weldId[v], -double(m.weldId[v])));
  }
}

}  // namespace

// ---- the default rule, kCreaseAngleAuto (tools/crease_survey.py measures it on real meshes) ----

namespace {

// A closed ring-by-ring grid: `rows` x `cols` quads of positions p(i, j), two triangles each.
Mesh makeGrid(int rows, int cols, bool wrapRows, const std::function<glm::dvec3(int, int)>& p) {
  std::vector<glm::dvec3> positions;
  const int ringRows = wrapRows ? rows : rows + 1;
  for (int i = 0; i < ringRows; ++i)
    for (int j = 0; j < cols; ++j) positions.push_back(p(i, j));
  std::vector<std::array<uint32_t, 3>> triangles;
  auto id = [&](int i, int j) { return uint32_t((i % ringRows) * cols + j % cols); };
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) {
      triangles.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
      triangles.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
    }
  return makeMesh(positions, triangles);
}

// The demo's hexagonal prism (tools/make_test_data.py) without its normals: 6 sides of 3 segments,
// flat caps; 18 side edges of 60 degrees, 12 rim edges of 90, everything else flat.
Mesh makePrism() {
  const double pi = std::numbers::pi;
  Mesh side = makeGrid(3, 6, false, [&](int s, int k) {
    return glm::dvec3(0.5 * std::cos(2 * pi * k / 6), 0.5 * std::sin(2 * pi * k / 6), -1.5 + s);
  });
  std::vector<glm::dvec3> positions = side.positions;
  std::vector<std::array<uint32_t, 3>> triangles = side.triangles;
  positions.push_back({0, 0, 1.5});
  positions.push_back({0, 0, -1.5});
  const uint32_t top = 24, bottom = 25;
  for (uint32_t k = 0; k < 6; ++k) {
    triangles.push_back({top, 18 + k, 18 + (k + 1) % 6});
    triangles.push_back({bottom, (k + 1) % 6, k});
  }
  return makeMesh(positions, triangles);
}

// A torus of n x n quads (R = 1, r = 0.4): at n = 8 its edges bend by 18 to 48 degrees, all smooth.
Mesh makeTorus(int n) {
  const double pi = std::numbers::pi;
  return makeGrid(n, n, true, [&](int i, int j) {
    const double a = 2 * pi * i / n, b = 2 * pi * j / n;
    return glm::dvec3((1 + 0.4 * std::cos(b)) * std::cos(a), (1 + 0.4 * std::cos(b)) * std::sin(a), 0.4 * std::sin(b));
  });
}

size_t creasesOf(Mesh m, double creaseAngleDeg) {
  applyCreaseAngle(m, creaseAngleDeg);
  MeshTopology topo = buildTopology(m);
  expectConsistent(m, topo);
  return topo.creaseEdges;
}

}  // namespace

TEST(MeshTopology, AutoCreaseRule) {
  const double flat[4] = {0, 0, 0, 0}, bent[4] = {0, 0, 18, 18}, creased[4] = {90, 0, 90, 0};
  EXPECT_FALSE(autoCrease(40, flat));     // at most the old default's 40: never
  EXPECT_TRUE(autoCrease(40.5, flat));    // between flat faces
  EXPECT_FALSE(autoCrease(48, bent));     // its neighbours bend too (the coarse torus)
  EXPECT_TRUE(autoCrease(60, bent));      // 3 times theirs or more
  EXPECT_TRUE(autoCrease(60, creased));   // next to other creases (the prism's side edges by its rim)
  const double tube[4] = {70, 70, 70, 70};
  EXPECT_FALSE(autoCrease(70, tube));
  EXPECT_TRUE(autoCrease(80, tube));      // sharp whatever its neighbours do
}

TEST(MeshTopology, AutoCreaseKeepsCadEdgesSharp) {
  EXPECT_EQ(creasesOf(makeCube(), kCreaseAngleAuto), 12u);
  EXPECT_EQ(creasesOf(makePrism(), kCreaseAngleAuto), 30u);   // every side and rim edge
  EXPECT_EQ(creasesOf(makePrism(), 70), 12u);   // a fixed 70 loses the 60-degree side edges
}

TEST(MeshTopology, AutoCreaseKeepsCoarseCurvedSurfacesSmooth) {
  Mesh torus = makeTorus(8);
  EXPECT_EQ(creasesOf(torus, kCreaseAngleAuto), 0u);
  EXPECT_EQ(creasesOf(torus, 40), 96u);   // explicit 40: as before, the 45-degree edges are creases
  Mesh m = torus;
  applyCreaseAngle(m, kCreaseAngleAuto);
  EXPECT_EQ(m.positions, torus.positions);   // nothing split, normals bit for bit the computed ones
  EXPECT_EQ(m.normals, torus.normals);
  EXPECT_EQ(creasesOf(makeTorus(6), kCreaseAngleAuto), 0u);
}
