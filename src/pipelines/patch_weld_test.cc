// The weld of smooth and accurate output by topology (patch_output.h weldPatchVertices): a
// non-manifold fin stays one edge of three sheets, a closed box with a sliver stays closed, an open
// edge stays open, and nothing else opens; edges counted by exact position bits, and in the written
// files by their vertex indices.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <sstream>

#include <sffd/sffd.h>

#include "backends/backend_test_support.h"
#include "kernels/clip/knot_box_clip.h"
#include "model/mesh.h"
#include "pipelines/deformer_internal.h"
#include "pipelines/stream_budget.h"
#include "tests/support/cli_runner.h"

namespace {

using namespace sffd;
namespace fs = std::filesystem;

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

struct Deformed {
  Mesh out;
  EdgeCounts want;   // expectedEdges
};

Deformed deformTwisted(const Mesh& mesh, Method method, const std::string& device, Precision precision) {
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
  return {deformer.result(), expectedEdges(deformer.internal().input, *deformer.internal().run->patchVertices())};
}

void expectWelded(const Mesh& mesh, Method method, const std::string& device, EdgeCounts input,
                  Precision precision = Precision::Auto) {
  const auto [out, want] = deformTwisted(mesh, method, device, precision);
  std::map<uint32_t, glm::dvec3> at;   // one position a location, so the writers' position dedup keeps it one
  for (size_t v = 0; v < out.positions.size(); ++v) EXPECT_EQ(at.emplace(out.weldId[v], out.positions[v]).first->second, out.positions[v]);
  const EdgeCounts got = countEdges(out);
  EXPECT_EQ(got.boundary, want.boundary);
  EXPECT_EQ(got.nonManifold, want.nonManifold);
  EXPECT_EQ(want.boundary > 0, input.boundary > 0);
  EXPECT_EQ(want.nonManifold > 0, input.nonManifold > 0);
}

// Edges of a written .obj or .off by the file's vertex indices (what a reader that keeps the file's
// vertices sees), and the count of its vertices.
EdgeCounts countFileEdges(const fs::path& path, size_t& vertices) {
  std::ifstream in(path);
  std::string word;
  std::vector<std::array<uint32_t, 3>> faces;
  vertices = 0;
  if (path.extension() == ".off") {
    size_t nf = 0, ne = 0;
    in >> word >> vertices >> nf >> ne;
    double x;
    for (size_t i = 0; i < 3 * vertices; ++i) in >> x;
    faces.resize(nf);
    for (auto& f : faces) in >> ne >> f[0] >> f[1] >> f[2];
  } else {
    for (std::string line; std::getline(in, line);) {
      std::istringstream l(line);
      l >> word;
      vertices += word == "v";
      if (word != "f") continue;
      auto& f = faces.emplace_back();
      for (uint32_t& c : f) l >> word, c = uint32_t(std::stoul(word.substr(0, word.find('/')))) - 1;
    }
  }
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (const auto& t : faces)
    for (int c = 0; c < 3; ++c) ++uses[{std::min(t[c], t[(c + 1) % 3]), std::max(t[c], t[(c + 1) % 3])}];
  EdgeCounts n;
  for (const auto& [e, k] : uses) n.boundary += k == 1, n.nonManifold += k > 2;
  return n;
}

// The CPU reference and the devices here that `among` names.
std::vector<std::string> devices(std::set<std::string> among = {"cpu", "vulkan", "gl-egl", "gl-osmesa"}) {
  std::vector<std::string> d{"cpu"};
  for (const std::string& n : sffd::testing::backendsHere(sffd::testing::testBackends()))
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

// In float (smooth's default) the sliver's points, 1e-9 apart, round onto each other: by position bits
// its folded rows meet in non-manifold edges, but the OBJ and OFF files keep one vertex a location
// (Mesh::weldIdIsLocation), so by their vertex indices they stay closed and manifold.
TEST(PatchWeld, SliverBoxFileStaysClosedInFloat) {
  const fs::path dir = sffd::test::tempDir("patch_weld_sliver");
  for (const std::string& device : devices({"cpu", "vulkan"}))
    for (Method method : {Method::Smooth, Method::Accurate}) {
      SCOPED_TRACE(device + (method == Method::Smooth ? " smooth" : " accurate"));
      const auto [out, want] = deformTwisted(sliverBox(), method, device, Precision::Float);
      EXPECT_EQ(want.boundary + want.nonManifold, 0u);
      std::set<uint32_t> locations(out.weldId.begin(), out.weldId.end());
      for (const char* ext : {".obj", ".off"}) {
        SCOPED_TRACE(ext);
        size_t vertices = 0;
        writeMesh((dir / (std::string("o") + ext)).string(), out);
        const EdgeCounts got = countFileEdges(dir / (std::string("o") + ext), vertices);
        EXPECT_EQ(vertices, locations.size());
        EXPECT_EQ(got.boundary, want.boundary);
        EXPECT_EQ(got.nonManifold, want.nonManifold);
      }
    }
  fs::remove_all(dir);
}

TEST(PatchWeld, ClosedSphereStaysClosed) {
  const Mesh sphere = readMesh(std::string(SFFD_TEST_DATA) + "/sphere.obj");
  for (Method method : {Method::Smooth, Method::Accurate}) {
    SCOPED_TRACE(method == Method::Smooth ? "smooth" : "accurate");
    expectWelded(sphere, method, "cpu", {0, 0});
  }
}

void expectSameMesh(const Mesh& a, const Mesh& b) {
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.texcoords, b.texcoords);
  EXPECT_EQ(a.colors, b.colors);
  EXPECT_EQ(a.weldId, b.weldId);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.triangleMaterial, b.triangleMaterial);
  EXPECT_EQ(a.triangleGroup, b.triangleGroup);
  EXPECT_EQ(a.weldIdIsLocation, b.weldIdIsLocation);
  EXPECT_EQ(a.normalsFromFile, b.normalsFromFile);
}

// Patches [first, last) of `P` as a slice of their own.
PatchVertices sliceOf(const PatchVertices& P, size_t first, size_t last) {
  const size_t nv = size_t(tessVertexCount(P.level));
  auto part = [&](const auto& v, size_t perPatch) {
    using V = std::decay_t<decltype(v)>;
    return v.empty() ? V{} : V(v.begin() + first * perPatch, v.begin() + last * perPatch);
  };
  PatchVertices s;
  s.level = P.level;
  s.parent = part(P.parent, 1), s.material = part(P.material, 1), s.group = part(P.group, 1), s.parentWeld = part(P.parentWeld, 3);
  s.lamParent = part(P.lamParent, 3 * nv), s.position = part(P.position, 3 * nv), s.normal = part(P.normal, 3 * nv);
  s.texcoord = part(P.texcoord, 2 * nv), s.color = part(P.color, 4 * nv);
  return s;
}

// The sphere (it carries texture coordinates) twisted by `method` at level 3 on the CPU device: the
// Deformer, its patches' vertices and those welded at once.
struct TwistedSphere {
  std::unique_ptr<Device> device;   // outlives the Deformer
  std::unique_ptr<Deformer> deformer;
  PatchVertices P;
  Mesh whole;
};

TwistedSphere twistedSphere(Method method) {
  const Mesh sphere = readMesh(std::string(SFFD_TEST_DATA) + "/sphere.obj");
  EXPECT_FALSE(sphere.texcoords.empty());
  Lattice lattice = fitLattice(sphere, {5, 5, 5}, {2, 2, 2});
  applyLatticePreset(lattice, "twist", 0.3);
  TwistedSphere t;
  DeviceRequest request;
  request.name = "cpu";
  t.device = std::make_unique<Device>(Device::open(request));
  DeformOptions o;
  o.method = method;
  o.tess = 3;
  t.deformer = std::make_unique<Deformer>(*t.device, sphere, lattice, o);
  t.deformer->deform(lattice);
  t.P = *t.deformer->internal().run->patchVertices();
  t.whole = weldPatchVertices(t.P);
  EXPECT_GT(t.whole.triangles.size(), 0u);
  return t;
}

// The welds of the smooth and the accurate method's patches.
class PatchWeldOf : public ::testing::TestWithParam<Method> {};
INSTANTIATE_TEST_SUITE_P(Methods, PatchWeldOf, ::testing::Values(Method::Smooth, Method::Accurate),
                         [](const ::testing::TestParamInfo<Method>& m) { return m.param == Method::Smooth ? "smooth" : "accurate"; });

// A GPU that fuses multiply-adds gives a shared point's normal from two patches a few ulps apart: one
// vertex still; normals apart by more than rounding (a crease's) are two.
TEST_P(PatchWeldOf, NormalsApartByRoundingAreOneVertex) {
  const TwistedSphere t = twistedSphere(GetParam());
  const size_t nv = size_t(tessVertexCount(t.P.level));
  auto nudged = [&](double by) {
    PatchVertices P = t.P;
    for (size_t p = 1; p < P.patchCount(); p += 2)
      for (size_t i = 3 * nv * p; i < 3 * nv * (p + 1); ++i) P.normal[i] += by * (i % 3 == 0 ? 1 : -1);
    return weldPatchVertices(P);
  };
  const Mesh ulps = nudged(2.4e-7), apart = nudged(1e-3);   // 2 float ulps of 1; far beyond rounding
  EXPECT_EQ(ulps.normals.size(), t.whole.normals.size());
  EXPECT_EQ(ulps.triangles, t.whole.triangles);
  EXPECT_GT(apart.normals.size(), t.whole.normals.size());
  EXPECT_EQ(apart.positions.size(), apart.normals.size());
}

// The results weld the downloaded patches in slices (PatchWelder): the same mesh as all of them welded
// at once, whatever the slices.
TEST_P(PatchWeldOf, SlicesWeldAsOne) {
  const TwistedSphere t = twistedSphere(GetParam());
  const PatchVertices& P = t.P;
  expectSameMesh(t.deformer->result(), t.whole);
  for (size_t step : {size_t(1), size_t(7)}) {
    PatchWelder weld(P.level, P.patchCount());
    for (size_t first = 0; first < P.patchCount(); first += step) weld.add(sliceOf(P, first, std::min(P.patchCount(), first + step)));
    expectSameMesh(weld.finish(), t.whole);
  }
}

// A location shared by two patches whose positions there disagree (a fin, a sliver) takes the position of
// the lower parent's patch, whichever comes first: the vertices made there before it move with it.
TEST(PatchWeld, ALocationTakesTheLowerParentsPositionInEitherOrder) {
  const Mesh input = meshOf({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, {{0, 1, 2}, {2, 1, 3}});
  // Level 1: a patch's vertices are its corners, barycentrics (1,0,0), (0,1,0), (0,0,1).
  auto patches = [&](std::vector<uint32_t> parents) {
    PatchVertices P;
    P.level = 1;
    for (uint32_t parent : parents) {
      P.parent.push_back(parent);
      for (int c = 0; c < 3; ++c) {
        const uint32_t v = input.triangles[parent][c];
        // Parent 1 puts the shared corners (1 and 2) half a unit higher than parent 0 does.
        const glm::dvec3 x = input.positions[v] + glm::dvec3(0, 0, parent == 1 && v != 3 ? 0.5 : 0.0);
        for (int a = 0; a < 3; ++a) {
          P.lamParent.push_back(a == c ? 1.0 : 0.0);
          P.position.push_back(x[a]);
          P.normal.push_back(a == 2 ? 1.0 : 0.0);
        }
      }
    }
    carryAttributes(P, input);
    return P;
  };
  for (const std::vector<uint32_t>& order : {std::vector<uint32_t>{0, 1}, std::vector<uint32_t>{1, 0}}) {
    SCOPED_TRACE("parents " + std::to_string(order[0]) + ", " + std::to_string(order[1]));
    const Mesh m = weldPatchVertices(patches(order));
    ASSERT_EQ(m.positions.size(), 4u);
    ASSERT_EQ(m.triangles.size(), 2u);
    for (const glm::dvec3& x : m.positions) EXPECT_EQ(x.z, 0.0);   // parent 0's, at corners 1 and 2 too
  }
}

// What a streamed weld hands over, appended.
struct GatheringSink final : MeshSink {
  Mesh m;
  void add(const Mesh& piece, size_t firstVertex) override {
    EXPECT_EQ(firstVertex, m.positions.size());
    auto append = [](auto& to, const auto& from) { to.insert(to.end(), from.begin(), from.end()); };
    append(m.positions, piece.positions), append(m.normals, piece.normals), append(m.texcoords, piece.texcoords);
    append(m.colors, piece.colors), append(m.weldId, piece.weldId), append(m.triangles, piece.triangles);
    append(m.triangleMaterial, piece.triangleMaterial), append(m.triangleGroup, piece.triangleGroup);
  }
};

// A streamed weld that forgets the locations no later parent reaches (compacting as soon as it may here)
// hands over the mesh of one that keeps them all, holding far fewer.
TEST_P(PatchWeldOf, ForgettingPassedLocationsStreamsTheSameMesh) {
  const TwistedSphere t = twistedSphere(GetParam());
  const PatchVertices& P = t.P;
  GatheringSink sink;
  sink.m.normalsFromFile = sink.m.weldIdIsLocation = true;
  PatchWelder weld(P.level, P.patchCount(), &sink);
  weld.forgetPassedLocations(t.deformer->internal().input, 1);
  size_t mostHeld = 0;
  for (size_t first = 0; first < P.patchCount(); first += 7) {
    weld.add(sliceOf(P, first, std::min(P.patchCount(), first + 7)));
    mostHeld = std::max(mostHeld, weld.locationsHeld());
  }
  expectSameMesh(sink.m, t.whole);
  EXPECT_LT(mostHeld, t.whole.positions.size() / 2);
  EXPECT_THROW(weld.finish(), std::logic_error);
}

// What a streamed weld of t's patches holds at most, their parents renumbered by `rank` (the input's
// triangles in a new order) and the patches sorted by them, against the front `shapeOf` that order.
void expectFrontBounds(const TwistedSphere& t, const std::function<StreamShape(const Mesh&, const std::vector<uint32_t>&)>& shapeOf) {
  const Mesh& input = t.deformer->internal().input;
  std::vector<size_t> order(t.P.patchCount());
  for (size_t p = 0; p < order.size(); ++p) order[p] = p;
  const double sliceVertices = double(kWeldSlicePatches * size_t(tessVertexCount(t.P.level)));
  for (bool shuffled : {false, true}) {
    // A shuffled mesh's parents are numbered in the new order; its patches come sorted by them.
    Mesh mesh = input;
    std::vector<uint32_t> rank(input.triangles.size());
    for (uint32_t i = 0; i < rank.size(); ++i) rank[i] = i;
    if (shuffled) std::shuffle(rank.begin(), rank.end(), std::mt19937(5));
    for (uint32_t i = 0; i < rank.size(); ++i) mesh.triangles[rank[i]] = input.triangles[i];
    PatchVertices P = t.P;
    for (uint32_t& parent : P.parent) parent = rank[parent];
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return P.parent[a] < P.parent[b]; });
    PatchVertices sorted = sliceOf(P, 0, 0);
    for (size_t p : order) {
      const PatchVertices one = sliceOf(P, p, p + 1);
      auto append = [](auto& to, const auto& from) { to.insert(to.end(), from.begin(), from.end()); };
      append(sorted.parent, one.parent), append(sorted.parentWeld, one.parentWeld), append(sorted.lamParent, one.lamParent);
      append(sorted.position, one.position), append(sorted.normal, one.normal);
    }
    const StreamShape shape = shapeOf(mesh, rank);
    GatheringSink sink;
    PatchWelder weld(P.level, P.patchCount(), &sink);
    weld.forgetPassedLocations(mesh, 1);
    size_t mostHeld = 0;
    for (size_t first = 0; first < sorted.patchCount(); first += kWeldSlicePatches) {
      weld.add(sliceOf(sorted, first, std::min(sorted.patchCount(), first + kWeldSlicePatches)));
      mostHeld = std::max(mostHeld, weld.locationsHeld());
    }
    EXPECT_LE(double(mostHeld), 2 * shape.frontLocations + sliceVertices) << (shuffled ? "shuffled" : "in order");
    EXPECT_GT(2 * double(mostHeld), shape.frontLocations) << "the bound is more than twice what the weld holds";
  }
}

// The streamed job's memory estimate (stream_budget.h) bounds what the weld holds by its front: between
// compactions twice the front at most (at least PatchWelder::kCompactAt, 1 here) and one slice. Its
// triangles in a shuffled order make the front most of the mesh, and the bound follows.
TEST(PatchWeld, HoldsNoMoreThanTheStreamEstimatesFront) {
  const TwistedSphere t = twistedSphere(Method::Smooth);
  const double edgeLength = t.deformer->internal().resolved.edgeLength;
  expectFrontBounds(t, [&](const Mesh& mesh, const std::vector<uint32_t>&) { return streamShape(mesh, edgeLength, t.P.level, 1000); });
}

// So does a one-shot accurate job's, from its knot-box sub-triangles (accurateStreamShape), their parents
// renumbered as the patches' and sorted by them (in each parent in their order).
TEST(PatchWeld, HoldsNoMoreThanTheAccurateEstimatesFront) {
  const TwistedSphere t = twistedSphere(Method::Accurate);
  const Mesh& input = t.deformer->internal().input;
  const std::vector<SubTriangle> subs = clipAgainstKnotBoxes(input, t.deformer->internal().structure);
  ASSERT_EQ(subs.size(), t.P.patchCount());
  expectFrontBounds(t, [&](const Mesh& mesh, const std::vector<uint32_t>& rank) {
    std::vector<SubTriangle> renumbered = subs;
    for (SubTriangle& s : renumbered) s.parent = rank[s.parent];
    std::stable_sort(renumbered.begin(), renumbered.end(), [](const SubTriangle& a, const SubTriangle& b) { return a.parent < b.parent; });
    return accurateStreamShape(mesh, renumbered, t.P.level);
  });
}

}  // namespace
