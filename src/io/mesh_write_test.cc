// Mesh writers (mesh_io_write.cpp): binary PLY and STL, and the attributes every format keeps.
#include <gtest/gtest.h>

#include <sffd/error.h>

#include "model/mesh.h"
#include "tests/support/cli_runner.h"

using namespace sffd;
using sffd::test::slurp;
using sffd::test::tempDir;
namespace fs = std::filesystem;

namespace {

const std::string kData = SFFD_TEST_DATA;

glm::dvec3 asFloat(const glm::dvec3& v) {
  volatile float x = float(v.x), y = float(v.y), z = float(v.z);   // through memory: no folding at -O3
  return {double(x), double(y), double(z)};
}

TEST(MeshWrite, BinaryPlyAndStlReadBackAsTheirText) {
  const fs::path dir = tempDir("mesh_write_binary");
  const Mesh teapot = readMesh(kData + "/teapot.bpt");
  for (const char* ext : {".ply", ".stl"})
    for (int digits : {9, 17}) {
      SCOPED_TRACE(std::string(ext) + " " + std::to_string(digits) + " digits");
      const std::string bin = (dir / (std::string("bin") + ext)).string(), text = (dir / (std::string("text") + ext)).string();
      writeMesh(bin, teapot, MeshWriteOptions{.significantDigits = digits, .binary = true});
      writeMesh(text, teapot, digits);
      EXPECT_LT(fs::file_size(bin), fs::file_size(text));
      const Mesh b = readMesh(bin), t = readMesh(text);
      ASSERT_EQ(b.triangles.size(), teapot.triangles.size());
      // PLY keeps the vertices (float, or double with 17 digits); STL welds them back by position.
      const bool exact = std::string(ext) == ".ply" && digits == 17;
      for (size_t f = 0; f < teapot.triangles.size(); ++f)
        for (int c = 0; c < 3; ++c) {
          const glm::dvec3 want = teapot.positions[teapot.triangles[f][c]];
          ASSERT_EQ(b.positions[b.triangles[f][c]], exact ? want : asFloat(want)) << "triangle " << f;
          const glm::dvec3 fromText = t.positions[t.triangles[f][c]];
          ASSERT_EQ(b.positions[b.triangles[f][c]], exact ? fromText : asFloat(fromText)) << "triangle " << f;
        }
      if (std::string(ext) == ".ply") {
        // (float normals are normalised again on reading: equal to float resolution)
        for (size_t v = 0; v < b.normals.size(); ++v) ASSERT_LE(glm::length(b.normals[v] - t.normals[v]), exact ? 0.0 : 1e-7);
        EXPECT_TRUE(b.normalsFromFile);
      }
    }
  // The binary STL header does not start with "solid" (readers would try it as text).
  EXPECT_NE(slurp(dir / "bin.stl").rfind("solid", 0), 0u);
  fs::remove_all(dir);
}

TEST(MeshWrite, BinaryIsRefusedForTextFormats) {
  const fs::path dir = tempDir("mesh_write_refused");
  const Mesh cube = readMesh(kData + "/cube.obj");
  for (const char* name : {"x.obj", "x.off"}) {
    const std::string p = (dir / name).string();
    try {
      writeMesh(p, cube, MeshWriteOptions{.binary = true});
      ADD_FAILURE() << name << " written in binary";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Input);
      EXPECT_NE(std::string(e.what()).find("binary output is for .ply and .stl"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(p));
  }
  fs::remove_all(dir);
}

}  // namespace
