// Polygons into triangles (polygon_triangulation.cpp) and the readers' lenient cases: concave
// polygons keep their orientation and area, convex ones read exactly as before, polygons without
// area are dropped with a warning, and what the common importers skip is skipped with a warning.
#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include <sffd/error.h>

#include "io/mesh_io_internal.h"

namespace sffd {
namespace {

// Signed area of each triangle seen from +z (the test polygons lie in z = 0).
std::vector<double> signedAreas(const Mesh& m) {
  std::vector<double> a;
  for (const auto& t : m.triangles) {
    glm::dvec3 n = glm::cross(m.positions[t[1]] - m.positions[t[0]], m.positions[t[2]] - m.positions[t[0]]);
    a.push_back(0.5 * n.z);
  }
  return a;
}

TEST(PolygonTriangulation, ConcavePolygonKeepsItsOrientationAndArea) {
  // An arrow-head notch: the fan from corner 1 would cross the notch and flip a triangle.
  const std::string obj =
      "v 0 0 0\nv 4 0 0\nv 4 4 0\nv 2 1 0\nv 0 4 0\n"
      "f 1 2 3 4 5\n";   // a fan from (0, 0) would cross the notch at (2, 1)
  Mesh m = meshio::readMeshBytes("notch.obj", obj);
  ASSERT_EQ(m.triangles.size(), 3u);
  double total = 0;
  for (double a : signedAreas(m)) {
    EXPECT_GT(a, 0) << "a triangle turned over";
    total += a;
  }
  EXPECT_DOUBLE_EQ(total, 16.0 - 0.5 * 4 * 3);   // the square less the notch
  EXPECT_TRUE(m.warnings.empty());
}

TEST(PolygonTriangulation, ClockwiseConcavePolygonStaysClockwise) {
  const std::string obj = "v 0 0 0\nv 4 0 0\nv 4 4 0\nv 2 1 0\nv 0 4 0\nf 5 4 3 2 1\n";
  Mesh m = meshio::readMeshBytes("notch_cw.obj", obj);
  ASSERT_EQ(m.triangles.size(), 3u);
  for (double a : signedAreas(m)) EXPECT_LT(a, 0);
}

TEST(PolygonTriangulation, ConvexPolygonsAreFannedAsBefore) {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\n";
  Mesh m = meshio::readMeshBytes("pentagon.obj", obj);
  ASSERT_EQ(m.triangles.size(), 3u);
  for (uint32_t i = 0; i < 3; ++i) {
    EXPECT_EQ(m.triangles[i][0], 0u);
    EXPECT_EQ(m.triangles[i][1], i + 1);
    EXPECT_EQ(m.triangles[i][2], i + 2);
  }
}

TEST(PolygonTriangulation, PolygonsWithoutAreaAreDroppedWithAWarning) {
  // One good triangle, a polygon of collinear corners, and a long polygon that only repeats corners.
  std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 1 2 4 5\nf";
  for (int i = 0; i < 300; ++i) obj += " 1 2";
  obj += "\n";
  Mesh m = meshio::readMeshBytes("degenerate.obj", obj);
  EXPECT_EQ(m.triangles.size(), 1u);
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_NE(m.warnings[0].find("2 polygons without area dropped"), std::string::npos) << m.warnings[0];
}

TEST(PolygonTriangulation, EmptyObjFaceLinesAreSkippedWithAWarning) {
  Mesh m = meshio::readMeshBytes("empty_f.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf\nf 1 2 3\nf   \n");
  EXPECT_EQ(m.triangles.size(), 1u);
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_EQ(m.warnings[0], "empty_f.obj:4: 2 empty face lines skipped");
}

TEST(PolygonTriangulation, FreeTextPlyHeaderLinesAreIgnoredWithAWarning) {
  const std::string ply =
      "ply\nformat ascii 1.0\nCreated by an old exporter\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  Mesh m = meshio::readMeshBytes("old.ply", ply);
  EXPECT_EQ(m.triangles.size(), 1u);
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_EQ(m.warnings[0], "old.ply:3: 1 free-text header line without \"comment\" ignored");
  // After the first element a line that is no PLY keyword is still an error.
  const std::string bad =
      "ply\nformat ascii 1.0\nelement vertex 3\nnonsense here\nproperty float x\nend_header\n";
  EXPECT_THROW(meshio::readMeshBytes("bad.ply", bad), Error);
}

TEST(PolygonTriangulation, AsciiStlFacetsOfFourVerticesAreReadWithAWarning) {
  const std::string stl =
      "solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\n"
      "endfacet\nendsolid q\n";
  Mesh m = meshio::readMeshBytes("quad.stl", stl);
  EXPECT_EQ(m.triangles.size(), 2u);
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_NE(m.warnings[0].find("quad.stl:2: 1 facet has more than 3 vertices"), std::string::npos) << m.warnings[0];
}

}  // namespace
}  // namespace sffd
