// Mesh writers (mesh_io_write.cpp): binary PLY and STL, and the attributes every format keeps.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include <sffd/error.h>

#include "model/mesh.h"
#include "tests/support/cli_runner.h"

using namespace sffd;
using sffd::test::slurp;
using sffd::test::tempDir;
namespace fs = std::filesystem;

namespace {

const std::string kData = SFFD_TEST_DATA;

glm::dvec3 asFloat(const glm::dvec3& v) {
  volatile float x = float(v.x), y = float(v.y), z = float(v.z);   // through memory: no folding at -O3
  return {double(x), double(y), double(z)};
}

TEST(MeshWrite, BinaryPlyAndStlReadBackAsTheirText) {
  const fs::path dir = tempDir("mesh_write_binary");
  const Mesh teapot = readMesh(kData + "/teapot.bpt");
  for (const char* ext : {".ply", ".stl"})
    for (int digits : {9, 17}) {
      SCOPED_TRACE(std::string(ext) + " " + std::to_string(digits) + " digits");
      const std::string bin = (dir / (std::string("bin") + ext)).string(), text = (dir / (std::string("text") + ext)).string();
      writeMesh(bin, teapot, MeshWriteOptions{.significantDigits = digits, .binary = true});
      writeMesh(text, teapot, digits);
      EXPECT_LT(fs::file_size(bin), fs::file_size(text));
      const Mesh b = readMesh(bin), t = readMesh(text);
      ASSERT_EQ(b.triangles.size(), teapot.triangles.size());
      // PLY keeps the vertices (float, or double with 17 digits); STL welds them back by position.
      const bool exact = std::string(ext) == ".ply" && digits == 17;
      for (size_t f = 0; f < teapot.triangles.size(); ++f)
        for (int c = 0; c < 3; ++c) {
          const glm::dvec3 want = teapot.positions[teapot.triangles[f][c]];
          ASSERT_EQ(b.positions[b.triangles[f][c]], exact ? want : asFloat(want)) << "triangle " << f;
          const glm::dvec3 fromText = t.positions[t.triangles[f][c]];
          ASSERT_EQ(b.positions[b.triangles[f][c]], exact ? fromText : asFloat(fromText)) << "triangle " << f;
        }
      if (std::string(ext) == ".ply") {
        // (float normals are normalised again on reading: equal to float resolution)
        for (size_t v = 0; v < b.normals.size(); ++v) ASSERT_LE(glm::length(b.normals[v] - t.normals[v]), exact ? 0.0 : 1e-7);
        EXPECT_TRUE(b.normalsFromFile);
      }
    }
  // The binary STL header does not start with "solid" (readers would try it as text).
  EXPECT_NE(slurp(dir / "bin.stl").rfind("solid", 0), 0u);
  fs::remove_all(dir);
}

TEST(MeshWrite, BinaryIsRefusedForTextFormats) {
  const fs::path dir = tempDir("mesh_write_refused");
  const Mesh cube = readMesh(kData + "/cube.obj");
  for (const char* name : {"x.obj", "x.off"}) {
    const std::string p = (dir / name).string();
    try {
      writeMesh(p, cube, MeshWriteOptions{.binary = true});
      ADD_FAILURE() << name << " written in binary";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Input);
      EXPECT_NE(std::string(e.what()).find("binary output is for .ply and .stl"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(p));
  }
  fs::remove_all(dir);
}

// Attributes survive OBJ and PLY (text and binary) round trips; PLY colours are bytes.
TEST(MeshWrite, AttributesRoundTrip) {
  const fs::path dir = tempDir("mesh_write_attributes");
  {
    std::ofstream(dir / "lib.mtl") << "newmtl red\nKd 1 0 0\nd 0.5\nmap_Kd -s 1 1 1 bricks.png\nnewmtl unused\nKd 0 1 0\n";
    std::ofstream(dir / "in.obj") << "mtllib lib.mtl\nv 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nv 1 1 0 1 1 1\n"
                                     "vt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\nvt 0.5 0.5\n"
                                     "g a\nusemtl red\nf 1/1 2/2 3/3\ng b\nusemtl blue\nf 2/5 4/4 3/3\n";
  }
  const Mesh m = readMesh((dir / "in.obj").string());
  ASSERT_EQ(m.positions.size(), 5u);   // position 2 with two texture coordinates: two vertices
  EXPECT_EQ(m.texcoords[4], glm::dvec2(0.5, 0.5));
  EXPECT_EQ(m.colors[1], glm::dvec4(0, 1, 0, 1));
  EXPECT_EQ(m.triangleMaterial, (std::vector<uint32_t>{0, 1}));
  EXPECT_EQ(m.triangleGroup, (std::vector<uint32_t>{0, 1}));
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[0].baseColor, glm::dvec4(1, 0, 0, 0.5));
  EXPECT_EQ(m.materials[0].baseColorTexture, "bricks.png");
  EXPECT_EQ(m.materials[1].baseColor, glm::dvec4(1.0));   // not in the library
  for (const char* name : {"out.obj", "out.ply", "bin.ply"}) {
    SCOPED_TRACE(name);
    const std::string p = (dir / name).string();
    writeMesh(p, m, MeshWriteOptions{.significantDigits = 17, .binary = std::string(name) == "bin.ply"});
    const Mesh r = readMesh(p);
    ASSERT_EQ(r.triangles.size(), 2u);
    for (size_t f = 0; f < 2; ++f)
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(r.texcoords[r.triangles[f][c]], m.texcoords[m.triangles[f][c]]);
        EXPECT_EQ(r.colors[r.triangles[f][c]], m.colors[m.triangles[f][c]]);
      }
    if (std::string(name) == "out.obj") {
      EXPECT_EQ(r.triangleMaterial, m.triangleMaterial);
      EXPECT_EQ(r.triangleGroup, m.triangleGroup);
      EXPECT_EQ(r.groups, m.groups);
      EXPECT_EQ(r.materialLibraries, m.materialLibraries);
      EXPECT_EQ(r.materials[0].baseColorTexture, "bricks.png");   // lib.mtl is beside out.obj too
    }
  }
  // PLY's other names for texture coordinates, and float colours.
  std::ofstream(dir / "st.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                                   "property float s\nproperty float t\nproperty float red\nproperty float green\nproperty float blue\n"
                                   "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                   "0 0 0 0.25 0.5 1 0.5 0\n1 0 0 1 0 0 0 0\n0 1 0 0 1 0 0 0\n3 0 1 2\n";
  const Mesh st = readMesh((dir / "st.ply").string());
  EXPECT_EQ(st.texcoords[0], glm::dvec2(0.25, 0.5));
  EXPECT_EQ(st.colors[0], glm::dvec4(1, 0.5, 0, 1));
  fs::remove_all(dir);
}

// An OBJ `v` line holds one colour: two vertices at one position with two colours (a colour seam, as
// at a UV sphere's pole) are two lines, which read back as one location. One line with the first
// vertex's colour gave the other corners a colour they never had.
TEST(MeshWrite, ObjKeepsTwoColoursAtOnePosition) {
  const fs::path dir = tempDir("mesh_write_colour_seam");
  std::ofstream(dir / "in.obj") << "v 0 0 0 1 0 0\nv 1 0 0 1 0 0\nv 0 1 0 1 0 0\nv 0 0 0 0 1 0\nv -1 0 0 0 1 0\n"
                                   "f 1 2 3\nf 4 3 5\n";
  const Mesh m = readMesh((dir / "in.obj").string());
  const std::string p = (dir / "out.obj").string();
  writeMesh(p, m, 17);
  const Mesh r = readMesh(p);
  ASSERT_EQ(r.triangles.size(), 2u);
  for (size_t f = 0; f < 2; ++f)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(r.colors[r.triangles[f][c]], m.colors[m.triangles[f][c]]) << f << " " << c;
  EXPECT_EQ(r.weldId[r.triangles[0][0]], r.weldId[r.triangles[1][0]]);   // still one location
  const std::string text = slurp(p);
  size_t lines = 0;
  for (size_t at = text.find("\nv "); at != std::string::npos; at = text.find("\nv ", at + 1)) ++lines;
  EXPECT_EQ(lines, 5u);
  fs::remove_all(dir);
}

// The OBJ and OFF writers write one position per location when the mesh names its locations
// (Mesh::weldIdIsLocation, the smooth and accurate output): two locations at one position stay two
// vertices. Otherwise (a mesh read from a file, or a location whose vertices were moved apart) one per
// distinct position.
TEST(MeshWrite, LocationsAtOnePositionStayApart) {
  const fs::path dir = tempDir("mesh_write_locations");
  Mesh m;   // vertex 3 lies where vertex 0 does, at another location; vertex 4 is vertex 1's location again
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {1, 0, 0}};
  m.weldId = {0, 1, 2, 3, 1};
  m.triangles = {{0, 1, 2}, {3, 2, 4}};
  // The file's vertex count and its faces' position indices (from 0).
  auto written = [&](const char* ext) {
    const fs::path path = dir / (std::string("m") + ext);
    writeMesh(path.string(), m);
    std::istringstream in(slurp(path));
    std::string word;
    size_t vertices = 0, nf = 0, three = 0;
    std::vector<uint32_t> corners(6);
    if (std::string(ext) == ".off") {
      in >> word >> vertices >> nf >> three;
      for (size_t i = 0; i < 3 * vertices; ++i) in >> word;
      for (size_t f = 0; f < 2; ++f) in >> three >> corners[3 * f] >> corners[3 * f + 1] >> corners[3 * f + 2];
    } else {
      size_t c = 0;
      for (std::string line; std::getline(in, line);) {
        if (line.rfind("v ", 0) == 0) ++vertices;
        std::istringstream l(line);
        if (l >> word && word == "f")
          while (l >> word) corners.at(c++) = uint32_t(std::stoul(word)) - 1;
      }
    }
    return std::pair{vertices, corners};
  };
  using Corners = std::vector<uint32_t>;
  for (const char* ext : {".obj", ".off"}) {
    SCOPED_TRACE(ext);
    m.weldIdIsLocation = true;
    EXPECT_EQ(written(ext), std::pair(size_t(4), Corners{0, 1, 2, 3, 2, 1}));
    m.weldIdIsLocation = false;   // weldId by position, as read from a file
    EXPECT_EQ(written(ext), std::pair(size_t(3), Corners{0, 1, 2, 0, 2, 1}));
    m.weldIdIsLocation = true;
    m.positions[4] = {2, 0, 0};   // one location, two positions: by position
    EXPECT_EQ(written(ext), std::pair(size_t(4), Corners{0, 1, 2, 0, 2, 3}));
    m.positions[4] = m.positions[1];
  }
  fs::remove_all(dir);
}

std::string base64(const std::string& bytes) {
  static const char* abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);   // bytes in this group; 4 - (3 - n) characters, then '='
    uint32_t v = 0;
    for (size_t k = 0; k < 3; ++k) v = (v << 8) | (k < n ? uint8_t(bytes[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k) out += k <= n ? abc[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

// The glTF reader on a file made here: node transforms (a translated child of a mirroring node),
// strips, fans, normalized byte colours, flipped texture coordinates, a skipped line primitive.
TEST(MeshRead, GltfPrimitivesAndTransforms) {
  const fs::path dir = tempDir("mesh_read_gltf");
  std::string bin;
  auto floats = [&](std::initializer_list<float> v) {
    for (float f : v) bin.append(reinterpret_cast<const char*>(&f), 4);
  };
  floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0});   // 4 positions, offset 0, 48 bytes
  floats({0, 0, 1, 0, 0, 1, 1, 1});               // 4 texture coordinates, offset 48, 32 bytes
  bin += std::string("\xff\x00\x00\x00\xff\x00\x00\x00\xff\xff\xff\xff", 12);   // 4 colours (ubyte), offset 80
  const std::string json = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"scale": [-1, 1, 1], "children": [1]}, {"translation": [10, 0, 0], "mesh": 0}],
    "meshes": [{"primitives": [
      {"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "COLOR_0": 2}, "mode": 5},
      {"attributes": {"POSITION": 0}, "mode": 6},
      {"attributes": {"POSITION": 0}, "mode": 1}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                  {"bufferView": 2, "componentType": 5121, "normalized": true, "count": 4, "type": "VEC3"}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                    {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
    "buffers": [{"byteLength": )" + std::to_string(bin.size()) + R"(, "uri": "data:application/octet-stream;base64,)" + base64(bin) + R"("}]})";
  std::ofstream(dir / "t.gltf") << json;
  const Mesh m = readMesh((dir / "t.gltf").string());
  ASSERT_EQ(m.positions.size(), 8u);   // two primitives of 4 vertices (the line primitive skipped)
  ASSERT_EQ(m.triangles.size(), 4u);   // a strip of 4: 2 triangles; a fan of 4: 2 triangles
  EXPECT_EQ(m.positions[3], glm::dvec3(-11, 1, 0));   // scale(-1, 1, 1) * translate(10, 0, 0) * (1, 1, 0)
  EXPECT_EQ(m.texcoords[1], glm::dvec2(1, 1));        // glTF (1, 0) with v flipped
  EXPECT_EQ(m.texcoords[5], glm::dvec2(0, 0));        // no TEXCOORD_0 in the fan: (0, 0)
  EXPECT_EQ(m.colors[1], glm::dvec4(0, 1, 0, 1));
  EXPECT_EQ(m.colors[3], glm::dvec4(1, 1, 1, 1));
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_NE(m.warnings[0].find("1 point or line primitive skipped"), std::string::npos) << m.warnings[0];
  // Strip (0 1 2), (2 1 3) and fan (0 1 2), (0 2 3), each turned (b and c swapped) by the mirror.
  using T = std::array<uint32_t, 3>;
  EXPECT_EQ(m.triangles, (std::vector<T>{{0, 2, 1}, {2, 3, 1}, {4, 6, 5}, {4, 7, 6}}));
  // So the strip, counter-clockwise in its own frame, is counter-clockwise in the world too.
  for (size_t f = 0; f < 2; ++f) {
    const T& t = m.triangles[f];
    EXPECT_GT(glm::cross(m.positions[t[1]] - m.positions[t[0]], m.positions[t[2]] - m.positions[t[0]]).z, 0.0) << f;
  }
  fs::remove_all(dir);
}

// A buffer named by an absolute path is looked for in the model's folder, wherever the model is read from:
// read from its own folder ("t.gltf", whose folder is empty), "/PATH" named a file elsewhere.
TEST(MeshRead, GltfBufferPathsStayInTheModelsFolder) {
  const fs::path dir = tempDir("mesh_read_gltf_uri");
  const fs::path elsewhere = tempDir("mesh_read_gltf_uri_elsewhere");
  std::string bin;
  for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) bin.append(reinterpret_cast<const char*>(&f), 4);
  std::ofstream(elsewhere / "b.bin", std::ios::binary) << bin;
  std::ofstream(dir / "t.gltf") << R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "buffers": [{"byteLength": 36, "uri": ")" + (elsewhere / "b.bin").string() + R"("}]})";
  const fs::path cwd = fs::current_path();
  for (const bool fromItsFolder : {false, true}) {
    if (fromItsFolder) fs::current_path(dir);
    const std::string name = fromItsFolder ? "t.gltf" : (dir / "t.gltf").string();
    EXPECT_THROW(readMesh(name), Error) << name;
  }
  fs::current_path(cwd);
  fs::remove_all(dir);
  fs::remove_all(elsewhere);
}

// An output that is a symbolic link is written through it, whole or streamed: the link stays a link and its
// target, in another folder, gets the mesh; nothing is left beside either.
TEST(MeshWrite, ThroughASymbolicLinkTheLinkStays) {
  const fs::path dir = tempDir("mesh_write_symlink");
  fs::create_directories(dir / "real");
  const Mesh teapot = readMesh(kData + "/teapot.bpt");
  writeMesh((dir / "expected.ply").string(), teapot, MeshWriteOptions{.significantDigits = 9, .binary = true});
  for (const bool dangling : {true, false}) {
    SCOPED_TRACE(dangling ? "the target not there yet" : "over an existing target");
    const fs::path target = dir / "real" / "t.ply", link = dir / "link.ply";
    if (!dangling) std::ofstream(target) << "old";
    fs::remove(link);
    fs::create_symlink(fs::path("real") / "t.ply", link);   // relative, as users make them
    writeMesh(link.string(), teapot, MeshWriteOptions{.significantDigits = 9, .binary = true});
    EXPECT_TRUE(fs::is_symlink(link));
    EXPECT_EQ(slurp(target), slurp(dir / "expected.ply"));
    size_t files = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir)) files += e.is_regular_file() && !e.is_symlink();
    EXPECT_EQ(files, 2u) << "a temporary file is left";
    fs::remove(target);
  }
}

// An audit (2026-12): writeMesh refused a Mesh with a bad index or a normals count unlike the vertex count,
// and significant digits of 0 or 18, as an internal error (sffd's own bug), and so did MeshFileWriter used
// out of order. They are the caller's mistakes: input errors, naming the field.
TEST(MeshWrite, CallersMistakesAreInputErrors) {
  const fs::path dir = tempDir("mesh_write_mistakes");
  const Mesh cube = readMesh(kData + "/cube.obj");
  const std::string out = (dir / "x.obj").string();
  auto expectInput = [&](const std::string& what, const std::string& message, auto&& f) {
    try {
      f();
      ADD_FAILURE() << what << ": nothing was thrown";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Input) << what << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << what << ": " << e.what();
    }
  };
  Mesh badIndex = cube, fewNormals = cube, badGroup = cube;
  badIndex.triangles[2][0] = uint32_t(cube.positions.size());
  fewNormals.normals.pop_back();
  badGroup.triangleGroup.assign(cube.triangles.size(), 3);
  expectInput("index", "triangles[2]: vertex index", [&] { writeMesh(out, badIndex); });
  expectInput("normals", "normals has", [&] { writeMesh(out, fewNormals); });
  expectInput("groups", "triangleGroup[0] is 3", [&] { writeMesh(out, badGroup); });
  for (int digits : {0, 18})
    expectInput("digits " + std::to_string(digits), "significantDigits must be 1..17", [&] { writeMesh(out, cube, digits); });
  EXPECT_FALSE(fs::exists(out));
  for (const char* name : {"x.obj", "x.ply"}) {
    SCOPED_TRACE(name);
    const std::string path = (dir / name).string();
    {
      MeshFileWriter early(path);
      expectInput("add() before begin()", "add() outside begin() and end()", [&] { early.add(cube, 0); });
      expectInput("end() before begin()", "end() without begin()", [&] { early.end(); });
    }
    EXPECT_FALSE(fs::exists(path));
    MeshFileWriter writer(path);
    writer.begin(Mesh{});
    expectInput("begin() twice", "begin() called twice", [&] { writer.begin(Mesh{}); });
    expectInput("a piece out of order", "firstVertex 5", [&] { writer.add(cube, 5); });
    writer.add(cube, 0);
    Mesh next = cube;
    next.normals.clear();
    expectInput("a piece unlike the first", "0 normals", [&] { writer.add(next, cube.positions.size()); });
    writer.end();
    expectInput("end() twice", "end() without begin(), or twice", [&] { writer.end(); });
    fs::remove(path);
  }
  fs::remove_all(dir);
}

}  // namespace
