// Internal interface of the mesh readers (mesh_io*.cpp). Each reader gets the file's bytes (read whole
// by readMesh) and returns a finished Mesh or throws inputError(path, line, what).
#pragma once
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "core/key3_map.h"
#include "model/mesh.h"

namespace sffd::meshio {

// What readMesh does once the file is read: dispatch by the extension of `path` (the fuzz targets
// call it with bytes that never were a file).
Mesh readMeshBytes(const std::string& path, std::string text, const MeshReadOptions& options = {});

Mesh readObj(const std::string& path, const std::string& text);
Mesh readOff(const std::string& path, const std::string& text);
Mesh readPly(const std::string& path, const std::string& text);
Mesh readStl(const std::string& path, const std::string& text);
Mesh readOm(const std::string& path, const std::string& text);
// Whether readMesh reads `path` in a forked child process (.om, readOm): a caller with other threads forks
// only where none of them is inside the dynamic loader or holds a lock (apps/sffd job.cpp reads it first).
bool readsInForkedChild(const std::string& path);
Mesh readBpt(const std::string& path, const std::string& text, const MeshReadOptions& options);

// Completes a mesh whose positions, normals (one slot per vertex, possibly unset) and triangles are
// filled: checks there is a triangle and every index is in range, normalises the file normals marked in
// `fromFile`, recomputes (angle-weighted) the others and zero-length ones, sets normalsFromFile and weldId.
// `normalShared` (empty, or per vertex a vertex index, its own if none): vertices whose recomputed
// normals are summed over the vertices naming the same one (an OBJ position split only by `vt`).
void finishMesh(Mesh& mesh, const std::vector<uint8_t>& fromFile, const std::string& path,
                const std::vector<uint32_t>& normalShared = {});

// Polygon -> triangles (fan from its first corner).
inline void fanTriangulate(const uint32_t* corners, size_t n, std::vector<std::array<uint32_t, 3>>& out) {
  for (size_t i = 1; i + 1 < n; ++i) out.push_back({corners[0], corners[i], corners[i + 1]});
}

// A polygon of a file into mesh.triangles: fanned when convex, ear-clipped when concave, dropped (and
// counted in `dropped`) when it has no area (polygon_triangulation.cpp). Corners must be in range.
void addPolygon(Mesh& mesh, const uint32_t* corners, size_t n, size_t& dropped);
// One warning line in mesh.warnings for the polygons addPolygon dropped, if any.
void noteDroppedPolygons(Mesh& mesh, size_t dropped);

// The key the readers tell equal values apart by (Key3Map): the bits of a glm::dvec2 or dvec3's components,
// -0 as +0 (bit equality otherwise), the words past its length 0.
template <class Vec>
Key3 bitsKey(const Vec& v) {
  Key3 k{};
  for (int c = 0; c < Vec::length(); ++c) {
    const double d = v[c] + 0.0;
    std::memcpy(&k[size_t(c)], &d, 8);
  }
  return k;
}

// Index of each vertex's distinct position (first appearance order) and the number of distinct positions.
std::vector<uint32_t> distinctPositions(const std::vector<glm::dvec3>& positions, uint32_t& count);

// Largest vertex count a mesh may have (indices are uint32).
constexpr uint64_t kMaxVertices = 0xFFFFFFF0u;

}  // namespace sffd::meshio
