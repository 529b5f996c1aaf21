// validateMesh's weld rule (Mesh::weldId in <sffd/mesh.h>): the vertices of one weld id are at one
// position; the ids are any labels below the vertex count; one position may have several ids.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <sffd/error.h>

#include "model/mesh.h"

using namespace sffd;

namespace {

// validateMesh's input error ("" when it takes the mesh).
std::string messageOf(const Mesh& mesh) {
  try {
    validateMesh(mesh, "mesh");
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Input) << e.what();
    return e.what();
  }
  return "";
}

// A caller's weldId that put one id at two positions deformed silently into a torn or empty result
// (docs/ROBUSTNESS.md "Found"); now refused, naming the first vertex away from its id's first vertex.
TEST(MeshCheck, OneWeldIdIsOnePositionAndAnyLabelsAreTaken) {
  const Mesh cube = readMesh(SFFD_TEST_DATA "/cube2.obj");   // 8 corners split by 3 face normals each
  ASSERT_EQ(cube.positions.size(), 24u);
  EXPECT_EQ(messageOf(cube), "");   // the reader's own ids

  Mesh m = cube;   // a split corner moved after welding
  m.positions[0].x += 1e-3;
  EXPECT_EQ(messageOf(m), "mesh: weldId[8] is 0, as vertex 0's, but vertex 8 is at (1, -1, 1) and vertex 0 at (1.001, -1, 1): "
                          "vertices with one weld id must be at one position (leave weldId empty to weld by position)");
  m = cube;   // two corners given one id
  m.weldId[2] = m.weldId[0];
  EXPECT_EQ(messageOf(m).rfind("mesh: weldId[2] is 0, as vertex 0's, but vertex 2 is at (-1, -1, -1) and vertex 0 at (1, -1, 1)", 0), 0u);
  m = cube;
  std::fill(m.weldId.begin(), m.weldId.end(), 0u);
  EXPECT_EQ(messageOf(m).rfind("mesh: weldId[1] is 0, as vertex 0's", 0), 0u);

  // Taken: each id the smallest vertex index at its position, the ids reversed, one split corner a
  // location of its own (two sheets touching there), every vertex its own.
  const uint32_t n = uint32_t(cube.positions.size());
  m = cube;
  for (uint32_t v = 0; v < n; ++v)
    m.weldId[v] = uint32_t(std::find(cube.positions.begin(), cube.positions.end(), cube.positions[v]) - cube.positions.begin());
  EXPECT_EQ(messageOf(m), "");
  m = cube;
  for (uint32_t& w : m.weldId) w = n - 1 - w;
  EXPECT_EQ(messageOf(m), "");
  m = cube;
  m.weldId[0] = n - 1;   // the reader's ids are 0..7
  EXPECT_EQ(messageOf(m), "");
  for (uint32_t v = 0; v < n; ++v) m.weldId[v] = v;
  EXPECT_EQ(messageOf(m), "");

  // 0 and -0 are one position; a NaN is reported as non-finite, not as a weld id at two positions.
  Mesh z;
  z.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-0.0, 0, 0}};
  z.triangles = {{0, 1, 2}, {3, 2, 1}};
  z.weldId = {0, 1, 2, 0};
  EXPECT_EQ(messageOf(z), "");
  z.positions[3].y = std::nan("");
  EXPECT_EQ(messageOf(z).rfind("mesh: positions[3] is non-finite", 0), 0u);
}

}  // namespace
