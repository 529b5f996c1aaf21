// A lattice that throws points beyond the floating-point range of the computation gives no file of
// inf and NaN: the run is refused (exit 2) with the vertex where it happened, and nothing is written.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/support/cli_runner.h"

namespace sffd::test {
namespace {

TEST(NonFinite, ResultsAreRefusedBeforeWriting) {
  fs::path dir = tempDir("nonfinite");
  const std::string mesh = std::string(SFFD_TEST_DATA) + "/sphere.obj", lattice = (dir / "l.json").string();
  ASSERT_EQ(runSffd("lattice " + mesh + " -o " + lattice + " --quiet").status, 0);
  nlohmann::json L = nlohmann::json::parse(slurp(lattice));
  L["control_points"][62] = {1e39, 0, 0};   // finite in double, beyond float's range
  std::ofstream(dir / "far.json") << L.dump();
  const std::string far = (dir / "far.json").string();
  for (const char* b : {"vulkan", "gl", "cpu"})
    for (const char* method : {"--method smooth", "--method accurate --precision float", "--method classic --precision float"}) {
      const std::string out = (dir / (std::string(b) + ".obj")).string();
      RunResult r = runSffd("deform " + mesh + " -l " + far + " " + method + " --backend " + b + " -o " + out + " --quiet");
      if (r.status == 3) continue;   // backend not here
      EXPECT_EQ(r.status, 2) << b << " " << method << ": " << r.err;
      EXPECT_NE(r.err.find("sffd: error: " + out + ": not written: vertex "), std::string::npos) << r.err;
      EXPECT_FALSE(fs::exists(out)) << b << " " << method;
    }
  fs::remove_all(dir);
}

// A result finite in double but past float's range: the text formats hold it, a binary STL (floats) is
// refused like a non-finite result. It held infinities, which sffd itself refused to read back.
TEST(NonFinite, DoubleResultsPastFloatAreRefusedByBinaryStl) {
  fs::path dir = tempDir("nonfinite_stl");
  const std::string mesh = std::string(SFFD_TEST_DATA) + "/sphere.obj", lattice = (dir / "l.json").string();
  ASSERT_EQ(runSffd("lattice " + mesh + " -o " + lattice + " --quiet").status, 0);
  nlohmann::json L = nlohmann::json::parse(slurp(lattice));
  L["control_points"][62] = {1e300, 0, 0};
  std::ofstream(dir / "far.json") << L.dump();
  const std::string job = "deform " + mesh + " -l " + (dir / "far.json").string() + " --backend cpu --precision double --quiet -o ";
  for (const char* method : {" --method classic", " --method smooth --tess 2"}) {   // gathered, streamed
    RunResult text = runSffd(job + (dir / "t.stl").string() + method);
    EXPECT_EQ(text.status, 0) << method << ": " << text.err;
    const std::string out = (dir / "b.stl").string();
    RunResult r = runSffd(job + out + " --binary" + method);
    EXPECT_EQ(r.status, 2) << method << ": " << r.err;
    EXPECT_EQ(r.err.rfind("sffd: error: " + out + ": not written: vertex ", 0), 0u) << r.err;
    EXPECT_FALSE(fs::exists(out)) << method;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sffd::test
