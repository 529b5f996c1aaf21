// Knot-box clipping (knot_box_clip.h, METHOD.md 2.1): the pieces tile each parent (area, winding),
// each lies in one knot box, vertex descriptions are consistent, and shared parent edges are cut at
// bitwise-identical places from both sides (no cracks, no T-junctions). Statistics for rabbit_cym.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <map>
#include <numbers>
#include <random>

#include "kernels/clip/knot_box_clip.h"
#include "model/lattice.h"
#include "model/mesh.h"
#include "model/mesh_topology.h"

using namespace sffd;

namespace {

const std::string kData = SFFD_TEST_DATA;

Mesh load(const std::string& name) { return readMesh(kData + "/" + name); }

// The paper's lattice shape: 5x5x5 control points, degree 2, over the mesh's bounding box.
Lattice boxLattice(const Mesh& m) {
  glm::dvec3 lo = m.positions[0], hi = lo;
  for (const auto& p : m.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return makeIdentityLattice(lo, hi, {5, 5, 5}, {2, 2, 2});
}

glm::dvec3 param(const Lattice& L, const glm::dvec3& x) { return L.frameLinear * x + L.frameOffset; }

// Distinct knot values of axis a from the domain's start to its end: the box boundaries.
std::vector<double> breaks(const Lattice& L, int a) {
  std::vector<double> b;
  for (double k : L.knots[a])
    if (k >= L.domainLo(a) && k <= L.domainHi(a) && (b.empty() || b.back() != k)) b.push_back(k);
  return b;
}

double det3(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) { return glm::dot(a, glm::cross(b, c)); }

bool isCorner(SubVertexKind k) { return k <= SubVertexKind::Corner2; }
bool isEdge(SubVertexKind k) { return k >= SubVertexKind::Edge0 && k <= SubVertexKind::Edge2; }

// Position along parent edge e, from its lower-weldId endpoint, of a sub-vertex on that edge (-1: not on it).
double edgeParam(const Mesh& m, size_t parent, int e, const SubVertex& v) {
  const auto& tri = m.triangles[parent];
  const int a = e, b = (e + 1) % 3;
  const int lo = m.weldId[tri[a]] <= m.weldId[tri[b]] ? a : b;
  if (v.kind == SubVertexKind(int(SubVertexKind::Edge0) + e)) return v.t;
  if (v.kind == SubVertexKind(int(SubVertexKind::Corner0) + a) || v.kind == SubVertexKind(int(SubVertexKind::Corner0) + b)) {
    const int c = int(v.kind) - int(SubVertexKind::Corner0);
    return c == lo ? 0.0 : 1.0;
  }
  return -1;
}

double minAngleDeg(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 p[3] = {a, b, c};
  double best = 180;
  for (int i = 0; i < 3; ++i) {
    glm::dvec3 e1 = p[(i + 1) % 3] - p[i], e2 = p[(i + 2) % 3] - p[i];
    best = std::min(best, std::atan2(glm::length(glm::cross(e1, e2)), glm::dot(e1, e2)) * 180 / std::numbers::pi);
  }
  return best;
}

struct ClipStats {
  size_t subTriangles = 0, sharedEdgesChecked = 0;
  double minAngle = 180, parentMinAngle = 180;
  size_t below1deg = 0, below01deg = 0;
};

// Checks every property of a clipping result; returns statistics.
ClipStats checkClip(const Mesh& m, const Lattice& L, const std::vector<SubTriangle>& subs) {
  ClipStats st;
  st.subTriangles = subs.size();
  const size_t T = m.triangles.size();
  std::array<std::vector<double>, 3> br;
  for (int a = 0; a < 3; ++a) br[a] = breaks(L, a);

  std::vector<double> lamArea(T, 0.0), worldArea(T, 0.0);
  std::vector<std::array<bool, 3>> cornerSeen(T, {false, false, false});
  // Per (parent, edge): the t values of its edge vertices, and its sub-edges as [t0, t1] intervals.
  std::map<std::pair<size_t, int>, std::vector<double>> edgeTs;
  std::map<std::pair<size_t, int>, std::vector<std::pair<double, double>>> edgeSegments;

  uint32_t lastParent = 0;
  for (const SubTriangle& s : subs) {
    if (s.parent >= T) {
      ADD_FAILURE() << "parent " << s.parent << " out of range";
      return st;
    }
    EXPECT_GE(s.parent, lastParent) << "sub-triangles come in parent order";
    lastParent = s.parent;
    const auto& tri = m.triangles[s.parent];
    const glm::dvec3 V[3] = {m.positions[tri[0]], m.positions[tri[1]], m.positions[tri[2]]};
    const glm::dvec3 P[3] = {param(L, V[0]), param(L, V[1]), param(L, V[2])};

    // Vertex descriptions.
    for (const SubVertex& v : s.corners) {
      if (isCorner(v.kind)) {
        int c = int(v.kind) - int(SubVertexKind::Corner0);
        glm::dvec3 unit(0.0);
        unit[c] = 1;
        EXPECT_EQ(v.lam, unit);
        cornerSeen[s.parent][c] = true;
      } else if (isEdge(v.kind)) {
        int e = int(v.kind) - int(SubVertexKind::Edge0);
        int a = e, b = (e + 1) % 3, other = (e + 2) % 3;
        int lo = m.weldId[tri[a]] <= m.weldId[tri[b]] ? a : b, hi = lo == a ? b : a;
        EXPECT_GE(v.t, 0.0);
        EXPECT_LE(v.t, 1.0);
        EXPECT_EQ(v.lam[other], 0.0);
        EXPECT_EQ(v.lam[lo], 1.0 - v.t);
        EXPECT_EQ(v.lam[hi], v.t);
        edgeTs[{s.parent, e}].push_back(v.t);
      } else {
        EXPECT_EQ(v.kind, SubVertexKind::Interior);
        for (int i = 0; i < 3; ++i) EXPECT_GE(v.lam[i], -1e-15);
        EXPECT_NEAR(v.lam[0] + v.lam[1] + v.lam[2], 1.0, 1e-13);
      }
    }

    // Winding and area: the barycentric determinant is the sub-triangle's share of the parent.
    const double share = det3(s.corners[0].lam, s.corners[1].lam, s.corners[2].lam);
    EXPECT_GT(share, 0.0) << "parent " << s.parent;
    lamArea[s.parent] += share;
    glm::dvec3 x[3], p[3];
    for (int i = 0; i < 3; ++i) {
      const glm::dvec3& l = s.corners[i].lam;
      x[i] = l[0] * V[0] + l[1] * V[1] + l[2] * V[2];
      p[i] = l[0] * P[0] + l[1] * P[1] + l[2] * P[2];
    }
    const glm::dvec3 parentCross = glm::cross(V[1] - V[0], V[2] - V[0]);
    const glm::dvec3 subCross = glm::cross(x[1] - x[0], x[2] - x[0]);
    EXPECT_GE(glm::dot(subCross, parentCross), 0.0);
    worldArea[s.parent] += 0.5 * glm::length(subCross);
    double angle = minAngleDeg(x[0], x[1], x[2]);
    st.minAngle = std::min(st.minAngle, angle);
    st.below1deg += angle < 1;
    st.below01deg += angle < 0.1;

    // One knot box: the one holding the centroid, with all three corners in its closed bounds.
    const glm::dvec3 centroid = (p[0] + p[1] + p[2]) / 3.0;
    for (int a = 0; a < 3; ++a) {
      size_t box = size_t(std::upper_bound(br[a].begin(), br[a].end(), centroid[a]) - br[a].begin());
      box = std::clamp<size_t>(box, 1, br[a].size() - 1) - 1;
      double lo = box == 0 ? -INFINITY : br[a][box], hi = box + 2 == br[a].size() ? INFINITY : br[a][box + 1];
      const double tol = 1e-12 * std::max(1.0, std::abs(br[a].back() - br[a].front()));
      for (int i = 0; i < 3; ++i) {
        EXPECT_GE(p[i][a], lo - tol) << "parent " << s.parent << " axis " << a;
        EXPECT_LE(p[i][a], hi + tol) << "parent " << s.parent << " axis " << a;
      }
    }

    // Sub-edges lying on a parent edge.
    for (int i = 0; i < 3; ++i)
      for (int e = 0; e < 3; ++e) {
        double t0 = edgeParam(m, s.parent, e, s.corners[i]), t1 = edgeParam(m, s.parent, e, s.corners[(i + 1) % 3]);
        if (t0 >= 0 && t1 >= 0) edgeSegments[{s.parent, e}].push_back({std::min(t0, t1), std::max(t0, t1)});
      }
  }

  // Tiling: shares sum to one, world areas to the parent's area; every corner survives.
  for (size_t t = 0; t < T; ++t) {
    const auto& tri = m.triangles[t];
    const glm::dvec3 V[3] = {m.positions[tri[0]], m.positions[tri[1]], m.positions[tri[2]]};
    const double area = 0.5 * glm::length(glm::cross(V[1] - V[0], V[2] - V[0]));
    st.parentMinAngle = std::min(st.parentMinAngle, minAngleDeg(V[0], V[1], V[2]));
    EXPECT_NEAR(lamArea[t], 1.0, 1e-9) << "parent " << t;
    EXPECT_NEAR(worldArea[t], area, 1e-9 * area) << "parent " << t;
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(cornerSeen[t][c]) << "parent " << t << " corner " << c;
    // Along each parent edge the sub-edges chain from 0 to 1 without gaps or overlaps.
    for (int e = 0; e < 3; ++e) {
      auto segs = edgeSegments[{t, e}];
      std::sort(segs.begin(), segs.end());
      if (segs.empty()) {
        ADD_FAILURE() << "parent " << t << " edge " << e << ": no sub-edges";
        continue;
      }
      EXPECT_EQ(segs.front().first, 0.0);
      EXPECT_EQ(segs.back().second, 1.0);
      for (size_t i = 0; i + 1 < segs.size(); ++i) EXPECT_EQ(segs[i].second, segs[i + 1].first) << "parent " << t << " edge " << e;
    }
  }

  // Crack-free: both triangles of a shared edge hold the same cut points, bit for bit, and the same sub-edges.
  MeshTopology topo = buildTopology(m);
  for (size_t t = 0; t < T; ++t)
    for (int e = 0; e < 3; ++e) {
      const int32_t u = topo.neighbour[t][e];
      if (u < 0 || size_t(u) < t) continue;
      const int f = topo.neighbourEdge[t][e];
      auto bits = [&](size_t tri, int edge) {
        std::vector<uint64_t> b;
        for (double x : edgeTs[{tri, edge}]) b.push_back(std::bit_cast<uint64_t>(x));
        std::sort(b.begin(), b.end());
        b.erase(std::unique(b.begin(), b.end()), b.end());
        return b;
      };
      EXPECT_EQ(bits(t, e), bits(size_t(u), f)) << "triangles " << t << " and " << u;
      auto segs = [&](size_t tri, int edge) {
        auto s = edgeSegments[{tri, edge}];
        std::sort(s.begin(), s.end());
        return s;
      };
      EXPECT_EQ(segs(t, e), segs(size_t(u), f)) << "triangles " << t << " and " << u;
      ++st.sharedEdgesChecked;
    }
  return st;
}

void printStats(const std::string& name, size_t parents, const ClipStats& st, double ms) {
  std::cout << "[ stats    ] " << name << ": " << parents << " triangles -> " << st.subTriangles << " sub-triangles, min angle "
            << st.minAngle << " deg (parents " << st.parentMinAngle << "), " << st.below1deg << " below 1 deg, "
            << st.below01deg << " below 0.1 deg, " << st.sharedEdgesChecked << " shared edges crack-free, clip " << ms
            << " ms\n";
}

void runModel(const std::string& name) {
  Mesh m = load(name);
  Lattice L = boxLattice(m);
  auto t0 = std::chrono::steady_clock::now();
  std::vector<SubTriangle> subs = clipAgainstKnotBoxes(m, L);
  double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ClipStats st = checkClip(m, L, subs);
  EXPECT_GT(st.sharedEdgesChecked, 0u);
  EXPECT_GT(subs.size(), m.triangles.size());
  printStats(name, m.triangles.size(), st, ms);
}

TEST(KnotBoxClip, Cube2) {
  Mesh m = load("cube2.obj");
  Lattice L = boxLattice(m);
  std::vector<SubTriangle> subs = clipAgainstKnotBoxes(m, L);
  ClipStats st = checkClip(m, L, subs);
  EXPECT_EQ(st.sharedEdgesChecked, 18u);   // crease edges included: adjacency is by weldId
  // Each face is cut into 3x3 squares, two triangles each. The face diagonals pass exactly through
  // grid points, where two planes meet: no twin points, no slivers.
  EXPECT_EQ(subs.size(), 6u * 9u * 2u);
  EXPECT_NEAR(st.minAngle, 45.0, 1e-9);
  printStats("cube2.obj", m.triangles.size(), st, 0);
}

TEST(KnotBoxClip, Sphere) { runModel("sphere.obj"); }

TEST(KnotBoxClip, RabbitStatistics) { runModel("torus.obj"); }

TEST(KnotBoxClip, RotatedFrame) {
  // The clipping happens in parameter space: a rotated, scaled, shifted frame moves the planes.
  Mesh m = load("sphere.obj");
  Lattice L;
  const double c = std::cos(0.5), s = std::sin(0.5);
  L.frameLinear = glm::dmat3(glm::dvec3(c, s, 0), glm::dvec3(-s, c, 0), glm::dvec3(0, 0, 1)) * 1.7;
  L.frameOffset = glm::dvec3(0.3, -0.2, 0.1);
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const auto& p : m.positions) {
    lo = glm::min(lo, param(L, p));
    hi = glm::max(hi, param(L, p));
  }
  L.degree = {2, 3, 1};
  L.counts = {5, 6, 4};
  for (int a = 0; a < 3; ++a) L.knots[a] = clampedUniformKnots(L.counts[a], L.degree[a], lo[a], hi[a]);
  std::vector<SubTriangle> subs = clipAgainstKnotBoxes(m, L);
  ClipStats st = checkClip(m, L, subs);
  printStats("sphere.obj, rotated frame", m.triangles.size(), st, 0);
}

TEST(KnotBoxClip, NoInteriorKnotsLeavesTrianglesWhole) {
  Mesh m = load("cube2.obj");
  Lattice L = makeIdentityLattice(glm::dvec3(-1), glm::dvec3(1), {3, 3, 3}, {2, 2, 2});   // one knot box
  std::vector<SubTriangle> subs = clipAgainstKnotBoxes(m, L);
  ASSERT_EQ(subs.size(), m.triangles.size());
  for (size_t t = 0; t < subs.size(); ++t) {
    EXPECT_EQ(subs[t].parent, t);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(subs[t].corners[c].kind, SubVertexKind(int(SubVertexKind::Corner0) + c));
  }
}

// A lattice over [0,3]^3 whose interior knots are exactly 1 and 2 on every axis.
Lattice unitKnotLattice() { return makeIdentityLattice(glm::dvec3(0), glm::dvec3(3), {5, 5, 5}, {2, 2, 2}); }

Mesh triangleMesh(std::vector<glm::dvec3> p) {
  Mesh m;
  m.positions = std::move(p);
  for (uint32_t i = 0; i + 2 < m.positions.size(); i += 3) m.triangles.push_back({i, i + 1, i + 2});
  weldPositions(m);
  computeVertexNormals(m);
  return m;
}

TEST(KnotBoxClip, PlanesThroughCornersAndAlongEdgesMakeNoSlivers) {
  const Lattice L = unitKnotLattice();
  struct Case {
    const char* what;
    std::vector<glm::dvec3> tri;
    size_t expected;
  };
  const Case cases[] = {
      // x = 1 only touches corner 0; x = 2 cuts: a triangle and a quad.
      {"corner on a plane", {{1, 0.5, 0.5}, {2.5, 0.2, 0.5}, {2.5, 0.8, 0.5}}, 3},
      // edge (0,2) lies in x = 1, the rest is on one side: untouched.
      {"edge in a plane", {{1, 0.2, 0.5}, {1.5, 0.5, 0.5}, {1, 0.8, 0.5}}, 1},
      // the whole triangle lies in z = 1: only x = 2 cuts it.
      {"triangle in a plane", {{1.5, 0.2, 1}, {2.5, 0.2, 1}, {2.5, 0.8, 1}}, 3},
      // corner 0 on x = 1 and y = 1: x = 2 cuts it, then y = 1 through corner 0 cuts both pieces.
      {"corner on two planes", {{1, 1, 0.5}, {2.5, 0.5, 0.5}, {2.5, 1.5, 0.5}}, 6},
      // all three corners on knot planes, nothing inside crosses one: untouched.
      {"corners on planes", {{1, 1, 1}, {2, 1, 1}, {1, 2, 1}}, 1},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    Mesh m = triangleMesh(c.tri);
    std::vector<SubTriangle> subs = clipAgainstKnotBoxes(m, L);
    EXPECT_EQ(subs.size(), c.expected);
    checkClip(m, L, subs);
    // No two corners of a sub-triangle coincide, and no sub-triangle is a sliver.
    for (const SubTriangle& s : subs) {
      glm::dvec3 x[3];
      for (int i = 0; i < 3; ++i) {
        const glm::dvec3& l = s.corners[i].lam;
        x[i] = l[0] * m.positions[0] + l[1] * m.positions[1] + l[2] * m.positions[2];
      }
      EXPECT_GT(minAngleDeg(x[0], x[1], x[2]), 5.0);
    }
    // A point created twice (on a chord shared by two pieces) is the same point, bit for bit.
    std::vector<glm::dvec3> interior;
    for (const SubTriangle& s : subs)
      for (const SubVertex& v : s.corners)
        if (v.kind == SubVertexKind::Interior) interior.push_back(v.lam);
    for (const auto& a : interior)
      for (const auto& b : interior)
        if (glm::length(a - b) < 1e-9) {
          EXPECT_EQ(a, b);
        }
  }
}

TEST(KnotBoxClip, DegenerateTrianglesProduceNothing) {
  const Lattice L = unitKnotLattice();
  Mesh m = triangleMesh({{0.5, 0.5, 0.5}, {1.5, 1.5, 1.5}, {2.5, 2.5, 2.5},    // collinear across planes
                         {0.5, 0.5, 0.5}, {0.5, 0.5, 0.5}, {2.5, 0.5, 0.5}});  // a collapsed edge
  std::vector<SubTriangle> subs;
  ASSERT_NO_THROW(subs = clipAgainstKnotBoxes(m, L));
  EXPECT_TRUE(subs.empty());
}

TEST(KnotBoxClip, RandomHeightFieldWithVerticesOnPlanes) {
  // A height field over [0,3]^2 on a quarter grid, so that many vertices and whole edges lie on the
  // knot planes x, y = 1, 2; heights random, a third of them snapped onto z = 1 or 2. Repeated
  // knots on z (degree 3, a double knot) must count once.
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> height(0.0, 3.0);
  const int n = 12;
  Mesh m;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      double z = height(rng);
      if (rng() % 3 == 0) z = 1.0 + double(rng() % 2);
      m.positions.push_back({3.0 * i / n, 3.0 * j / n, z});
    }
  for (uint32_t i = 0; i < uint32_t(n); ++i)
    for (uint32_t j = 0; j < uint32_t(n); ++j) {
      uint32_t a = i * (n + 1) + j, b = a + (n + 1), c = b + 1, d = a + 1;
      if ((i + j) % 2) {
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({a, c, d});
      } else {
        m.triangles.push_back({a, b, d});
        m.triangles.push_back({b, c, d});
      }
    }
  weldPositions(m);
  computeVertexNormals(m);
  Lattice L = unitKnotLattice();
  L.degree[2] = 3;
  L.counts[2] = 7;
  L.knots[2] = {0, 0, 0, 0, 1, 2, 2, 3, 3, 3, 3};
  std::vector<SubTriangle> subs = clipAgainstKnotBoxes(m, L);
  ClipStats st = checkClip(m, L, subs);
  EXPECT_EQ(st.sharedEdgesChecked, size_t(3 * n * n - 2 * n));
  printStats("random height field", m.triangles.size(), st, 0);
}

TEST(KnotBoxClip, RandomFramesAndKnotsStayCrackFree) {
  // Random rotated and scaled frames, degrees 1..3 and non-uniform knots, some of them placed exactly
  // on vertex coordinates (planes through vertices, along edges when a mesh is axis-aligned).
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (const char* name : {"cube2.obj", "sphere.obj", "torus.obj"}) {
    const Mesh m = load(name);
    for (int round = 0; round < 4; ++round) {
      SCOPED_TRACE(std::string(name) + " round " + std::to_string(round));
      Lattice L;
      if (round > 0) {
        glm::dvec3 axis = glm::normalize(glm::dvec3(uni(rng) - 0.5, uni(rng) - 0.5, uni(rng) - 0.5));
        double angle = 3 * uni(rng), c = std::cos(angle), s = std::sin(angle);
        glm::dmat3 K(0, axis.z, -axis.y, -axis.z, 0, axis.x, axis.y, -axis.x, 0);   // cross-product matrix
        glm::dmat3 R = glm::dmat3(1.0) + s * K + (1 - c) * K * K;
        L.frameLinear = R * glm::dmat3(0.5 + uni(rng), 0, 0, 0, 0.5 + uni(rng), 0, 0, 0, 0.5 + uni(rng));
        L.frameOffset = glm::dvec3(uni(rng), uni(rng), uni(rng));
      }
      glm::dvec3 lo(1e300), hi(-1e300);
      for (const auto& p : m.positions) {
        lo = glm::min(lo, param(L, p));
        hi = glm::max(hi, param(L, p));
      }
      for (int a = 0; a < 3; ++a) {
        L.degree[a] = 1 + int(rng() % 3);
        std::vector<double> inner;
        const int n = 1 + int(rng() % 6);
        for (int i = 0; i < n; ++i) {
          // Half the knots at a vertex's coordinate, half anywhere.
          double k = rng() % 2 ? param(L, m.positions[rng() % m.positions.size()])[a] : lo[a] + (hi[a] - lo[a]) * uni(rng);
          if (k > lo[a] && k < hi[a]) inner.push_back(k);
        }
        std::sort(inner.begin(), inner.end());
        std::vector<double>& U = L.knots[a];
        U.assign(size_t(L.degree[a]) + 1, lo[a]);
        U.insert(U.end(), inner.begin(), inner.end());
        U.insert(U.end(), size_t(L.degree[a]) + 1, hi[a]);
        L.counts[a] = int(U.size()) - L.degree[a] - 1;
      }
      std::vector<SubTriangle> subs = clipAgainstKnotBoxes(m, L);
      checkClip(m, L, subs);
      if (::testing::Test::HasFailure()) return;
    }
  }
}

}  // namespace
