// sffd on the gles backend as a user runs it: held to the OpenGL ES 3.1 minimum limits by default,
// every method runs there (every kernel fits 4 storage blocks) and gives the CPU reference's bytes in
// strict mode, as it does with SFFD_GLES_LIMITS=device; double precision is a usage error (exit 2).
// docs/GLES.md.
#include <gtest/gtest.h>

#include "tests/support/cli_runner.h"

namespace sffd::test {
namespace {

class Gles : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!hasDevice("gles")) GTEST_SKIP() << "no gles device here";
    dir = tempDir("gles");
    mesh = std::string(SFFD_TEST_DATA) + "/sphere.obj";
    lattice = std::string(SFFD_TEST_DATA) + "/lattices/sphere_twist.npy";
  }
  void TearDown() override { fs::remove_all(dir); }
  RunResult deform(const std::string& options, const std::string& out, const std::string& env = "") {
    return runSffd("deform " + mesh + " -l " + lattice + " " + options + " -o " + (dir / out).string() + " --quiet", env);
  }
  fs::path dir;
  std::string mesh, lattice;
};

TEST_F(Gles, EveryMethodRunsWithinTheMinimumLimitsToTheCpuBytes) {
  for (const char* method : {"classic", "accurate", "smooth"}) {
    const std::string options = std::string("--method ") + method + " --strict --precision float --tess 3 --backend ";
    ASSERT_EQ(deform(options + "gles", "gles.obj").status, 0) << method;
    ASSERT_EQ(deform(options + "cpu", "cpu.obj").status, 0) << method;
    EXPECT_EQ(slurp(dir / "gles.obj"), slurp(dir / "cpu.obj")) << method;
  }
}

// Smooth FFD at the default tessellation, split deform steps too, at the minimum limits and at the device's own.
TEST_F(Gles, SmoothRunsAtTheMinimumAndAtTheDevicesOwnLimits) {
  ASSERT_EQ(deform("--method smooth --strict --backend cpu", "cpu.obj").status, 0);
  RunResult held = deform("--method smooth --strict --backend gles", "held.obj");
  ASSERT_EQ(held.status, 0) << held.err;
  EXPECT_EQ(slurp(dir / "held.obj"), slurp(dir / "cpu.obj"));
  ASSERT_EQ(deform("--method smooth --strict --split --backend gles", "split.obj").status, 0);
  EXPECT_EQ(slurp(dir / "split.obj"), slurp(dir / "cpu.obj"));
  ASSERT_EQ(deform("--method smooth --strict --backend gles", "own.obj", "SFFD_GLES_LIMITS=device").status, 0);
  EXPECT_EQ(slurp(dir / "own.obj"), slurp(dir / "cpu.obj"));
}

// conform compares gles's buffers bit for bit with the CPU reference's at the minimum limits: accurate
// FFD, smooth FFD (every kernel: PN, clipping, deform).
TEST_F(Gles, ConformStrictIsBitIdenticalToTheCpu) {
  const std::string job = "conform " + mesh + " -l " + lattice + " --strict --backends gles,cpu --require gles --tess 3";
  for (const std::string method : {"accurate", "smooth"}) {
    RunResult r = runSffd(job + " --method " + method);
    EXPECT_EQ(r.status, 0) << method << ": " << r.err;
    auto count = [&](const std::string& what) {
      size_t n = 0;
      for (size_t at = r.out.find(what); at != std::string::npos; at = r.out.find(what, at + 1)) ++n;
      return n;
    };
    // Every buffer (smooth: PN, clip headers and records, patches, positions, normals) equal bit for bit.
    EXPECT_EQ(count(" gles vs cpu: "), method == "smooth" ? 6u : 3u) << method << ": " << r.out;
    EXPECT_EQ(count(" gles vs cpu: max_abs=0 max_ulp=0 mismatched=0/"), count(" gles vs cpu: ")) << r.out;
    EXPECT_NE(r.out.find("conform: PASS"), std::string::npos) << method;
  }
}

TEST_F(Gles, DoublePrecisionIsAUsageError) {
  RunResult r = deform("--method classic --precision double --backend gles", "d.obj");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("OpenGL ES has no double precision"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("use --precision float (or auto) with --backend gles"), std::string::npos) << r.err;   // in the tool's words
  EXPECT_FALSE(fs::exists(dir / "d.obj"));
}

}  // namespace
}  // namespace sffd::test
