// Every tessellation level at the low end, on every backend, through every variant of the smooth and
// accurate methods: a crash at --tess 1 once survived because no test swept the options. Each run must
// succeed with the documented triangle count (level^2 a patch), and strict runs must give the same
// bytes on every backend. gles runs held to the ES 3.1 minimum limits (every kernel fits them) and
// refuses double precision as a usage error.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/support/cli_runner.h"

namespace sffd::test {
namespace {

struct SweepCase {
  const char* backend;
  int level;
};
void PrintTo(const SweepCase& c, std::ostream* os) { *os << c.backend << " --tess " << c.level; }

class OptionSweep : public ::testing::TestWithParam<SweepCase> {};

TEST_P(OptionSweep, EveryVariantSucceedsWithTheDocumentedCount) {
  const SweepCase c = GetParam();
  fs::path dir = tempDir(std::string("sweep_") + c.backend + std::to_string(c.level));
  // A coarse box far from the origin, every edge a crease, and a twisted lattice around it.
  writeBoxObj(dir / "box.obj", 40, -25, 10, 1);
  const std::string box = (dir / "box.obj").string(), lattice = (dir / "l.json").string();
  ASSERT_EQ(runSffd("lattice " + box + " -o " + lattice + " --preset twist:0.6 --quiet").status, 0);
  if (runSffd(std::string("devices")).out.find(c.backend) == std::string::npos)
    GTEST_SKIP() << c.backend << " is not available here";
  const bool gles = std::string(c.backend) == "gles";
  // No doubles: OpenGL ES (a usage error) and NVIDIA's GL (a device error: docs/CONFORMANCE.md).
  const bool doubles = sffd::test::hasDoubles(std::string(c.backend) == "gl" ? "gl-egl" : c.backend);

  const std::string level = std::to_string(c.level);
  const char* variants[] = {"--method smooth",
                            "--method smooth --strict",
                            "--method smooth --strict --split",
                            "--method smooth --clip knot-box",
                            "--method smooth --precision double",
                            "--method accurate",
                            "--method accurate --strict --precision float"};
  int i = 0;
  for (const char* v : variants) {
    const std::string out = (dir / ("out" + std::to_string(i) + ".obj")).string(),
                      stats = (dir / ("s" + std::to_string(i++) + ".json")).string();
    RunResult r = runSffd("deform " + box + " -l " + lattice + " --edge-length 0.7 --tess " + level + " " + v +
                          " --backend " + c.backend + " -o " + out + " --stats " + stats + " --quiet");
    if (!doubles && std::string(v).find("double") != std::string::npos) {
      EXPECT_EQ(r.status, gles ? 2 : 3) << v << ": " << r.err;
      EXPECT_FALSE(fs::exists(out)) << v;
      continue;
    }
    ASSERT_EQ(r.status, 0) << v << ": " << r.err;
    nlohmann::json s = nlohmann::json::parse(slurp(stats));
    const long subs = s["sub_triangles"], triangles = s["output"]["triangles"];
    EXPECT_GT(subs, 0) << v;
    EXPECT_EQ(triangles, subs * c.level * c.level) << v;
  }
  // The strict smooth results of every backend equal the CPU reference's, byte for byte.
  const std::string cpuOut = (dir / "cpu.obj").string();
  ASSERT_EQ(runSffd("deform " + box + " -l " + lattice + " --edge-length 0.7 --tess " + level +
                    " --strict --backend cpu -o " + cpuOut + " --quiet")
                .status,
            0);
  EXPECT_EQ(slurp(dir / "out1.obj"), slurp(cpuOut));
  EXPECT_EQ(slurp(dir / "out2.obj"), slurp(cpuOut));
  fs::remove_all(dir);
}

std::vector<SweepCase> sweepCases() {
  std::vector<SweepCase> v;
  for (const char* b : {"vulkan", "gl", "gles", "cpu"})
    for (int level : {1, 2, 3}) v.push_back({b, level});
  return v;
}

INSTANTIATE_TEST_SUITE_P(Levels, OptionSweep, ::testing::ValuesIn(sweepCases()),
                         [](const ::testing::TestParamInfo<SweepCase>& i) {
                           return std::string(i.param.backend) + "_tess" + std::to_string(i.param.level);
                         });

}  // namespace
}  // namespace sffd::test
