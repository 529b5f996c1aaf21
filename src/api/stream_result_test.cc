// Deformer::streamResult into MeshFileWriter gives the bytes writeMesh writes of result(), for every
// format (streamed: .ply and .stl, text and binary; gathered: the others, and .ply with colours), every
// method, several chunks, a model far from the origin, and a one-shot Deformer (DeformOptions::once).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>

#include <sffd/sffd.h>

#include "api/api_test_support.h"
#include "backends/backend_test_support.h"
#include "backends/vulkan/vk_backend.h"

namespace {

using namespace sffd;
namespace fs = std::filesystem;

std::string bytesOf(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

struct Target {
  const char* name;
  bool binary;
};
const Target kTargets[] = {{"a.ply", true}, {"a.ply", false}, {"a.stl", true}, {"a.stl", false}, {"a.obj", false}};

class StreamResult : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sffd_stream_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // A small sphere (360 triangles) cut from the test data's, with texture coordinates.
    mesh_ = readMesh(std::string(SFFD_TEST_DATA) + "/sphere.obj");
    mesh_.texcoords.resize(mesh_.positions.size());
    for (size_t v = 0; v < mesh_.positions.size(); ++v) mesh_.texcoords[v] = {mesh_.positions[v].x, mesh_.positions[v].z};
  }
  void TearDown() override { fs::remove_all(dir_); }

  Lattice twisted(const Mesh& mesh) const {
    Lattice L = fitLattice(mesh, {4, 4, 5}, {2, 2, 2});
    applyLatticePreset(L, "twist", 0.4);
    return L;
  }

  // Every target written both ways by Deformers made with `o`: result() then writeMesh, and a fresh
  // Deformer's streamResult (a one-shot Deformer streams once).
  void expectSameFiles(const Mesh& mesh, DeformOptions o) {
    Device device = sffd::testing::openTestDevice("cpu");
    const Lattice L = twisted(mesh);
    Deformer classic(device, mesh, L, o);
    classic.deform(L);
    const Mesh whole = classic.result();
    const int digits = classic.doublePrecision() || classic.localOrigin() != glm::dvec3(0.0) ? 17 : 9;
    for (const Target& t : kTargets) {
      SCOPED_TRACE(std::string(t.name) + (t.binary ? " binary" : " text"));
      const MeshWriteOptions w{digits, t.binary};
      writeMesh((dir_ / "want").string() + t.name, whole, w);
      o.once = true;
      Deformer once(device, mesh, L, o);
      once.deform(L);
      MeshFileWriter out((dir_ / "got").string() + t.name, w);
      once.streamResult(out);
      EXPECT_EQ(out.triangleCount(), whole.triangles.size());
      const std::string want = bytesOf((dir_ / "want").string() + t.name);
      ASSERT_FALSE(want.empty());
      EXPECT_TRUE(want == bytesOf((dir_ / "got").string() + t.name));
      EXPECT_THROW(once.streamResult(out), Error);   // once: the buffers are gone
      EXPECT_THROW(once.deform(L), Error);
    }
    size_t files = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) ++files;
    EXPECT_EQ(files, 6u);   // want and got of a.ply, a.stl, a.obj: no temporary file left
  }

  fs::path dir_;
  Mesh mesh_;
};

TEST_F(StreamResult, SmoothFilesAreWriteMeshsBytes) {
  DeformOptions o;
  o.tess = 3;
  o.edgeLength = 0.5;
  o.maxChunkElements = 37;   // several chunks
  expectSameFiles(mesh_, o);
}

TEST_F(StreamResult, AccurateAndFarFromTheOriginAndColoursToo) {
  DeformOptions o;
  o.method = Method::Accurate;
  o.tess = 2;
  o.maxChunkElements = 50;
  expectSameFiles(mesh_, o);
  Mesh far = mesh_;
  for (glm::dvec3& p : far.positions) p += glm::dvec3(4096, 0, 0);
  far.colors.assign(far.positions.size(), glm::dvec4(0.25, 0.5, 0.75, 0.5));   // .ply gathered (alpha)
  o.method = Method::Smooth;
  o.edgeLength = 0.5;
  expectSameFiles(far, o);
}

// A one-shot accurate Deformer keeps no chunk on the device: its result runs the chunks one after another
// in one buffer (before, every chunk's output was made at once: the whole output on the device). Vulkan as
// a discrete GPU, counting its device memory allocations; the bytes are the kept Deformer's.
TEST_F(StreamResult, AccurateOneShotRunsItsChunksInOneBuffer) {
  setenv("SFFD_VK_STAGING", "1", 1);   // read when the device is opened
  std::optional<Device> device;
  try {
    device = sffd::testing::openTestDevice("vulkan");
  } catch (const Error& e) {
    unsetenv("SFFD_VK_STAGING");
    if (e.kind() != ErrorKind::Device || sffd::testing::requiredHere("vulkan")) throw;
    GTEST_SKIP() << e.what();
  }
  unsetenv("SFFD_VK_STAGING");
  DeformOptions o;
  o.method = Method::Accurate;
  o.tess = 2;
  o.maxChunkElements = 20;
  const Lattice L = twisted(mesh_);
  Deformer kept(*device, mesh_, L, o);
  kept.deform(L);
  const size_t chunks = kept.deviceOutput().size();
  ASSERT_GT(chunks, 20u);
  const Mesh whole = kept.result();
  o.once = true;
  const size_t before = vk::deviceMemoryAllocations();
  Deformer once(*device, mesh_, L, o);
  once.deform(L);
  EXPECT_TRUE(once.deviceOutput().empty());
  const Mesh streamed = once.result();
  EXPECT_LT(vk::deviceMemoryAllocations() - before, 10u);
  EXPECT_EQ(streamed.positions, whole.positions);
  EXPECT_EQ(streamed.triangles, whole.triangles);
  EXPECT_GT(once.timings().deformMs, 0.0);
}

// A small one-shot smooth job dispatches deform_smooth in its one-site form where the device translates every
// process (lavapipe below Mesa 23; SFFD_ASSUME_ONE_SAMPLE_SITE), a kept Deformer in the usual form: the same
// bits, fast and strict, on Vulkan and GL here (GL keeps the usual form).
TEST_F(StreamResult, OneShotSmoothIsTheKeptDeformersBits) {
  for (const std::string name : {"vulkan", "gl-egl"}) {
    std::string why;
    std::optional<Device> device = sffd::testing::openUnlessAbsent(name, sffd::testing::openTestDevice, why);
    if (!device) continue;
    for (bool strict : {false, true}) {   // (double's dispatch is not the specialized one: the same code either way)
      SCOPED_TRACE(name + (strict ? " strict" : " fast"));
      DeformOptions o;
      o.tess = 3;
      o.edgeLength = 0.5;
      o.strict = strict;
      o.precision = Precision::Float;
      const Lattice L = twisted(mesh_);
      Deformer kept(*device, mesh_, L, o);
      kept.deform(L);
      const Mesh whole = kept.result();
      o.once = true;
      Deformer once(*device, mesh_, L, o);
      once.deform(L);
      const Mesh streamed = once.result();
      EXPECT_EQ(streamed.positions, whole.positions);
      EXPECT_EQ(streamed.normals, whole.normals);
      EXPECT_EQ(streamed.triangles, whole.triangles);
    }
  }
}

TEST_F(StreamResult, NonFiniteVertexLeavesNoFile) {
  {
    MeshFileWriter out((dir_ / "bad.ply").string(), {9, true});
    Mesh piece;
    piece.positions = {{0, 0, 0}, {1, 0, 0}, {0, NAN, 0}};
    piece.triangles = {{0, 1, 2}};
    out.begin(Mesh{});
    EXPECT_THROW(out.add(piece, 0), Error);
  }   // the writer gone uncommitted: its scratch files with it
  EXPECT_TRUE(fs::is_empty(dir_));
}

}  // namespace
