// The weld of smooth and accurate output by topology (patch_output.h weldPatchVertices): a
// non-manifold fin stays one edge of three sheets, a closed box with a sliver stays closed, an open
// edge stays open, and nothing else opens; edges counted by exact position bits.
#include <gtest/gtest.h>

#include <array>
#include <map>
#include <set>

#include <sffd/sffd.h>

#include "backends/backend_test_support.h"
#include "model/mesh.h"
#include "pipelines/deformer_internal.h"

namespace {

using namespace sffd;

Mesh meshOf(std::vector<glm::dvec3> positions, std::vector<std::array<uint32_t, 3>> triangles) {
  Mesh m;
  m.positions = std::move(positions);
  m.triangles = std::move(triangles);
  for (uint32_t v = 0; v < m.positions.size(); ++v) m.weldId.push_back(v);
  computeVertexNormals(m);
  return m;
}

// Three triangles on the edge (0,0,0)-(1,0,0).
Mesh fin() {
  return meshOf({{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -0.5, 0.8}, {0.5, -0.5, -0.8}}, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
}

// The unit cube, its top face a sliver (area 5e-9) along the edge y = 0 and three triangles: closed.
Mesh sliverBox() {
  return meshOf({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, {0.5, 1e-8, 1}},
                {{0, 2, 1}, {0, 3, 2}, {0, 1, 5}, {0, 5, 4}, {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7},
                 {4, 5, 8}, {4, 8, 7}, {8, 5, 6}, {8, 6, 7}});
}

struct EdgeCounts {
  size_t boundary = 0, nonManifold = 0;
};

// Edges by the exact bits of their end positions (what a position-deduplicating writer sees).
EdgeCounts countEdges(const Mesh& m) {
  std::map<std::array<double, 3>, uint32_t> id;
  std::vector<uint32_t> pid;
  for (const auto& p : m.positions) pid.push_back(id.emplace(std::array<double, 3>{p.x, p.y, p.z}, uint32_t(id.size())).first->second);
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (const auto& t : m.triangles)
    for (int c = 0; c < 3; ++c) {
      const uint32_t a = pid[t[c]], b = pid[t[(c + 1) % 3]];
      if (a != b) ++uses[{std::min(a, b), std::max(a, b)}];
    }
  EdgeCounts n;
  for (const auto& [e, k] : uses) n.boundary += k == 1, n.nonManifold += k > 2;
  return n;
}

// Segments of the tessellation along input edges used by one triangle (boundary) and by more than two
// (non-manifold), counted in one of their patches each: what the output must have.
EdgeCounts expectedEdges(const Mesh& input, const PatchVertices& pv) {
  std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> users;
  for (uint32_t t = 0; t < input.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const uint32_t a = input.weldId[input.triangles[t][c]], b = input.weldId[input.triangles[t][(c + 1) % 3]];
      users[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  const std::vector<uint32_t> local = tessTriangles(pv.level);
  const size_t nv = size_t(tessVertexCount(pv.level));
  EdgeCounts n;
  for (size_t p = 0; p < pv.patchCount(); ++p)
    for (size_t i = 0; i < local.size(); i += 3)
      for (int c = 0; c < 3; ++c) {
        const double* l0 = &pv.lamParent[3 * (p * nv + local[i + c])];
        const double* l1 = &pv.lamParent[3 * (p * nv + local[i + (c + 1) % 3])];
        for (int z = 0; z < 3; ++z) {
          if (l0[z] != 0 || l1[z] != 0) continue;   // not both on the parent edge opposite corner z
          const auto& tri = input.triangles[pv.parent[p]];
          const uint32_t a = input.weldId[tri[(z + 1) % 3]], b = input.weldId[tri[(z + 2) % 3]];
          const std::vector<uint32_t>& u = users[{std::min(a, b), std::max(a, b)}];
          if (u.size() == 1) ++n.boundary;
          else if (u.size() > 2 && u.front() == pv.parent[p]) ++n.nonManifold;
        }
      }
  return n;
}

void expectWelded(const Mesh& mesh, Method method, const std::string& device, EdgeCounts input,
                  Precision precision = Precision::Auto) {
  Lattice lattice = fitLattice(mesh, {5, 5, 5}, {2, 2, 2});
  applyLatticePreset(lattice, "twist", 0.3);
  DeviceRequest request;
  request.name = device;
  Device d = Device::open(request);
  DeformOptions o;
  o.method = method;
  o.strict = true;
  o.tess = 3;
  o.precision = precision;
  Deformer deformer(d, mesh, lattice, o);
  deformer.deform(lattice);
  const Mesh out = deformer.result();
  std::map<uint32_t, glm::dvec3> at;   // one position a location, so the writers' position dedup keeps it one
  for (size_t v = 0; v < out.positions.size(); ++v) EXPECT_EQ(at.emplace(out.weldId[v], out.positions[v]).first->second, out.positions[v]);
  const EdgeCounts got = countEdges(out), want = expectedEdges(deformer.internal().input, *deformer.internal().run->patchVertices());
  EXPECT_EQ(got.boundary, want.boundary);
  EXPECT_EQ(got.nonManifold, want.nonManifold);
  EXPECT_EQ(want.boundary > 0, input.boundary > 0);
  EXPECT_EQ(want.nonManifold > 0, input.nonManifold > 0);
}

// The CPU reference and the required devices that `among` names.
std::vector<std::string> devices(std::set<std::string> among = {"cpu", "vulkan", "gl-egl", "gl-osmesa"}) {
  std::vector<std::string> d{"cpu"};
  for (const std::string& n : sffd::testing::requiredBackends())
    if (n != "cpu" && among.count(n)) d.push_back(n);
  return d;
}

TEST(PatchWeld, FinStaysOneNonManifoldEdge) {
  for (const std::string& device : devices())
    for (Method method : {Method::Smooth, Method::Accurate}) {
      SCOPED_TRACE(device + (method == Method::Smooth ? " smooth" : " accurate"));
      expectWelded(fin(), method, device, {6, 1});
    }
}

// In double: the sliver's tessellation points are 1e-9 apart, below float's resolution at 1.
TEST(PatchWeld, SliverBoxStaysClosed) {
  for (const std::string& device : devices({"cpu", "vulkan"}))
    for (Method method : {Method::Smooth, Method::Accurate}) {
      SCOPED_TRACE(device + (method == Method::Smooth ? " smooth" : " accurate"));
      expectWelded(sliverBox(), method, device, {0, 0}, Precision::Double);
    }
}

TEST(PatchWeld, ClosedSphereStaysClosed) {
  const Mesh sphere = readMesh(std::string(SFFD_TEST_DATA) + "/sphere.obj");
  for (Method method : {Method::Smooth, Method::Accurate}) {
    SCOPED_TRACE(method == Method::Smooth ? "smooth" : "accurate");
    expectWelded(sphere, method, "cpu", {0, 0});
  }
}

}  // namespace
