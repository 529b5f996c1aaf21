// sffd/mesh.h: triangle meshes as plain data, views over the caller's arrays, and mesh files.
//
// A vertex is a (position, normal) pair; vertices that share a position but carry different normals
// (split normals, creases) are separate vertices with the same weldId. Positions and normals are
// glm::dvec3 (three tightly packed doubles), so `positions.data()` is an xyz array.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace sffd {

struct BicubicPatch {
  std::array<glm::dvec3, 16> points;   // P(u,v) = sum_r sum_c B3_r(u) B3_c(v) points[4r+c]
};

struct Mesh {
  std::vector<glm::dvec3> positions;             // per vertex
  std::vector<glm::dvec3> normals;               // per vertex, unit length
  std::vector<uint32_t> weldId;                  // per vertex: index of its distinct position
  std::vector<std::array<uint32_t, 3>> triangles;  // counter-clockwise vertex indices
  bool normalsFromFile = false;                  // false: normals were computed on load
  // .bpt input only: the exact surface, and for each vertex its patch and (u, v) (error reference).
  std::vector<BicubicPatch> patches;
  std::vector<uint32_t> vertexPatch;
  std::vector<glm::dvec2> vertexUV;
  // What reading the file repaired or skipped, one line each (the command-line tool prints them as
  // warnings); empty for a clean file.
  std::vector<std::string> warnings;
};

// A triangle mesh in the caller's memory (float or double xyz, 32-bit indices), read once when a
// Deformer is made; nothing is kept. Strides are in elements of the pointed-to type (0: packed, 3).
struct MeshView {
  const double* positions = nullptr;    // or positionsF32
  const float* positionsF32 = nullptr;
  size_t vertexCount = 0;
  size_t positionStride = 0;
  const double* normals = nullptr;      // optional, unit length; or normalsF32. None: computed, with
  const float* normalsF32 = nullptr;    // creases above DeformOptions::creaseAngleDeg
  size_t normalStride = 0;
  const uint32_t* triangles = nullptr;  // 3 per triangle, counter-clockwise
  size_t triangleCount = 0;
};

// Copies a view into a Mesh (welding, normals as readMesh makes them). Throws an input Error for an
// index out of range, a non-finite coordinate or a view without positions.
Mesh meshFromView(const MeshView& view);

struct MeshReadOptions {
  int bptResolution = 10;   // .bpt: grid segments per patch side (10: 200 triangles a patch)
};

// Reads by extension (.obj .off .ply .stl .om, .bpt). Polygons are triangulated; missing or zero
// normals are recomputed (angle-weighted). Throws an input Error ("file:line: what") on a bad file.
Mesh readMesh(const std::string& path, const MeshReadOptions& options = {});

// Writes by extension (.obj .ply .off .stl) with vertex normals where the format has them, text
// coordinates with `significantDigits` digits, to a temporary file renamed into place on success.
void writeMesh(const std::string& path, const Mesh& mesh, int significantDigits = 9);

}  // namespace sffd
