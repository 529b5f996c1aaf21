// End-to-end: the file formats users exchange (docs/CLI.md "Mesh files"): binary output, attributes
// kept through every method.
#include <gtest/gtest.h>

#include "model/mesh.h"
#include "support/cli_runner.h"

namespace sffd::test {
namespace {

const std::string kData = SFFD_TEST_DATA;
const std::string kSphere = kData + "/sphere.obj -l " + kData + "/lattices/sphere_twist.npy --normalize 0.99 --backend cpu --quiet";

TEST(Formats, BinaryOutputEqualsText) {
  const fs::path dir = tempDir("formats_binary");
  for (const char* method : {"classic", "smooth"})
    for (const char* ext : {".ply", ".stl"}) {
      SCOPED_TRACE(std::string(method) + ext);
      const std::string bin = (dir / (std::string("b") + ext)).string(), text = (dir / (std::string("t") + ext)).string();
      const std::string base = "deform " + kSphere + " --method " + method + " --precision float --edge-length 0.3 -o ";
      ASSERT_EQ(runSffd(base + bin + " --binary").status, 0);
      ASSERT_EQ(runSffd(base + text).status, 0);
      // Binary holds floats, text 9 digits: the same values to float resolution (the model is in [-1, 1]).
      const Mesh b = readMesh(bin), t = readMesh(text);
      ASSERT_EQ(b.triangles.size(), t.triangles.size());
      for (size_t f = 0; f < b.triangles.size(); ++f)
        for (int c = 0; c < 3; ++c) ASSERT_LE(glm::length(b.positions[b.triangles[f][c]] - t.positions[t.triangles[f][c]]), 1.2e-7);
    }
  const RunResult r = runSffd("deform " + kSphere + " --method classic -o " + (dir / "x.obj").string() + " --binary");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "sffd: error: --binary writes .ply and .stl, not '.obj'\n");
  EXPECT_FALSE(fs::exists(dir / "x.obj"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sffd::test
