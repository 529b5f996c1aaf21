// End-to-end: the file formats users exchange (docs/CLI.md "Mesh files"): binary output, attributes
// kept through every method, glTF written for Khronos' validator and read from an outside converter.
// The npm packages (gltf-validator, obj2gltf) are installed at test time into the build tree.
#include <gtest/gtest.h>

#include <algorithm>

#include "model/mesh.h"
#include "support/cli_runner.h"

namespace sffd::test {
namespace {

const std::string kData = SFFD_TEST_DATA;
const fs::path kNpm = fs::path(SFFD_BINARY).parent_path() / "npm";

// The npm packages in build/npm (installed once, under a lock: ctest runs tests in parallel); false
// when npm or its registry cannot be reached.
bool npmPackages() {
  if (fs::exists(kNpm / "node_modules/gltf-validator") && fs::exists(kNpm / "node_modules/.bin/obj2gltf")) return true;
  fs::create_directories(kNpm);
  const std::string cmd = "flock " + (kNpm / "lock").string() + " npm install --no-audit --no-fund --prefix " + kNpm.string() +
                          " gltf-validator obj2gltf >" + (kNpm / "install.log").string() + " 2>&1";
  return std::system(cmd.c_str()) == 0 && fs::exists(kNpm / "node_modules/gltf-validator");
}

// Khronos' glTF-Validator on `files`: its output, and whether every file had no error.
std::pair<bool, std::string> validateGltf(const std::vector<fs::path>& files) {
  std::string cmd = "NODE_PATH=" + (kNpm / "node_modules").string() + " node " + SFFD_SOURCE_DIR + "/tests/tools/gltf_validate.js";
  for (const fs::path& f : files) cmd += " " + f.string();
  const fs::path log = kNpm / ("validate_" + std::to_string(::getpid()) + ".log");
  const int raw = std::system((cmd + " >" + log.string() + " 2>&1").c_str());
  return {WIFEXITED(raw) && WEXITSTATUS(raw) == 0, slurp(log)};
}

// Texture coordinates at each triangle corner, to float resolution (glTF stores floats).
void expectSameCornerTexcoords(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  ASSERT_FALSE(a.texcoords.empty());
  ASSERT_FALSE(b.texcoords.empty());
  for (size_t f = 0; f < a.triangles.size(); ++f)
    for (int c = 0; c < 3; ++c) ASSERT_LE(glm::length(a.texcoords[a.triangles[f][c]] - b.texcoords[b.triangles[f][c]]), 1e-7) << f;
}
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

TEST(Formats, ObjKeepsTexcoordsThroughEveryMethod) {
  const fs::path dir = tempDir("formats_obj");
  const Mesh input = readMesh(kData + "/sphere.obj");
  ASSERT_FALSE(input.texcoords.empty());
  for (const char* method : {"classic", "smooth", "accurate"}) {
    const fs::path out = dir / (std::string(method) + ".obj");
    ASSERT_EQ(runSffd("deform " + kSphere + " --method " + method + " --edge-length 0.3 --tess 4 -o " + out.string()).status, 0);
    const Mesh r = readMesh(out.string());
    ASSERT_EQ(r.texcoords.size(), r.positions.size()) << method;
    // Classic: the same vertices with the same texture coordinates (17 digits: exact).
    if (std::string(method) == "classic") EXPECT_EQ(r.texcoords, input.texcoords);
  }
  fs::remove_all(dir);
}

TEST(Formats, GltfOutputValidatesAndKeepsTexcoords) {
  if (!npmPackages()) GTEST_SKIP() << "npm cannot install gltf-validator (no registry?): see " << (kNpm / "install.log");
  const fs::path dir = tempDir("formats_gltf");
  std::vector<fs::path> written;
  for (const char* method : {"classic", "smooth", "accurate"})
    for (const char* ext : {".glb", ".gltf"}) {
      const fs::path out = dir / (std::string(method) + ext);
      const RunResult r = runSffd("deform " + kSphere + " --method " + method + " --edge-length 0.3 --tess 4 -o " + out.string());
      ASSERT_EQ(r.status, 0) << r.err;
      written.push_back(out);
      // What the same run writes as OBJ, read back: the same corners' texture coordinates.
      const fs::path obj = dir / (std::string(method) + ext + ".obj");
      ASSERT_EQ(runSffd("deform " + kSphere + " --method " + method + " --edge-length 0.3 --tess 4 -o " + obj.string()).status, 0);
      expectSameCornerTexcoords(readMesh(obj.string()), readMesh(out.string()));
    }
  EXPECT_TRUE(fs::exists(dir / "smooth.bin"));
  const auto [ok, report] = validateGltf(written);
  EXPECT_TRUE(ok) << report;
  fs::remove_all(dir);
}

TEST(Formats, GlbFromObj2gltfIsReadAndDeformed) {
  if (!npmPackages()) GTEST_SKIP() << "npm cannot install obj2gltf (no registry?): see " << (kNpm / "install.log");
  const fs::path dir = tempDir("formats_obj2gltf");
  const fs::path glb = dir / "sphere.glb";
  ASSERT_EQ(std::system(((kNpm / "node_modules/.bin/obj2gltf").string() + " -i " + kData + "/sphere.obj -o " + glb.string() + " >/dev/null 2>&1").c_str()), 0);
  const Mesh converted = readMesh(glb.string()), original = readMesh(kData + "/sphere.obj");
  expectSameCornerTexcoords(original, converted);   // obj2gltf keeps the OBJ's triangles and flips v; the reader flips back
  const fs::path out = dir / "deformed.glb";
  const std::string lattice = kData + "/lattices/sphere_twist.npy --normalize 0.99 --backend cpu --quiet";
  ASSERT_EQ(runSffd("deform " + glb.string() + " -l " + lattice + " --method smooth --edge-length 0.3 --tess 4 -o " + out.string()).status, 0);
  EXPECT_FALSE(readMesh(out.string()).texcoords.empty());
  const auto [ok, report] = validateGltf({out});
  EXPECT_TRUE(ok) << report;
  fs::remove_all(dir);
}

TEST(Formats, BadGltfIsOneErrorLine) {
  const fs::path dir = tempDir("formats_bad_gltf");
  const std::pair<const char*, const char*> cases[] = {
      {"truncated.gltf", "{\"asset\": {\"version\": \"2.0\"}"},
      {"noscene.gltf", "{\"asset\": {\"version\": \"2.0\"}}"},
      {"badglb.glb", "glTF\x02\x00\x00\x00\xff\xff\x00\x00"},
      {"outside.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}],"
                       "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}}]}],"
                       "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\"}],"
                       "\"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}],"
                       "\"buffers\": [{\"byteLength\": 12, \"uri\": \"data:application/octet-stream;base64,AAAAAAAAAAAAAAAA\"}]}"}};
  for (const auto& [name, text] : cases) {
    std::ofstream(dir / name) << text;
    const RunResult r = runSffd("deform " + (dir / name).string() + " -l " + kData + "/lattices/sphere_twist.npy -o " + (dir / "x.obj").string());
    EXPECT_EQ(r.status, 2) << name << ": " << r.err;
    EXPECT_EQ(r.err.rfind("sffd: error: " + (dir / name).string() + ": ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(dir / "x.obj"));
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sffd::test
