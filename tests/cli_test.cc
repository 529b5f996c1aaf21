// End-to-end tests of the sffd command line: the PyGeM oracle through every backend, the contract's
// errors and exit statuses, and outputs that appear whole or not at all.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "model/mesh.h"
#include "tests/support/cli_runner.h"

namespace fs = std::filesystem;

namespace {

const std::string kData = SFFD_TEST_DATA;

using sffd::test::RunResult;
using sffd::test::runSffd;
using sffd::test::slurp;
using sffd::test::tempDir;
using sffd::test::usable;
using sffd::test::hasDevice;
using sffd::test::hasDoubles;

std::vector<glm::dvec3> readPoints(const std::string& path) {
  std::ifstream f(path);
  std::vector<glm::dvec3> pts;
  double x, y, z;
  while (f >> x >> y >> z) pts.push_back({x, y, z});
  return pts;
}

// One line, "sffd: error: ...", on stderr.
void expectOneErrorLine(const RunResult& r) {
  EXPECT_EQ(r.err.rfind("sffd: error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

class PygemOracle : public ::testing::TestWithParam<std::string> {};

// PyGeM's test_ffd_sphere_mod: every facet corner of test_sphere.stl, deformed, equals PyGeM's
// expected_points.txt within PyGeM's 1.5e-6 (1e-10 for the CPU reference), outside points unmoved.
TEST_P(PygemOracle, SphereMatchesExpectedPoints) {
  if (!usable(GetParam())) GTEST_SKIP() << GetParam() << " is not on this machine";
  // 1.5e-6 is below float's resolution at the sphere's coordinates: classic FFD meets it in double.
  if (hasDevice(GetParam()) && !hasDoubles(GetParam())) GTEST_SKIP() << GetParam() << " has no double precision here";
  fs::path dir = tempDir("pygem_" + GetParam());
  std::string out = (dir / "sphere.obj").string();
  std::string base = kData + "/pygem/sphere_ffd/";
  RunResult r = runSffd("deform " + base + "test_sphere.stl -l " + base + "parameters_test_ffd_sphere.prm --method classic --backend " +
                        GetParam() + " -o " + out + " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  sffd::Mesh in = sffd::readMesh(base + "test_sphere.stl");
  sffd::Mesh res = sffd::readMesh(out);
  ASSERT_EQ(in.positions.size(), res.positions.size());
  std::vector<glm::dvec3> input = readPoints(base + "input_points.txt"), expected = readPoints(base + "expected_points.txt");
  ASSERT_EQ(input.size(), 7200u);
  double tol = GetParam() == "cpu" ? 1e-10 : 1.5e-6;
  double worst = 0;
  size_t moved = 0, unmoved = 0;
  for (size_t i = 0; i < input.size(); ++i) {
    // Find the vertex of the (welded) mesh at this facet corner.
    size_t v = 0;
    double best = 1e30;
    for (size_t k = 0; k < in.positions.size(); ++k) {
      double d = glm::length(in.positions[k] - input[i]);
      if (d < best) best = d, v = k;
    }
    ASSERT_LT(best, 1e-9) << "facet corner " << i << " not found in the mesh as read";
    for (int a = 0; a < 3; ++a) worst = std::max(worst, std::abs(res.positions[v][a] - expected[i][a]));
    if (glm::length(expected[i] - input[i]) > 1e-9) ++moved;
    else {
      ++unmoved;
      EXPECT_EQ(res.positions[v], in.positions[v]) << "an outside point moved";
    }
  }
  EXPECT_LT(worst, tol);
  EXPECT_EQ(moved, 3932u);
  EXPECT_EQ(unmoved, 3268u);
  RecordProperty("max_abs_error", std::to_string(worst));
  std::printf("PyGeM sphere, backend %s: max |ours - expected| = %.3g over 7200 corners\n", GetParam().c_str(), worst);
}

INSTANTIATE_TEST_SUITE_P(Backends, PygemOracle, ::testing::Values("cpu", "vulkan", "gl-egl", "gl-osmesa"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& c : n) if (c == '-') c = '_';
                           return n;
                         });

TEST(Cli, IdentityPrmLeavesTheSphere) {
  fs::path dir = tempDir("identity");
  std::string out = (dir / "id.obj").string();
  RunResult r = runSffd("deform " + kData + "/pygem/sphere_ffd/input_welded.obj -l " + kData +
                        "/pygem/identity/parameters_test_ffd_identity.prm --method classic -o " + out + " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  sffd::Mesh in = sffd::readMesh(kData + "/pygem/sphere_ffd/input_welded.obj"), res = sffd::readMesh(out);
  ASSERT_EQ(in.positions.size(), res.positions.size());
  for (size_t v = 0; v < in.positions.size(); ++v) EXPECT_NEAR(glm::length(in.positions[v] - res.positions[v]), 0, 1e-9);
}

TEST(Cli, LatticeThenDeformWritesStats) {
  fs::path dir = tempDir("lattice");
  std::string lat = (dir / "twist.json").string(), out = (dir / "t.ply").string(), stats = (dir / "s.json").string();
  RunResult r = runSffd("lattice " + kData + "/sphere.obj -o " + lat + " --preset twist:0.5 --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  r = runSffd("deform " + kData + "/sphere.obj -l " + lat + " --method classic -o " + out + " --stats " + stats + " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream sf(stats);
  nlohmann::json j = nlohmann::json::parse(sf);
  EXPECT_EQ(j["method"], "classic");
  EXPECT_EQ(j["input"]["triangles"], j["output"]["triangles"]);
  EXPECT_TRUE(j["timings_ms"].contains("deform"));
  EXPECT_TRUE(j.contains("backend") && j.contains("device"));
  // The host phases account for the whole run: each non-negative, together within its total.
  double phases = 0;
  for (const char* k : {"read", "open_device", "checks", "prepare", "deform", "result", "write"}) {
    ASSERT_TRUE(j["host_ms"].contains(k)) << k;
    EXPECT_GE(j["host_ms"][k].get<double>(), -1e-6) << k;
    phases += j["host_ms"][k].get<double>();
  }
  EXPECT_LE(phases, j["timings_ms"]["total"].get<double>() + 1e-6);
  EXPECT_EQ(j["host_ms"]["weld"].get<double>(), 0.0);   // classic welds nothing
}

// Smooth and accurate weld their output on the host: host_ms.weld is that part of result, and not 0.
TEST(Cli, StatsGiveTheWeldsShareOfTheResult) {
  fs::path dir = tempDir("weld_stats");
  for (const char* method : {"smooth", "accurate"}) {
    const std::string stats = (dir / (std::string(method) + ".json")).string();
    RunResult r = runSffd("deform " + kData + "/sphere.obj -l " + kData + "/lattices/sphere_twist.npy --tess 3 --method " + method +
                          " --backend cpu -o " + (dir / "t.ply").string() + " --stats " + stats + " --quiet");
    ASSERT_EQ(r.status, 0) << r.err;
    std::ifstream sf(stats);
    nlohmann::json j = nlohmann::json::parse(sf);
    EXPECT_GT(j["host_ms"]["weld"].get<double>(), 0.0) << method;
    EXPECT_LE(j["host_ms"]["weld"].get<double>(), j["host_ms"]["result"].get<double>()) << method;
  }
}

// The shader cache's counts in --stats: where the Vulkan driver has VK_EXT_shader_object (lavapipe 25),
// a first run stores each kernel's binary and a second makes every kernel from them; elsewhere all 0.
TEST(Cli, StatsCountTheShaderCache) {
  fs::path dir = tempDir("shader_cache");
  const std::string stats = (dir / "s.json").string(), env = "SFFD_SHADER_CACHE_DIR=" + (dir / "cache").string();
  auto run = [&] {
    RunResult r = runSffd("deform " + kData + "/sphere.obj -l " + kData + "/lattices/sphere_twist.npy --tess 2 -o " +
                              (dir / "t.ply").string() + " --stats " + stats + " --quiet",
                          env);
    EXPECT_EQ(r.status, 0) << r.err;
    std::ifstream sf(stats);
    return nlohmann::json::parse(sf);
  };
  nlohmann::json first = run(), second = run();
  ASSERT_TRUE(first.contains("shader_cache")) << first.dump();
  const nlohmann::json& a = first["shader_cache"];
  const nlohmann::json& b = second["shader_cache"];
  if (a["misses"] == 0) {   // not in use on this device
    EXPECT_EQ(a, (nlohmann::json{{"hits", 0}, {"misses", 0}, {"stores", 0}}));
    EXPECT_FALSE(fs::exists(dir / "cache"));
    return;
  }
  EXPECT_EQ(first["backend"], "vulkan");
  EXPECT_EQ(a["hits"], 0);
  EXPECT_EQ(a["stores"], a["misses"]);
  EXPECT_EQ(b["hits"], a["misses"]);
  EXPECT_EQ(b["misses"], 0);
  EXPECT_EQ(b["stores"], 0);
}

// Accurate FFD's stats add its three dispatches' times, which make up its deform stage.
TEST(Cli, AccurateStatsGiveTheKernelsSteps) {
  fs::path dir = tempDir("accurate_steps");
  const std::string stats = (dir / "s.json").string();
  RunResult r = runSffd("deform " + kData + "/sphere.obj -l " + kData + "/lattices/sphere_twist.npy --method accurate --tess 3 -o " +
                        (dir / "a.ply").string() + " --backend cpu --stats " + stats + " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream sf(stats);
  const nlohmann::json t = nlohmann::json::parse(sf)["timings_ms"];
  double steps = 0;
  for (const char* k : {"accurate_samples", "accurate_patches", "accurate_tessellate"}) {
    ASSERT_TRUE(t.contains(k)) << k;
    EXPECT_GE(t[k].get<double>(), 0) << k;
    steps += t[k].get<double>();
  }
  EXPECT_NEAR(steps, t["deform"].get<double>(), 1e-6 + 1e-9 * steps);
}

// The CPU reference and every backend this machine must have (SFFD_REQUIRE_BACKENDS), each line
// naming its backend and then its device.
TEST(Cli, DevicesListsEveryRequiredBackend) {
  RunResult r = runSffd("devices");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const std::string& n : sffd::testing::testBackends())
    if (n == "cpu" || sffd::testing::requiredHere(n)) {
      EXPECT_NE(("\n" + r.out).find("\n" + n + " "), std::string::npos) << n << "\n" << r.out;
    }
  std::stringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    std::string backend, device;
    std::stringstream(line) >> backend >> device;
    EXPECT_FALSE(device.empty()) << line;
  }
}

TEST(Cli, MissingVulkanLoaderIsADeviceError) {
  RunResult r = runSffd("deform " + kData + "/cube.obj -l " + kData + "/lattices/cube_bend.npy --method classic --backend vulkan -o /tmp/never.obj",
                        "SFFD_VULKAN_LIBRARY=libvulkan-missing.so.9");
  EXPECT_EQ(r.status, 3);
  expectOneErrorLine(r);
  EXPECT_FALSE(fs::exists("/tmp/never.obj"));
}

// The inputs are read while the device opens (loadJobAndOpenDevice): a bad input is still the one error
// reported when the device fails too, as when the inputs were read first, and a good one gives the device's.
TEST(Cli, AnInputErrorWinsOverADeviceError) {
  const std::string lattice = " -l " + kData + "/lattices/cube_bend.npy --backend vulkan";
  const std::string noDevice = "SFFD_VULKAN_LIBRARY=libvulkan-missing.so.9";
  for (std::string command : {"deform -o /tmp/never.obj ", "error "}) {
    RunResult r = runSffd(command + kData + "/no-such-mesh.obj" + lattice, noDevice);
    EXPECT_EQ(r.status, 2) << command << " " << r.err;
    expectOneErrorLine(r);
    EXPECT_NE(r.err.find("no-such-mesh.obj"), std::string::npos) << r.err;
    r = runSffd(command + kData + "/cube.obj" + lattice, noDevice);
    EXPECT_EQ(r.status, 3) << command << " " << r.err;
    expectOneErrorLine(r);
  }
  EXPECT_FALSE(fs::exists("/tmp/never.obj"));
}

TEST(Cli, MissingIcdIsADeviceErrorAndAutoFallsBack) {
  std::string args = "deform " + kData + "/cube.obj -l " + kData + "/lattices/cube_bend.npy --method classic ";
  fs::path dir = tempDir("fallback");
  RunResult r = runSffd(args + "--backend vulkan -o " + (dir / "a.obj").string(), "VK_DRIVER_FILES=/nonexistent.json VK_ICD_FILENAMES=/nonexistent.json");
  EXPECT_EQ(r.status, 3);
  expectOneErrorLine(r);
  r = runSffd(args + "--backend auto -o " + (dir / "b.obj").string(), "VK_DRIVER_FILES=/nonexistent.json VK_ICD_FILENAMES=/nonexistent.json");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "b.obj"));
}

TEST(Cli, ErrorsHaveOneLineAndTheContractStatus) {
  fs::path dir = tempDir("errors");
  std::string out = (dir / "o.obj").string();
  std::string cube = kData + "/cube.obj", lat = kData + "/lattices/cube_bend.npy";
  struct Case { std::string args; int status; };
  std::vector<Case> cases = {
      {"", 2},
      {"frobnicate", 2},
      {"deform " + cube + " -o " + out, 2},                                        // no lattice
      {"deform " + cube + " -l " + lat + " --method classic", 2},                  // no output
      {"deform " + cube + " -l " + lat + " --method nope -o " + out, 2},
      {"deform " + cube + " -l " + lat + " --method classic --bogus -o " + out, 2},
      {"deform /nonexistent.obj -l " + lat + " --method classic -o " + out, 2},
      {"deform " + cube + " -l /nonexistent.json --method classic -o " + out, 2},
      {"deform " + cube + " -l " + lat + " --method classic -o " + cube, 2},      // output = input
      {"deform " + cube + " -l " + lat + " --method classic --backend metal -o " + out, 2},
      {"deform " + cube + " -l " + lat + " --method classic --device no-such-gpu --backend vulkan -o " + out, 3},
      {"deform " + cube + " -l " + lat + " --method classic -o /nonexistent-dir/o.obj", 2},
      {"lattice " + cube + " -o " + (dir / "l.json").string() + " --degree 6,2,2", 2},
      {"lattice " + cube + " -o " + (dir / "l.json").string() + " --preset wobble", 2},
  };
  for (const Case& c : cases) {
    RunResult r = runSffd(c.args);
    EXPECT_EQ(r.status, c.status) << c.args << "\n" << r.err;
    expectOneErrorLine(r);
  }
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(dir / "l.json"));
  for (const auto& e : fs::directory_iterator(dir)) ADD_FAILURE() << "left behind: " << e.path();
}

TEST(Cli, HelpForEveryCommand) {
  for (const char* c : {"deform", "lattice", "devices", "conform", "bench"}) {
    RunResult r = runSffd(std::string(c) + " --help");
    EXPECT_EQ(r.status, 0) << c;
    EXPECT_NE(r.out.find("usage: sffd"), std::string::npos) << c;
  }
}

TEST(Cli, ConformPassesAndStrictIsBitIdentical) {
  std::string base = "conform " + kData + "/sphere.obj -l " + kData + "/lattices/sphere_twist.npy --method classic";
  RunResult r = runSffd(base);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("conform: PASS"), std::string::npos) << r.out;
  r = runSffd(base + " --strict");
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("max_abs=0 max_ulp=0 mismatched=0/"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("max_ulp=1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("conform: PASS"), std::string::npos) << r.out;
}

}  // namespace

namespace {

TEST(Cli, ClipWritesACrackFreeSubTriangleMeshAndStats) {
  fs::path dir = tempDir("clip");
  for (const char* clip : {"regular", "knot-box"}) {
    std::string out = (dir / (std::string(clip) + ".obj")).string(), stats = (dir / (std::string(clip) + ".json")).string();
    RunResult r = runSffd("clip " + kData + "/cube2.obj -l " + kData + "/lattices/cube2_twist.npy --edge-length 0.3 --clip " +
                          clip + " -o " + out + " --stats " + stats + " --quiet");
    ASSERT_EQ(r.status, 0) << r.err;
    sffd::Mesh m = sffd::readMesh(out);
    // Closed: every welded edge shared by exactly two triangles.
    std::map<std::pair<uint32_t, uint32_t>, int> uses;
    for (const auto& t : m.triangles)
      for (int e = 0; e < 3; ++e) {
        uint32_t a = m.weldId[t[e]], b = m.weldId[t[(e + 1) % 3]];
        ++uses[{std::min(a, b), std::max(a, b)}];
      }
    for (const auto& [edge, n] : uses) EXPECT_EQ(n, 2) << clip;
    std::ifstream sf(stats);
    nlohmann::json j = nlohmann::json::parse(sf);
    EXPECT_EQ(j["clip"], clip);
    EXPECT_EQ(j["sub_triangles"], m.triangles.size());
    EXPECT_GT(j["quality"]["min_angle_deg"].get<double>(), 0.0);
  }
}

TEST(Cli, CreaseAngleAutoIsTheDefaultAndANumberIsAFixedThreshold) {
  // teapot_8x8.obj has no normals: 149 edges bend by more than 40 degrees and split a vertex; the
  // relative rule keeps 131 of them (the lid rim, the patch seams; docs/METHOD.md 3.1's table).
  fs::path dir = tempDir("crease_angle");
  auto creases = [&](const std::string& option) {
    const std::string stats = (dir / "s.json").string();
    RunResult r = runSffd("clip " + kData + "/teapot_8x8.obj -l " + kData + "/lattices/teapot_identity.npy --edge-length 1 -o " +
                          (dir / "sub.obj").string() + " --stats " + stats + " --quiet " + option);
    EXPECT_EQ(r.status, 0) << option << r.err;
    std::ifstream sf(stats);
    return nlohmann::json::parse(sf)["topology"]["crease_edges"].get<int>();
  };
  EXPECT_EQ(creases(""), 131);
  EXPECT_EQ(creases("--crease-angle auto"), 131);
  EXPECT_EQ(creases("--crease-angle 40"), 149);
  EXPECT_EQ(creases("--crease-angle 180"), 0);
  for (const char* bad : {"-1", "181", "sharp"}) {
    RunResult r = runSffd("clip " + kData + "/teapot_8x8.obj -l " + kData + "/lattices/teapot_identity.npy -o " +
                          (dir / "never.obj").string() + " --crease-angle " + bad);
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_NE(r.err.find("--crease-angle"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "never.obj"));
}

TEST(Cli, ClipRefusesAnAbsurdEdgeLength) {
  RunResult r = runSffd("clip " + kData + "/torus.obj -l " + kData + "/lattices/torus_twist.npy --edge-length 1e-6 -o /tmp/never_clip.obj");
  EXPECT_EQ(r.status, 2);
  expectOneErrorLine(r);
  EXPECT_NE(r.err.find("sub-triangles"), std::string::npos) << r.err;
  r = runSffd("clip " + kData + "/cube2.obj -l " + kData + "/lattices/cube2_twist.npy --edge-length -1 -o /tmp/never_clip.obj");
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(fs::exists("/tmp/never_clip.obj"));
}

}  // namespace

namespace {

TEST(Cli, RenderColoursByError) {
  fs::path dir = tempDir("render_error");
  std::string out = (dir / "e.png").string();
  RunResult r = runSffd("render " + kData + "/cube2.obj -l " + kData +
                        "/lattices/cube2_twist.npy --edge-length 0.5 --color-by normal --width 160 --height 120 -o " + out + " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream f(out, std::ios::binary);
  char sig[8] = {};
  f.read(sig, 8);
  EXPECT_EQ(std::string(sig + 1, 3), "PNG");
  r = runSffd("render " + kData + "/cube2.obj --color-by normal -o " + (dir / "f.png").string());
  EXPECT_EQ(r.status, 2);   // colouring by error needs a lattice
  EXPECT_FALSE(fs::exists(dir / "f.png"));
}

}  // namespace

// bench --json: the contract's keys, one run per backend asked, stage times from each, the split steps.
TEST(Cli, BenchJsonHasTheContractKeysOnEveryBackend) {
  RunResult r = runSffd("bench " + kData + "/sphere.obj -l " + kData +
                        "/lattices/sphere_twist.npy --normalize 0.99 --edge-length 0.12 --tess 4 "
                        "--backends vulkan,gl,cpu --repeat 3 --warmup 1 --split --json --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["mesh"], "sphere.obj");
  EXPECT_EQ(j["method"], "smooth");
  EXPECT_GT(j["sub_triangles"].get<int>(), 720);
  EXPECT_EQ(j["output_triangles"].get<int>(), j["sub_triangles"].get<int>() * 16);
  ASSERT_EQ(j["runs"].size(), 3u);
  std::vector<std::string> backends;
  for (const auto& run : j["runs"]) {
    backends.push_back(run["backend"]);
    EXPECT_EQ(run["repeat"], 3);
    EXPECT_FALSE(run["driver"].get<std::string>().empty()) << run["backend"];
    EXPECT_GT(run["cold_first_dispatch_ms"].get<double>(), 0.0);
    EXPECT_GT(run["peak_rss_mb"].get<double>(), 1.0);
    for (const char* k : {"hits", "misses", "stores"}) EXPECT_TRUE(run["shader_cache"][k].is_number()) << run["backend"] << " " << k;
    if (run["backend"] != "vulkan") {
      EXPECT_EQ(run["shader_cache"]["misses"], 0) << run["backend"];   // Vulkan's only
    }
    for (const char* stage : {"pn", "clip", "deform", "total"}) {
      const auto& st = run["stages_ms"][stage];
      EXPECT_LE(st["min"].get<double>(), st["median"].get<double>()) << stage;
      EXPECT_LE(st["median"].get<double>(), st["max"].get<double>()) << stage;
      EXPECT_GT(st["max"].get<double>(), 0.0) << run["backend"] << " " << stage;
    }
    EXPECT_TRUE(run["stages_ms"].contains("deform.sample")) << run["backend"];
  }
  EXPECT_EQ(backends, (std::vector<std::string>{"vulkan", "gl-egl", "cpu"}));
}

TEST(Cli, BenchRefusesBadOptions) {
  const std::string base = "bench " + kData + "/sphere.obj -l " + kData + "/lattices/sphere_twist.npy ";
  for (const std::string& bad : {std::string("--repeat 0"), std::string("--method classic"), std::string("--backends nope"),
                                 std::string("--tess 0"), std::string("--edge-length -1")}) {
    RunResult r = runSffd(base + bad);
    EXPECT_EQ(r.status, 2) << bad << ": " << r.err;
    expectOneErrorLine(r);
  }
}
