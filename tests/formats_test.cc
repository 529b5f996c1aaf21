// End-to-end: the file formats users exchange (docs/CLI.md "Mesh files"): binary output, attributes
// kept through every method, glTF written for Khronos' validator and read from an outside converter.
// The npm packages (gltf-validator, obj2gltf) are installed at test time into the build tree.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include <nlohmann/json.hpp>

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
    if (std::string(method) == "classic") { EXPECT_EQ(r.texcoords, input.texcoords); }
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
  // The test sphere with a material whose texture is a 2 x 2 PNG: obj2gltf embeds the image in the .glb.
  {
    std::ofstream(dir / "sphere.obj") << "mtllib sphere.mtl\nusemtl painted\n" << slurp(kData + "/sphere.obj");
    std::ofstream(dir / "sphere.mtl") << "newmtl painted\nKd 1 1 1\nmap_Kd paint.png\n";
    std::ofstream(dir / "paint.png", std::ios::binary)
        << std::string("\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x00\x00\x02\x00\x00\x00\x02\x08\x02\x00"
                       "\x00\x00\xfd\xd4\x9a\x73\x00\x00\x00\x10\x49\x44\x41\x54\x78\x9c\x63\x38\x91\x62\x04\x44\x0c\x10\x0a\x00"
                       "\x28\xae\x05\x79\x42\xe1\x27\xee\x00\x00\x00\x00\x49\x45\x4e\x44\xae\x42\x60\x82", 73);
  }
  const fs::path glb = dir / "sphere.glb";
  ASSERT_EQ(std::system(((kNpm / "node_modules/.bin/obj2gltf").string() + " -i " + (dir / "sphere.obj").string() + " -o " + glb.string() + " >/dev/null 2>&1").c_str()), 0);
  const Mesh converted = readMesh(glb.string()), original = readMesh(kData + "/sphere.obj");
  expectSameCornerTexcoords(original, converted);   // obj2gltf keeps the OBJ's triangles and flips v; the reader flips back
  const fs::path out = dir / "deformed.glb";
  const std::string lattice = kData + "/lattices/sphere_twist.npy --normalize 0.99 --backend cpu --quiet";
  ASSERT_EQ(runSffd("deform " + glb.string() + " -l " + lattice + " --method smooth --edge-length 0.3 --tess 4 -o " + out.string()).status, 0);
  const Mesh deformed = readMesh(out.string());
  EXPECT_FALSE(deformed.texcoords.empty());
  // The embedded texture is passed through: the same PNG bytes in the output.
  ASSERT_EQ(deformed.materials.size(), 1u);
  EXPECT_EQ(deformed.materials[0].baseColorImageMime, "image/png");
  EXPECT_EQ(std::string(deformed.materials[0].baseColorImage.begin(), deformed.materials[0].baseColorImage.end()), slurp(dir / "paint.png"));
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

// Frames of `sffd animate` are separate `sffd deform` runs of the interpolated lattices, byte for byte.
TEST(Formats, AnimateFramesEqualSeparateDeforms) {
  const fs::path dir = tempDir("formats_animate");
  const std::string mesh = kData + "/sphere.obj";
  for (const auto& [name, preset] : {std::pair{"ident", ""}, {"twist", " --preset twist:0.8"}, {"bend", " --preset bend:1.0"}})
    ASSERT_EQ(runSffd("lattice " + mesh + " --quiet -o " + (dir / (std::string(name) + ".json")).string() + preset).status, 0);
  const std::string keys = " -l " + (dir / "ident.json").string() + " -l " + (dir / "twist.json").string() + " -l " + (dir / "bend.json").string();
  const std::string options = " --backend cpu --quiet --edge-length 0.3 --tess 4 --precision float";
  // 5 frames over 3 keys: the keys at frames 0, 2, 4, their midpoints at 1 and 3.
  ASSERT_EQ(runSffd("animate " + mesh + keys + " --frames 5 -o " + (dir / "f_%d.ply").string() + options).status, 0);
  auto controlPoints = [&](const char* name) { return nlohmann::json::parse(slurp(dir / name))["control_points"]; };
  const nlohmann::json lattices[3] = {controlPoints("ident.json"), controlPoints("twist.json"), controlPoints("bend.json")};
  for (int f = 0; f < 5; ++f) {
    nlohmann::json L = nlohmann::json::parse(slurp(dir / "ident.json"));
    const nlohmann::json &a = lattices[f / 2], &b = lattices[std::min(f / 2 + 1, 2)];
    for (size_t i = 0; i < L["control_points"].size(); ++i)
      for (int c = 0; c < 3; ++c)
        L["control_points"][i][c] = f % 2 ? 0.5 * a[i][c].get<double>() + 0.5 * b[i][c].get<double>() : a[i][c].get<double>();
    std::ofstream(dir / "frame.json") << L.dump();
    ASSERT_EQ(runSffd("deform " + mesh + " -l " + (dir / "frame.json").string() + " -o " + (dir / "frame.ply").string() + options).status, 0);
    EXPECT_EQ(slurp(dir / ("f_" + std::to_string(f) + ".ply")), slurp(dir / "frame.ply")) << "frame " << f;
  }
  // As glTF: morph targets and an animation that Khronos' validator accepts; mixed structures refused.
  ASSERT_EQ(runSffd("animate " + mesh + keys + " --frames 5 --fps 10 -o " + (dir / "anim.glb").string() + options).status, 0);
  const Mesh first = readMesh((dir / "anim.glb").string()), frame0 = readMesh((dir / "f_0.ply").string());
  EXPECT_EQ(first.triangles.size(), frame0.triangles.size());
  ASSERT_EQ(runSffd("lattice " + mesh + " --quiet --counts 4,4,4 -o " + (dir / "other.json").string()).status, 0);
  const RunResult r = runSffd("animate " + mesh + " -l " + (dir / "ident.json").string() + " -l " + (dir / "other.json").string() +
                              " --frames 3 -o " + (dir / "x.glb").string() + options);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("differ from"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "x.glb"));
  if (npmPackages()) {
    const auto [ok, report] = validateGltf({dir / "anim.glb"});
    EXPECT_TRUE(ok) << report;
  }
  fs::remove_all(dir);
}

// A .gltf writes NAME.bin beside it: where that is the buffer an input .gltf reads, the output is refused
// (it overwrote the buffer, and the input could not be read again).
TEST(Formats, GltfOutputNeverOverwritesAnInputsBuffer) {
  const fs::path dir = tempDir("formats_gltf_buffer");
  ASSERT_EQ(runSffd("deform " + kSphere + " --method classic -o " + (dir / "a.gltf").string()).status, 0);
  fs::copy_file(dir / "a.gltf", dir / "in.gltf");   // reads a.bin
  const std::string before = slurp(dir / "a.bin");
  const std::string job = "deform " + (dir / "in.gltf").string() + " -l " + kData + "/lattices/sphere_twist.npy --backend cpu --quiet -o ";
  RunResult r = runSffd(job + (dir / "a.gltf").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err, "sffd: error: " + (dir / "a.bin").string() + ": output path is an input file; refusing to overwrite it\n");
  EXPECT_EQ(slurp(dir / "a.bin"), before);
  // Nor may a file written after the output be its .bin (--stats overwrote it).
  r = runSffd(job + (dir / "c.gltf").string() + " --stats " + (dir / "c.bin").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_FALSE(fs::exists(dir / "c.gltf"));
  EXPECT_EQ(runSffd(job + (dir / "b.gltf").string()).status, 0);
  fs::remove_all(dir);
}

// A frame that cannot be written leaves nothing: the numbered frames written before it went too (they were
// left), and a glTF is never written with values its floats cannot hold (it was, with infinities: Khronos'
// validator refused it, sffd said nothing), nor with key times past a float (a tiny --fps).
TEST(Formats, AnimateLeavesNothingWhenAFrameCannotBeWritten) {
  const fs::path dir = tempDir("formats_animate_fail");
  writeBoxObj(dir / "box.obj", 0, 0, 0, 1);
  const std::string box = (dir / "box.obj").string(), l0 = (dir / "l0.json").string(), far = (dir / "far.json").string();
  ASSERT_EQ(runSffd("lattice " + box + " --quiet -o " + l0).status, 0);
  ASSERT_EQ(runSffd("lattice " + box + " --quiet -o " + far + " --preset noise:1e300").status, 0);
  const std::string job = "animate " + box + " -l " + l0 + " -l " + far + " --frames 3 --backend cpu --method classic --quiet -o ";
  auto expectRefused = [&](const RunResult& r, const std::string& what) {
    EXPECT_EQ(r.status, 2) << what << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << what << "\n" << r.err;
    for (const auto& f : fs::directory_iterator(dir))
      if (f.path().extension() != ".obj" && f.path().extension() != ".json") {
        ADD_FAILURE() << what << ": left " << f.path();
        fs::remove(f.path());
      }
  };
  expectRefused(runSffd(job + (dir / "f_%d.ply").string()), "numbered frames");   // frame 0 is fine, frame 1 not finite
  // Files the frames would replace, one through a link, are as they were (a failing frame 1 took away the
  // user's frame 0, and the file at the end of the link).
  std::ofstream(dir / "g_0.ply") << "the user's frame 0";
  std::ofstream(dir / "target.ply") << "the user's target";
  fs::create_symlink("target.ply", dir / "g_1.ply");
  std::ofstream(dir / "g_2.ply") << "the user's frame 2";
  const std::string l1 = (dir / "l1.json").string();
  ASSERT_EQ(runSffd("lattice " + box + " --quiet -o " + l1 + " --preset twist:0.5").status, 0);
  RunResult failed = runSffd("animate " + box + " -l " + l0 + " -l " + l1 + " -l " + far + " --frames 5 --backend cpu --method classic --quiet -o " +
                             (dir / "g_%d.ply").string());   // frames 0 to 2 written, frame 3 not finite
  EXPECT_EQ(failed.status, 2) << failed.err;
  EXPECT_EQ(slurp(dir / "g_0.ply"), "the user's frame 0");
  EXPECT_EQ(slurp(dir / "target.ply"), "the user's target");
  EXPECT_TRUE(fs::is_symlink(dir / "g_1.ply"));
  EXPECT_EQ(slurp(dir / "g_2.ply"), "the user's frame 2");
  for (const char* f : {"g_0.ply", "g_1.ply", "g_2.ply", "target.ply"}) fs::remove(dir / f);
  expectRefused(failed, "frames that replace files");
  expectRefused(runSffd(job + (dir / "a.glb").string()), "glTF");
  // A double result past a float's range: finite in the other formats, not in glTF's floats.
  ASSERT_EQ(runSffd("lattice " + box + " --quiet -o " + far + " --preset bend:1e300").status, 0);
  RunResult r = runSffd("deform " + box + " -l " + far + " --backend cpu --method classic --precision double --quiet -o " +
                        (dir / "b.glb").string());
  EXPECT_NE(r.err.find("b.glb: not written: vertex 0 is not finite or beyond the range of glTF's floats"), std::string::npos) << r.err;
  expectRefused(r, "double result as glTF");
  r = runSffd("animate " + box + " -l " + l0 + " -l " + l0 + " --frames 3 --fps 1e-300 --backend cpu --quiet -o " + (dir / "t.glb").string());
  EXPECT_NE(r.err.find("--fps 1e-300 puts the last frame past the seconds a glTF key time (a float) holds"), std::string::npos) << r.err;
  expectRefused(r, "tiny --fps");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sffd::test
