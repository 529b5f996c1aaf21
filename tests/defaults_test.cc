// Defaults that surprise (issue 12, item 8): the default edge length is stated in --help and written
// to --stats; file normals that contradict the winding are warned about, and --ignore-normals
// recomputes them from the winding.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/support/cli_runner.h"

namespace sffd::test {
namespace {

// A regular tetrahedron wound outward, with per-vertex file normals pointing in (`inward`) or out.
void writeTetra(const fs::path& path, bool inward) {
  std::ofstream f(path);
  const int v[4][3] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  const double s = (inward ? -1.0 : 1.0) / std::sqrt(3.0);
  for (auto& p : v) f << "v " << p[0] << " " << p[1] << " " << p[2] << "\n";
  for (auto& p : v) f << "vn " << s * p[0] << " " << s * p[1] << " " << s * p[2] << "\n";
  for (const char* t : {"1//1 2//2 3//3", "1//1 4//4 2//2", "1//1 3//3 4//4", "2//2 4//4 3//3"}) f << "f " << t << "\n";
}

TEST(Defaults, EdgeLengthDefaultIsInHelpAndStats) {
  RunResult help = runSffd("deform --help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("(default a tenth of the mesh's largest extent)"), std::string::npos) << help.out;

  fs::path dir = tempDir("defaults_edge");
  writeBoxObj(dir / "box.obj", 0, 0, 0, 0.5);   // extent 1
  const std::string box = (dir / "box.obj").string(), l = (dir / "l.json").string();
  ASSERT_EQ(runSffd("lattice " + box + " -o " + l + " --quiet").status, 0);
  const std::string run = "deform " + box + " -l " + l + " --backend cpu --quiet -o " + (dir / "o.obj").string() + " --stats ";
  ASSERT_EQ(runSffd(run + (dir / "a.json").string()).status, 0);
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(slurp(dir / "a.json"))["edge_length"].get<double>(), 0.1);
  ASSERT_EQ(runSffd(run + (dir / "b.json").string() + " --edge-length 0.25").status, 0);
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(slurp(dir / "b.json"))["edge_length"].get<double>(), 0.25);
  ASSERT_EQ(runSffd(run + (dir / "c.json").string() + " --method classic").status, 0);
  EXPECT_TRUE(nlohmann::json::parse(slurp(dir / "c.json"))["edge_length"].is_null());
  // A mesh whose vertices all lie at one point has no extent to take a tenth of: it was refused with
  // "--edge-length must be a positive number", an option never given.
  std::ofstream(dir / "point.obj") << "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n";
  RunResult point = runSffd("deform " + (dir / "point.obj").string() + " -l " + l + " --backend cpu --quiet -o " +
                            (dir / "p.obj").string() + " --stats " + (dir / "p.json").string());
  ASSERT_EQ(point.status, 0) << point.err;
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(slurp(dir / "p.json"))["edge_length"].get<double>(), 1.0);
  fs::remove_all(dir);
}

TEST(Defaults, NormalsAgainstTheWindingAreWarnedAndCanBeIgnored) {
  fs::path dir = tempDir("defaults_normals");
  writeTetra(dir / "in.obj", true);
  writeTetra(dir / "out.obj", false);
  const std::string in = (dir / "in.obj").string(), outward = (dir / "out.obj").string(), l = (dir / "l.json").string();
  ASSERT_EQ(runSffd("lattice " + outward + " -o " + l + " --quiet").status, 0);
  const std::string tail = " -l " + l + " --backend cpu --method classic --quiet -o " + (dir / "o.obj").string();

  RunResult warned = runSffd("deform " + in + tail);
  EXPECT_EQ(warned.status, 0) << warned.err;
  EXPECT_NE(warned.err.find("sffd: warning: " + in + ": the file's normals point against the winding for 100% of the triangles; "
                            "the result follows the normals (--ignore-normals recomputes them from the winding)"),
            std::string::npos)
      << warned.err;
  EXPECT_EQ(std::count(warned.err.begin(), warned.err.end(), '\n'), 1) << warned.err;

  RunResult agree = runSffd("deform " + outward + tail);
  EXPECT_EQ(agree.status, 0) << agree.err;
  EXPECT_EQ(agree.err, "");

  // --ignore-normals: normals from the winding, so the written ones point out (the first vertex's along +x+y+z).
  RunResult ignored = runSffd("deform " + in + tail + " --ignore-normals");
  EXPECT_EQ(ignored.status, 0) << ignored.err;
  EXPECT_EQ(ignored.err, "");
  std::ifstream o(dir / "o.obj");
  std::string word;
  double x = 0, y = 0, z = 0;
  while (o >> word)
    if (word == "vn") {
      o >> x >> y >> z;
      break;
    }
  EXPECT_GT(x + y + z, 0) << x << " " << y << " " << z;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sffd::test
