// sffd/mesh.h: triangle meshes as plain data, views over the caller's arrays, and mesh files.
//
// A vertex is a (position, normal) pair; vertices that share a position but carry different normals
// (split normals, creases) are separate vertices with the same weldId. Positions and normals are
// glm::dvec3 (three tightly packed doubles), so `positions.data()` is an xyz array. Texture
// coordinates and colours, when the file has them, are per vertex too: a position with two texture
// coordinates (a seam) is two vertices with the same weldId, as a position with two normals is.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace sffd {

struct BicubicPatch {
  std::array<glm::dvec3, 16> points;   // P(u,v) = sum_r sum_c B3_r(u) B3_c(v) points[4r+c]
};

// A material as the mesh files name it: OBJ `usemtl` (with its .mtl's Kd and map_Kd when the library
// file is found), glTF's PBR base colour. Passed through from input to output; sffd never shades with it.
struct Material {
  std::string name;
  glm::dvec4 baseColor{1.0, 1.0, 1.0, 1.0};   // linear RGBA factor (glTF baseColorFactor, OBJ Kd with alpha 1)
  std::string baseColorTexture;               // image URI relative to the mesh file; empty: none
  // An image the file embeds instead (a .glb's buffer view): its bytes and MIME type, written back
  // embedded by the glTF writer; empty: none.
  std::vector<uint8_t> baseColorImage;
  std::string baseColorImageMime;
};

// Every per-vertex field is one per vertex or, where it may be left out, empty; every per-triangle field
// one per triangle or empty; indices in range. A Deformer and the writers refuse a Mesh that breaks this
// (an input Error naming the field), and a Deformer a non-finite position, normal, texture coordinate or
// colour, or a weld id at two positions (weldId below), too.
struct Mesh {
  std::vector<glm::dvec3> positions;             // per vertex, finite
  std::vector<glm::dvec3> normals;               // per vertex, unit length; empty: none (a Deformer computes them
                                                 // as readMesh computes missing ones, the writers write none)
  // Per vertex, the location on the surface it is at: a label below the vertex count (any labels; the
  // readers number the distinct positions 0, 1, ... by first appearance). Smooth and accurate FFD join
  // two triangles along an edge whose ends have the same two weld ids, so the vertices of one weld id must
  // be at one position (equal coordinates, 0 and -0 alike). A Deformer refuses a mesh where they are not
  // (positions edited after welding, say) with an input Error naming the first vertex away from its id's
  // first vertex. Vertices at one position with different ids are two locations (two sheets touching):
  // not joined, in the input as in the output. Empty: a Deformer welds by position.
  std::vector<uint32_t> weldId;
  // false: weldId is by exact position (the readers, meshFromView), and the OBJ and OFF writers find
  // the distinct positions themselves. true: weldId names each vertex's location on the input surface
  // (the smooth and accurate output, weldPatchVertices), one position a location, and those writers
  // write one position per location: two locations that round to one position (a sliver thinner than
  // float's resolution) stay two, so the file keeps the output's topology. A location whose vertices
  // no longer share one position (moved apart by the caller) makes the writers fall back to positions.
  bool weldIdIsLocation = false;
  std::vector<std::array<uint32_t, 3>> triangles;  // counter-clockwise vertex indices
  bool normalsFromFile = false;                  // false: normals were computed on load
  // .bpt input only: the exact surface, and for each vertex its patch and (u, v) (error reference).
  std::vector<BicubicPatch> patches;
  std::vector<uint32_t> vertexPatch;
  std::vector<glm::dvec2> vertexUV;
  // What reading the file repaired or skipped, one line each (the command-line tool prints them as
  // warnings); empty for a clean file.
  std::vector<std::string> warnings;

  // Carried attributes (empty: the file has none). Every method keeps them: classic per vertex as they
  // are, smooth and accurate interpolated from the parent triangle's corners at each output vertex.
  std::vector<glm::dvec2> texcoords;   // per vertex; OBJ convention: (0, 0) is the image's lower left
  std::vector<glm::dvec4> colors;      // per vertex, RGBA in [0, 1] as the file stores them (no colour space conversion)
  // Per triangle, an index into `materials` / `groups`, or kNoIndex; empty: none at all.
  static constexpr uint32_t kNoIndex = 0xFFFFFFFFu;
  std::vector<uint32_t> triangleMaterial;
  std::vector<Material> materials;
  std::vector<uint32_t> triangleGroup;
  std::vector<std::string> groups;             // OBJ `g` names
  std::vector<std::string> materialLibraries;  // OBJ `mtllib` file names, written back as they were read
};

// The crease rule for meshes without normals when none is given (DeformOptions::creaseAngleDeg's
// default, `--crease-angle auto`): an edge is a crease where it bends by 80 degrees or more, or by more
// than 40 and at least 3 times as much as the edges around it (docs/METHOD.md 3.1). A creaseAngleDeg of
// 0 or more marks instead every edge whose dihedral angle exceeds it.
inline constexpr double kCreaseAngleAuto = -1;

// A triangle mesh in the caller's memory (float or double xyz, 32-bit indices), read once when a
// Deformer is made; nothing is kept. Strides are in elements of the pointed-to type (0: packed, 3).
struct MeshView {
  const double* positions = nullptr;    // or positionsF32
  const float* positionsF32 = nullptr;
  size_t vertexCount = 0;
  size_t positionStride = 0;
  const double* normals = nullptr;      // optional, unit length; or normalsF32. None: computed, with
  const float* normalsF32 = nullptr;    // creases by DeformOptions::creaseAngleDeg
  size_t normalStride = 0;
  const uint32_t* triangles = nullptr;  // 3 per triangle, counter-clockwise
  size_t triangleCount = 0;
};

// Copies a view into a Mesh (welding, normals as readMesh makes them). Throws an input Error for an
// index out of range, a non-finite coordinate, a view without positions or one without triangles.
Mesh meshFromView(const MeshView& view);

struct MeshReadOptions {
  int bptResolution = 10;   // .bpt: grid segments per patch side (10: 200 triangles a patch)
};

// Reads by extension (.obj .off .ply .stl .om, .bpt, .gltf .glb). Polygons are triangulated; missing or zero
// normals are recomputed (angle-weighted). Throws an input Error ("file:line: what") on a bad file. A .om file
// is read by OpenMesh in a forked child process (its reader aborts on a damaged file): as with any fork, read
// one while no other thread of the program is inside the dynamic loader (opening a device, say) or holds a lock.
Mesh readMesh(const std::string& path, const MeshReadOptions& options = {});

struct MeshWriteOptions {
  int significantDigits = 9;   // text coordinates: 9 for float results, 17 for double (1..17; else an input Error)
  // .ply and .stl: binary little-endian instead of text (PLY: float, or double with more than 9
  // digits; STL: float, the format's only type). Other formats refuse it.
  bool binary = false;
};

// Writes by extension (.obj .ply .off .stl .gltf .glb) with vertex normals where the format has them, text
// coordinates with `significantDigits` digits, to a temporary file renamed into place on success.
// OBJ keeps texture coordinates (`vt`), groups, materials (`usemtl`) and `mtllib`; PLY texture
// coordinates (u, v) and colours (uchar red green blue alpha); glTF all of them, materials as PBR base
// colour factor and texture URI. Throws an input Error for a format it cannot write, bad options, a Mesh
// whose fields' sizes or indices are not as Mesh says (naming the field) or a non-finite vertex.
void writeMesh(const std::string& path, const Mesh& mesh, int significantDigits = 9);
void writeMesh(const std::string& path, const Mesh& mesh, const MeshWriteOptions& options);

// A receiver of a mesh in pieces, for results too large to hold whole (Deformer::streamResult): begin()
// once with a Mesh that has the tables (materials, groups, materialLibraries) and flags (weldIdIsLocation,
// normalsFromFile) but no vertices; add() for each piece in order; end() once after the last. A piece's
// vertices (positions and the per-vertex fields the mesh has) follow those of the pieces before:
// piece.positions[i] is vertex firstVertex + i. Its triangles (with their triangleMaterial and
// triangleGroup when the mesh has them) index any vertex given so far, its own included. The pieces'
// vertices and triangles, appended in order, are the whole mesh. An exception from a sink stops the stream.
class MeshSink {
 public:
  virtual ~MeshSink() = default;
  virtual void begin(const Mesh& tables) { (void)tables; }
  virtual void add(const Mesh& piece, size_t firstVertex) = 0;
  virtual void end() {}
};

// A MeshSink that writes the file writeMesh(path, mesh, options) writes, byte for byte: .ply (binary and
// text, without colours) and .stl as the pieces come, holding none of the mesh but what STL's facet normals
// need (positions, normals); a .ply's vertices and faces go to hidden temporary files beside the output,
// joined after its header at end(). Other formats, and .ply with colours (whose header depends on the last
// vertex's alpha), are gathered and written at end(). The file appears at end(), whole; a writer destroyed
// before (an exception) leaves nothing. Throws as writeMesh does: an input Error for a format it cannot write
// or a non-finite vertex (from the add() that gives it), which stops the stream; and an input Error for
// calls out of order (add() outside begin() and end(), either of those twice, a piece's firstVertex not the
// count so far) or a piece whose fields differ from the first's or whose indices are out of range. A streamed file is formatted
// and written on a thread of the writer's own while the caller makes the next pieces, so a failed write (a
// full disk) is thrown by a later add() or by end().
class MeshFileWriter final : public MeshSink {
 public:
  explicit MeshFileWriter(const std::string& path, const MeshWriteOptions& options = {});
  ~MeshFileWriter() override;
  MeshFileWriter(const MeshFileWriter&) = delete;
  MeshFileWriter& operator=(const MeshFileWriter&) = delete;
  void begin(const Mesh& tables) override;
  void add(const Mesh& piece, size_t firstVertex) override;
  void end() override;
  size_t vertexCount() const;     // given so far
  size_t triangleCount() const;
  // Whether a file of this name and these options is written as the pieces come (not gathered), for a
  // mesh with colours or without.
  static bool streams(const std::string& path, const MeshWriteOptions& options, bool colors = false);
  // The host bytes a streaming writer of this name keeps per vertex until end(), with its arrays' growth:
  // an .stl's positions and normals (96), a .ply's none (0).
  static size_t heldBytesPerVertex(const std::string& path, const MeshWriteOptions& options);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sffd
