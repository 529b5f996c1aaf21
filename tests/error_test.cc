// End-to-end tests of `sffd error` (docs/CLI.md, docs/ACCURACY.md "Error metrics"): the JSON contract,
// accurate FFD measured against the exact FFD (about 0), classic FFD (positive), closed and open meshes.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "tests/support/cli_runner.h"

namespace fs = std::filesystem;

namespace {

const std::string kData = std::string(SFFD_TEST_DATA) + "/";

using Result = sffd::test::RunResult;
using sffd::test::runSffd;
using sffd::test::slurp;
using sffd::test::tempDir;

void expectStats(const nlohmann::json& s) {
  for (const char* k : {"avg", "max", "std"}) {
    ASSERT_TRUE(s.contains(k)) << k;
    EXPECT_TRUE(s[k].is_number()) << k;
  }
  EXPECT_LE(s["avg"].get<double>(), s["max"].get<double>());
}

const std::string kCube = kData + "cube2.obj -l " + kData + "lattices/cube2_twist.npy";
const std::string kTeapot = kData + "teapot.bpt -l " + kData + "lattices/teapot_bend.npy --normalize 0.9090909";

}  // namespace

TEST(ErrorCommand, AccurateOnTheCubeIsExactAndHasAVolume) {
  Result r = runSffd("error " + kCube + " --method accurate --json --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["method"], "accurate");
  EXPECT_EQ(j["clip"], "knot-box");
  EXPECT_EQ(j["vertices"].get<size_t>() % 66, 0u);
  EXPECT_GT(j["vertices"].get<size_t>(), 0u);
  expectStats(j["geometry"]);
  expectStats(j["normal_deg"]);
  // Double precision by default where the device has it (lavapipe has), float otherwise.
  double tol = j.value("precision", "") == "double" ? 1e-9 : 1e-4;
  EXPECT_LT(j["geometry"]["max"].get<double>(), tol);
  ASSERT_TRUE(j["volume"].is_object()) << r.out;
  for (const char* k : {"reference", "result", "rel_error"}) EXPECT_TRUE(j["volume"][k].is_number()) << k;
  EXPECT_GT(j["volume"]["reference"].get<double>(), 0);
  EXPECT_LT(j["volume"]["rel_error"].get<double>(), 5e-3);   // the level-10 tessellation of the exact patches
}

TEST(ErrorCommand, ClassicHasAPositiveErrorOnTheSameJob) {
  Result a = runSffd("error " + kCube + " --method accurate --json --quiet --backend cpu");
  Result c = runSffd("error " + kCube + " --method classic --json --quiet --backend cpu");
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(c.status, 0) << c.err;
  nlohmann::json ja = nlohmann::json::parse(a.out), jc = nlohmann::json::parse(c.out);
  EXPECT_EQ(jc["method"], "classic");
  EXPECT_EQ(jc["vertices"].get<size_t>(), 12u * 66u);   // 12 triangles tessellated at level 10
  EXPECT_GT(jc["geometry"]["avg"].get<double>(), 1e-2);
  EXPECT_GT(jc["normal_deg"]["avg"].get<double>(), 1.0);
  // The same exact reference volume, whichever method is measured.
  EXPECT_DOUBLE_EQ(ja["volume"]["reference"].get<double>(), jc["volume"]["reference"].get<double>());
  EXPECT_GT(jc["volume"]["rel_error"].get<double>(), ja["volume"]["rel_error"].get<double>());
}

TEST(ErrorCommand, TheOpenTeapotHasNoVolume) {
  Result r = runSffd("error " + kTeapot + " --method classic --json --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["volume"].is_null()) << r.out;
  expectStats(j["geometry"]);
  // Against the exact bicubic surface: the flat triangles miss it between the vertices.
  EXPECT_GT(j["geometry"]["avg"].get<double>(), 1e-4);
}

TEST(ErrorCommand, AccurateTeapotRunsOnTheExactSurfaceReference) {
  Result r = runSffd("error " + kTeapot + " --method accurate --json --quiet --tess 2");
  ASSERT_EQ(r.status, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["volume"].is_null());
  EXPECT_EQ(j["vertices"].get<size_t>() % 6, 0u);   // 6 vertices a patch at level 2
  EXPECT_GT(j["geometry"]["max"].get<double>(), 1e-3);
}

TEST(ErrorCommand, HumanReadableSummaryAndBadOptions) {
  Result r = runSffd("error " + kCube + " --method accurate --quiet --tess 3");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("geometry"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("volume"), std::string::npos) << r.out;
  Result bad = runSffd("error " + kCube + " --method exact");
  EXPECT_EQ(bad.status, 2);
  EXPECT_EQ(bad.err.rfind("sffd: error: ", 0), 0u) << bad.err;
  Result tess = runSffd("error " + kCube + " --method accurate --tess 0");
  EXPECT_EQ(tess.status, 2) << tess.err;
  Result help = runSffd("error --help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("--json"), std::string::npos);
  // --stats FILE (a common option) writes --json's object there; it was taken and nothing written.
  const fs::path dir = tempDir("error_stats");
  const std::string stats = (dir / "s.json").string();
  Result summary = runSffd("error " + kCube + " --method accurate --quiet --tess 3 --stats " + stats);
  ASSERT_EQ(summary.status, 0) << summary.err;
  EXPECT_EQ(summary.out, r.out);
  Result json = runSffd("error " + kCube + " --method accurate --quiet --tess 3 --json");
  ASSERT_EQ(json.status, 0) << json.err;
  EXPECT_EQ(slurp(stats), json.out);
  fs::remove_all(dir);
}

// The analysis computes in the Deformer's frame (docs/ROBUSTNESS.md "Models of any size"): a model 1e-100 or
// 1e100 across has the errors of size 1, scaled (before, its normal error was 0 or 2 degrees and its reference
// volume 0 or NaN: squared lengths and volumes in world units left double's range).
TEST(ErrorCommand, EverySizeHasTheErrorsOfSizeOne) {
  const fs::path dir = tempDir("error_sizes");
  nlohmann::json unit;
  for (const char* size : {"1", "1e-100", "1e100"}) {
    const std::string lattice = (dir / (std::string(size) + ".json")).string(), mesh = kData + "cube2.obj --normalize " + size;
    ASSERT_EQ(runSffd("lattice " + mesh + " -o " + lattice + " --preset twist:0.4 --quiet").status, 0);
    Result r = runSffd("error " + mesh + " -l " + lattice + " --json --quiet --backend cpu --tess 3 --method classic");
    ASSERT_EQ(r.status, 0) << size << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    if (unit.is_null()) {
      unit = j;
      ASSERT_GT(unit["geometry"]["avg"].get<double>(), 0);
      ASSERT_GT(unit["normal_deg"]["avg"].get<double>(), 0);
      continue;
    }
    const double s = std::stod(size);
    auto near = [&](double value, double reference, const char* what) {
      EXPECT_NEAR(value, reference, 1e-3 * std::abs(reference)) << size << " " << what;
    };
    near(j["geometry"]["avg"].get<double>() / s, unit["geometry"]["avg"].get<double>(), "geometry avg");
    near(j["geometry"]["max"].get<double>() / s, unit["geometry"]["max"].get<double>(), "geometry max");
    near(j["normal_deg"]["avg"].get<double>(), unit["normal_deg"]["avg"].get<double>(), "normal avg");
    near(j["volume"]["reference"].get<double>() / (s * s * s), unit["volume"]["reference"].get<double>(), "volume");
    EXPECT_NEAR(j["volume"]["rel_error"].get<double>(), unit["volume"]["rel_error"].get<double>(), 1e-5) << size;
  }
}
