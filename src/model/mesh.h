// Triangle meshes as plain data, and their file formats (.obj .off .ply .stl .om through OpenMesh,
// .bpt Bezier patch files). A vertex is a (position, normal) pair; vertices that share a position but
// carry different normals (split normals, creases) are separate vertices with the same weldId.
#pragma once
#include <array>
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
};

struct MeshReadOptions {
  int bptResolution = 10;   // .bpt: grid segments per patch side (10: 200 triangles a patch)
};

// Reads by extension. Polygons are triangulated; missing or zero normals are recomputed
// (angle-weighted). Throws an input Error ("file:line: what") on a bad file.
Mesh readMesh(const std::string& path, const MeshReadOptions& options = {});

// Writes by extension (.obj .ply .off .stl) with vertex normals where the format has them, text
// coordinates with `significantDigits` digits, to a temporary file renamed into place on success.
void writeMesh(const std::string& path, const Mesh& mesh, int significantDigits = 9);

// Angle-weighted vertex normals from the triangles (vertices with no area keep +z).
void computeVertexNormals(Mesh& mesh);

// Assigns weldId from exact position equality.
void weldPositions(Mesh& mesh);

}  // namespace sffd
