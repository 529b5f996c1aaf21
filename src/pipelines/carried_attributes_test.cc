// Texture coordinates, colours and materials through every method (patch_output.h carryAttributes):
// classic keeps them per vertex, smooth and accurate interpolate them in the parent at the pre-image,
// seams split vertices and stay closed in position, and every device gives the CPU reference's values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <set>

#include <sffd/sffd.h>

#include "api/api_test_support.h"
#include "backends/backend_test_support.h"
#include "pipelines/deformer_internal.h"

namespace {

using namespace sffd;

// A torus as a UV-mapped OBJ as exporters write it: n x m positions, an (n+1) x (m+1) grid of texture
// coordinates whose last row and column repeat the first positions with u = 1 or v = 1 (two seams),
// per-position colours, two materials and two groups.
Mesh uvTorus(int n, int m) {
  const std::filesystem::path p = std::filesystem::temp_directory_path() / ("sffd_uv_torus_" + std::to_string(::getpid()) + ".obj");
  {
    std::ofstream f(p);
    f.precision(17);
    f << "mtllib none.mtl\n";
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < m; ++j) {
        const double a = 2 * std::numbers::pi * i / n, b = 2 * std::numbers::pi * j / m;
        const double x = (1 + 0.4 * std::cos(b)) * std::cos(a), y = (1 + 0.4 * std::cos(b)) * std::sin(a), z = 0.4 * std::sin(b);
        f << "v " << x << ' ' << y << ' ' << z << ' ' << 0.5 + 0.5 * x << ' ' << 0.5 + 0.5 * y << ' ' << 0.5 + z << "\n";
      }
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= m; ++j) f << "vt " << double(i) / n << ' ' << double(j) / m << "\n";
    // Grid point (i, j): position (i mod n) m + (j mod m) + 1, texture coordinate i (m+1) + j + 1.
    auto corner = [&](int i, int j) { return std::to_string((i % n) * m + (j % m) + 1) + "/" + std::to_string(i * (m + 1) + j + 1); };
    for (int i = 0; i < n; ++i) {
      f << (i == 0 ? "g outer\nusemtl red\n" : i == n / 2 ? "g inner\nusemtl blue\n" : "");
      for (int j = 0; j < m; ++j) {
        f << "f " << corner(i, j) << ' ' << corner(i + 1, j) << ' ' << corner(i + 1, j + 1) << "\n";
        f << "f " << corner(i, j) << ' ' << corner(i + 1, j + 1) << ' ' << corner(i, j + 1) << "\n";
      }
    }
  }
  Mesh mesh = readMesh(p.string());
  std::filesystem::remove(p);
  return mesh;
}

Device openDevice(const std::string& name) { return sffd::testing::openTestDevice(name); }

DeformOptions options(Method method) {
  DeformOptions o;
  o.method = method;
  o.strict = true;
  o.precision = Precision::Float;
  o.tess = 4;
  o.edgeLength = 0.3;
  return o;
}

// Undirected welded edges used by other than two triangles (a closed surface has none).
size_t openEdges(const Mesh& m) {
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (const auto& t : m.triangles)
    for (int c = 0; c < 3; ++c) {
      uint32_t a = m.weldId[t[c]], b = m.weldId[t[(c + 1) % 3]];
      if (a != b) ++uses[{std::min(a, b), std::max(a, b)}];
    }
  size_t open = 0;
  for (const auto& [e, k] : uses) open += k != 2;
  return open;
}

TEST(CarriedAttributes, ReadFromObj) {
  const Mesh mesh = uvTorus(12, 8);
  EXPECT_EQ(mesh.positions.size(), 13u * 9u);   // the seam rows are vertices of their own
  EXPECT_EQ(std::set<uint32_t>(mesh.weldId.begin(), mesh.weldId.end()).size(), 12u * 8u);
  ASSERT_EQ(mesh.texcoords.size(), mesh.positions.size());
  ASSERT_EQ(mesh.colors.size(), mesh.positions.size());
  ASSERT_EQ(mesh.triangleMaterial.size(), mesh.triangles.size());
  ASSERT_EQ(mesh.materials.size(), 2u);
  EXPECT_EQ(mesh.materials[1].name, "blue");
  EXPECT_EQ(mesh.groups, (std::vector<std::string>{"outer", "inner"}));
  EXPECT_EQ(mesh.materialLibraries, std::vector<std::string>{"none.mtl"});
  EXPECT_EQ(openEdges(mesh), 0u);
  // A seam is no crease: the two vertices of a seam position get one computed normal.
  for (size_t v = 0; v < mesh.positions.size(); ++v)
    for (size_t w = v + 1; w < mesh.positions.size(); ++w)
      if (mesh.weldId[v] == mesh.weldId[w]) { EXPECT_EQ(mesh.normals[v], mesh.normals[w]) << v << " " << w; }
}

TEST(CarriedAttributes, EveryMethodKeepsThemAndEveryDeviceAgrees) {
  const Mesh mesh = uvTorus(12, 8);
  Lattice lattice = fitLattice(mesh, {4, 4, 4}, {2, 2, 2});
  applyLatticePreset(lattice, "twist", 0.5);
  std::vector<std::string> devices = sffd::testing::backendsHere(sffd::testing::testBackends());
  devices.insert(devices.begin(), "cpu");
  for (Method method : {Method::Classic, Method::Smooth, Method::Accurate}) {
    Mesh reference;
    for (const std::string& name : devices) {
      SCOPED_TRACE(name + (method == Method::Classic ? " classic" : method == Method::Smooth ? " smooth" : " accurate"));
      Device device = openDevice(name);
      Deformer deformer(device, mesh, lattice, options(method));
      deformer.deform(lattice);
      const Mesh out = deformer.result();
      ASSERT_EQ(out.texcoords.size(), out.positions.size());
      ASSERT_EQ(out.colors.size(), out.positions.size());
      ASSERT_EQ(out.triangleMaterial.size(), out.triangles.size());
      EXPECT_EQ(out.materials.size(), 2u);
      EXPECT_EQ(out.groups.size(), 2u);
      EXPECT_EQ(openEdges(out), 0u);   // seams split vertices, never positions
      if (method == Method::Classic) {
        EXPECT_EQ(out.texcoords, mesh.texcoords);
        EXPECT_EQ(out.colors, mesh.colors);
        EXPECT_EQ(out.triangleMaterial, mesh.triangleMaterial);
      } else {
        // Each patch vertex: the parent's corners at its pre-image (to rounding), its parent's material.
        const PatchVertices pv = *deformer.internal().run->patchVertices();
        const Mesh& input = deformer.internal().input;
        const size_t nv = size_t(tessVertexCount(pv.level));
        ASSERT_EQ(pv.texcoord.size(), 2 * pv.vertexCount());
        for (size_t g = 0; g < pv.vertexCount(); ++g) {
          const auto& t = input.triangles[pv.parent[g / nv]];
          glm::dvec2 want(0.0);
          for (int c = 0; c < 3; ++c) want += pv.lamParent[3 * g + c] * input.texcoords[t[c]];
          ASSERT_NEAR(pv.texcoord[2 * g], want.x, 1e-15) << g;
          ASSERT_NEAR(pv.texcoord[2 * g + 1], want.y, 1e-15) << g;
          ASSERT_EQ(pv.material[g / nv], input.triangleMaterial[pv.parent[g / nv]]);
        }
        // A position with two texture coordinates lies on a seam (u or v at 0 and 1); nothing else splits.
        std::map<uint32_t, std::set<std::pair<double, double>>> uvsAt;
        for (size_t v = 0; v < out.positions.size(); ++v) uvsAt[out.weldId[v]].insert({out.texcoords[v].x, out.texcoords[v].y});
        size_t seam = 0;
        for (const auto& [w, uvs] : uvsAt) {
          if (uvs.size() < 2) continue;
          ++seam;
          for (const auto& [u, v] : uvs) EXPECT_TRUE(u == 0 || u == 1 || v == 0 || v == 1) << u << " " << v;
        }
        EXPECT_GT(seam, 12u + 8u);
      }
      if (name == "cpu") reference = out;
      else {
        EXPECT_EQ(out.texcoords, reference.texcoords);   // strict kernels: the same pre-images, so the same values
        EXPECT_EQ(out.colors, reference.colors);
      }
    }
  }
}

// A value all the corners share is carried exactly, whatever the weights' sum rounds to: an opaque alpha at
// weights 0.7, 0.2, 0.1 summed 0.9999999999999999, and the PLY writer then wrote an alpha channel of 255s.
TEST(CarriedAttributes, AValueTheCornersShareIsKeptExactly) {
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}};
  mesh.weldId = {0, 1, 2};
  mesh.colors = {{0.25, 0.5, 1, 1}, {0.25, 0.75, 1, 1}, {0.25, 0.5, 0, 1}};
  mesh.texcoords = {{0.3, 0.1}, {0.3, 0.7}, {0.3, 0.9}};
  PatchVertices pv;
  pv.level = 1;
  pv.parent = {0};
  pv.lamParent = {0.7, 0.2, 0.1, 0, 0.6, 0.4, 1, 0, 0};   // inside, on the edge 1-2, at corner 0
  pv.position.assign(9, 0.0);
  pv.normal.assign(9, 0.0);
  ASSERT_EQ(0.7 + 0.2 + 0.1, 0.9999999999999999);
  carryPatchAttributes(pv, mesh);
  for (size_t g = 0; g < 3; ++g) {
    EXPECT_EQ(pv.color[4 * g], 0.25) << g;       // shared by all three corners
    EXPECT_EQ(pv.color[4 * g + 3], 1.0) << g;    // likewise: opaque stays opaque
    EXPECT_EQ(pv.texcoord[2 * g], 0.3) << g;
  }
  EXPECT_EQ(pv.color[4 * 1 + 2], 0.6);           // on the edge 1-2: blue 1 and 0 are not shared, so interpolated
  EXPECT_EQ(pv.color[4 * 2 + 1], 0.5);           // at corner 0: its own value
}

}  // namespace
