// The file records that writeMesh and MeshFileWriter share (mesh_io_write.cpp), so that a file written as
// its pieces come has writeMesh's bytes.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <string>

#include <sffd/mesh.h>

#include "io/io_util.h"

namespace sffd::meshio {

// What a mesh's vertices carry into the file (checkWritable): fields present, and any colour alpha != 1.
struct Carried {
  bool normals = false, texcoords = false, colors = false, alpha = false;
};

// The lower-case extension of `path` after writeMesh's checks of the format and options (an input Error
// naming what is wrong; an internal one for digits outside 1..17).
std::string checkWriteTarget(const std::string& path, const MeshWriteOptions& options);

// checkFiniteVertex's Error for a vertex that fails it.
[[noreturn]] void throwBadVertex(const std::string& path, size_t v, const glm::dvec3& position, const glm::dvec3* normal,
                                 bool floats);

// An input Error naming vertex `v` when its position or its normal (null: none) is not finite, or, for a
// file of floats (binary STL), its position is past their range (a double there would be an infinity; normals
// are unit). Inline: the writers ask it for every vertex.
inline void checkFiniteVertex(const std::string& path, size_t v, const glm::dvec3& position, const glm::dvec3* normal,
                              bool floats = false) {
  auto finite = [](const glm::dvec3& x) { return std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z); };
  auto inFloats = [](const glm::dvec3& x) {
    return io::withinFloatRange(x.x) && io::withinFloatRange(x.y) && io::withinFloatRange(x.z);
  };
  if (!finite(position) || (normal && !finite(*normal)) || (floats && !inFloats(position)))
    throwBadVertex(path, v, position, normal, floats);
}

// PLY: float properties for `digits` <= 9, double above (the text header's rule too).
std::string plyHeader(size_t vertices, size_t faces, int digits, const Carried& has, bool binary);
// Vertices [first, first + count) and `count` faces from `triangles`.
void appendPlyVertices(std::string& s, const Mesh& mesh, size_t first, size_t count, int digits, const Carried& has,
                       bool binary);
void appendPlyFaces(std::string& s, const std::array<uint32_t, 3>* triangles, size_t count, bool binary);

// STL: the header (binary: its triangle count), `count` facets from `triangles` (each one's normal from
// mesh.positions, or for a degenerate triangle the mean of mesh.normals when `withNormals`), the footer.
std::string stlHeader(bool binary, size_t triangles);
void appendStlFacets(std::string& s, const Mesh& mesh, const std::array<uint32_t, 3>* triangles, size_t count,
                     bool withNormals, int digits, bool binary);
std::string stlFooter(bool binary);

}  // namespace sffd::meshio
