// Memory bounded before allocating (issue 12, item 4): a tiny lattice file asking for a huge lattice,
// and a smooth job above SFFD_MEMORY_LIMIT, are refused up front with exit 2 and the estimate.
#include <gtest/gtest.h>

#include <chrono>

#include "tests/support/cli_runner.h"

namespace sffd::test {
namespace {

const char* kBigLattice = R"({"format":"sffd-lattice","version":1,"degree":[2,2,2],"counts":[256,256,256],
  "box":{"min":[-1,-1,-1],"max":[1,1,1]}})";

TEST(MemoryLimit, HugeLatticeFromAFewBytesIsRefusedAtOnce) {
  fs::path dir = tempDir("memory_limit_lattice");
  writeBoxObj(dir / "box.obj", 0, 0, 0, 0.5);
  std::ofstream(dir / "big.json") << kBigLattice;
  const std::string box = (dir / "box.obj").string(), big = (dir / "big.json").string();
  for (const char* method : {"smooth", "classic", "accurate"}) {
    const auto t0 = std::chrono::steady_clock::now();
    RunResult r = runSffd("deform " + box + " -l " + big + " --method " + method + " --backend cpu -o " + (dir / "o.obj").string(),
                          "SFFD_MEMORY_LIMIT=4G");
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.status, 2) << method << ": " << r.err;
    EXPECT_LT(s, 1.0) << method;
    // The 256^3 box form alone is 254^3 x 27 points: tens of GiB, named with the limit.
    EXPECT_NE(r.err.find("sffd: error: " + big + ":1: the 256x256x256 lattice (up to 16387064 knot boxes of degree 2,2,2) needs about "),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("GiB of host memory to evaluate, more than the limit of 4.00 GiB (SFFD_MEMORY_LIMIT)"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(dir / "o.obj"));
  }
  // render and error read the lattice the same way.
  RunResult e = runSffd("error " + box + " -l " + big + " --backend cpu", "SFFD_MEMORY_LIMIT=4G");
  EXPECT_EQ(e.status, 2) << e.err;
  EXPECT_NE(e.err.find("(SFFD_MEMORY_LIMIT)"), std::string::npos) << e.err;
  fs::remove_all(dir);
}

TEST(MemoryLimit, SmoothJobAboveTheLimitIsRefusedWithTheEstimate) {
  fs::path dir = tempDir("memory_limit_smooth");
  writeBoxObj(dir / "box.obj", 0, 0, 0, 0.5);
  const std::string box = (dir / "box.obj").string(), lattice = (dir / "l.json").string();
  ASSERT_EQ(runSffd("lattice " + box + " -o " + lattice + " --preset twist:0.3 --quiet").status, 0);
  // A fine edge length on a small box: thousands of sub-triangles at level 64, about 1.3 MB each.
  const std::string job = "deform " + box + " -l " + lattice + " --backend cpu --edge-length 0.01 --tess 64 -o " + (dir / "o.obj").string();
  RunResult r = runSffd(job, "SFFD_MEMORY_LIMIT=512M");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("sffd: error: the smooth job needs about "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("GiB of host memory, more than the limit of 512.00 MiB (SFFD_MEMORY_LIMIT)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "o.obj"));
  // The same mesh at the default settings fits a small limit, and a bad limit is named.
  RunResult ok = runSffd("deform " + box + " -l " + lattice + " --backend cpu --quiet -o " + (dir / "o.obj").string(), "SFFD_MEMORY_LIMIT=256M");
  EXPECT_EQ(ok.status, 0) << ok.err;
  RunResult bad = runSffd("deform " + box + " -l " + lattice + " --backend cpu -o " + (dir / "p.obj").string(), "SFFD_MEMORY_LIMIT=lots");
  EXPECT_EQ(bad.status, 2) << bad.err;
  EXPECT_NE(bad.err.find("SFFD_MEMORY_LIMIT must be a size"), std::string::npos) << bad.err;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sffd::test
