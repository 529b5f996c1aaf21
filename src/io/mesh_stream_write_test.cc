// MeshFileWriter's PLY, whose records go through scratch files into the output, its blocks allocated before
// it replaces an existing file (atomic_file.cpp): writeMesh's bytes, and no scratch file left beside it.
#include <gtest/gtest.h>

#include <cmath>

#include <sffd/mesh.h>

#include "tests/support/cli_runner.h"

namespace {

using namespace sffd;
using sffd::test::slurp;
namespace fs = std::filesystem;

// An n x n grid of vertices with normals, two triangles a cell.
Mesh grid(uint32_t n) {
  Mesh m;
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      m.positions.push_back({x * 0.001, y * 0.001, 0.25 * std::sin(x * 0.01) * std::cos(y * 0.02)});
      m.normals.push_back(glm::normalize(glm::dvec3(0.01 * x, -0.02 * y, 1.0)));
    }
  for (uint32_t y = 0; y + 1 < n; ++y)
    for (uint32_t x = 0; x + 1 < n; ++x) {
      const uint32_t a = y * n + x;
      m.triangles.push_back({a, a + 1, a + n + 1});
      m.triangles.push_back({a, a + n + 1, a + n});
    }
  return m;
}

// `m` streamed in pieces of `rows` grid rows (each piece's triangles those of the cells above its rows).
void stream(const Mesh& m, uint32_t n, uint32_t rows, const fs::path& path, const MeshWriteOptions& o) {
  MeshFileWriter w(path.string(), o);
  w.begin(Mesh{});
  size_t firstTriangle = 0;
  for (uint32_t y = 0; y < n; y += rows) {
    const uint32_t y1 = std::min(n, y + rows);
    Mesh piece;
    piece.positions.assign(m.positions.begin() + size_t(y) * n, m.positions.begin() + size_t(y1) * n);
    piece.normals.assign(m.normals.begin() + size_t(y) * n, m.normals.begin() + size_t(y1) * n);
    // The cells whose corners are all given: rows up to y1 - 1.
    const size_t lastTriangle = y1 == n ? m.triangles.size() : 2 * size_t(y1 - 1) * (n - 1);
    piece.triangles.assign(m.triangles.begin() + std::ptrdiff_t(firstTriangle), m.triangles.begin() + std::ptrdiff_t(lastTriangle));
    firstTriangle = lastTriangle;
    w.add(piece, size_t(y) * n);
  }
  w.end();
}

class MeshStreamWrite : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = sffd::test::tempDir(std::string("stream_write_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { fs::remove_all(dir_); }

  void expectWriteMeshBytes(uint32_t n, bool binary, bool overwrite) {
    const Mesh m = grid(n);
    const MeshWriteOptions o{9, binary};
    writeMesh((dir_ / "whole.ply").string(), m, o);
    if (overwrite) writeMesh((dir_ / "streamed.ply").string(), grid(3), o);
    stream(m, n, 37, dir_ / "streamed.ply", o);
    EXPECT_EQ(slurp(dir_ / "streamed.ply"), slurp(dir_ / "whole.ply"));
    size_t files = 0;
    for (const auto& e : fs::directory_iterator(dir_)) files += e.is_regular_file();
    EXPECT_EQ(files, 2u) << "a scratch file is left beside the output";
  }

  fs::path dir_;
};

TEST_F(MeshStreamWrite, PlyIsWriteMeshsFile) {
  expectWriteMeshBytes(300, true, false);
  expectWriteMeshBytes(300, false, false);
  expectWriteMeshBytes(300, true, true);
  expectWriteMeshBytes(300, false, true);
}

// Over a larger file, the blocks allocated before the rename are the new file's: its size is what was written.
TEST_F(MeshStreamWrite, ReplacingALargerFileLeavesTheSizeWritten) {
  const Mesh m = grid(50);
  const MeshWriteOptions o{9, true};
  stream(m, 50, 7, dir_ / "a.ply", o);
  const auto size = fs::file_size(dir_ / "a.ply");
  stream(grid(20), 20, 7, dir_ / "a.ply", o);
  EXPECT_LT(fs::file_size(dir_ / "a.ply"), size);
  writeMesh((dir_ / "b.ply").string(), grid(20), o);
  EXPECT_EQ(slurp(dir_ / "a.ply"), slurp(dir_ / "b.ply"));
}

}  // namespace
