// validateMesh and checkMeshStructure (model/mesh.h): what a Mesh must hold to be read, deformed or
// written, checked in one place for the readers (finishMesh), meshFromView, the Deformer and writeMesh.
#include <cmath>
#include <string>
#include <vector>

#include <sffd/error.h>

#include "io/io_util.h"
#include "io/mesh_io_internal.h"
#include "model/mesh.h"

namespace sffd {

namespace {

template <class Vec>
bool finite(const Vec& v) {
  for (int c = 0; c < Vec::length(); ++c)
    if (!std::isfinite(v[c])) return false;
  return true;
}

template <class Vec>
std::string text(const Vec& v) {
  std::string s = "(";
  for (int c = 0; c < Vec::length(); ++c) s += (c ? ", " : "") + io::formatNumber(v[c]);
  return s + ")";
}

std::string count(size_t n, const char* what) { return std::to_string(n) + " " + what; }

// A per-vertex or per-triangle field: empty, or one entry each.
void checkSize(size_t size, size_t n, const char* field, const char* each, const std::string& source) {
  if (size != 0 && size != n)
    throw inputError(source, 0, std::string(field) + " has " + std::to_string(size) + " entries for " + count(n, each) +
                                    " (one each, or none)");
}

template <class Vec>
void checkFinite(const std::vector<Vec>& values, const char* field, const std::string& source) {
  for (size_t i = 0; i < values.size(); ++i)
    if (!finite(values[i])) throw inputError(source, 0, std::string(field) + "[" + std::to_string(i) + "] is non-finite " + text(values[i]));
}

// Indices into a table of `tableSize`, Mesh::kNoIndex allowed where `none`.
void checkIndices(const std::vector<uint32_t>& index, size_t tableSize, const char* field, const char* table,
                  bool none, const std::string& source) {
  for (size_t i = 0; i < index.size(); ++i)
    if (index[i] >= tableSize && !(none && index[i] == Mesh::kNoIndex))
      throw inputError(source, 0, std::string(field) + "[" + std::to_string(i) + "] is " + std::to_string(index[i]) + ", not below " +
                                      count(tableSize, table) + (none ? " (nor Mesh::kNoIndex)" : ""));
}

// One weld id, one position: smooth and accurate FFD join two triangles along the edge whose corners have
// the same two weld ids and weld their output by them, so two positions under one id would tear the result
// or drop its triangles without a word. Vertices at one position with different ids are two locations (two
// sheets touching) and stay apart, as the caller says. O(n): the first vertex of each id, no hash.
void checkWeldPositions(const Mesh& mesh, const std::string& source) {
  constexpr uint32_t kNone = ~0u;
  std::vector<uint32_t> first(mesh.weldId.size(), kNone);   // ids are below the vertex count (checked)
  for (size_t v = 0; v < mesh.weldId.size(); ++v) {
    uint32_t& f = first[mesh.weldId[v]];
    if (f == kNone) f = uint32_t(v);
    else if (mesh.positions[v] != mesh.positions[f])   // == per coordinate: 0 and -0 are one position
      throw inputError(source, 0, "weldId[" + std::to_string(v) + "] is " + std::to_string(mesh.weldId[v]) + ", as vertex " +
                                      std::to_string(f) + "'s, but vertex " + std::to_string(v) + " is at " + text(mesh.positions[v]) +
                                      " and vertex " + std::to_string(f) + " at " + text(mesh.positions[f]) +
                                      ": vertices with one weld id must be at one position (leave weldId empty to weld by position)");
  }
}

}  // namespace

void checkMeshStructure(const Mesh& mesh, const std::string& source) {
  const size_t n = mesh.positions.size(), nt = mesh.triangles.size();
  if (n > meshio::kMaxVertices) throw inputError(source, 0, "too many vertices (" + std::to_string(n) + ")");
  checkSize(mesh.normals.size(), n, "normals", "vertices", source);
  checkSize(mesh.texcoords.size(), n, "texcoords", "vertices", source);
  checkSize(mesh.colors.size(), n, "colors", "vertices", source);
  checkSize(mesh.vertexPatch.size(), n, "vertexPatch", "vertices", source);
  checkSize(mesh.vertexUV.size(), n, "vertexUV", "vertices", source);
  for (size_t t = 0; t < nt; ++t)
    for (uint32_t v : mesh.triangles[t])
      if (v >= n)
        throw inputError(source, 0, "triangles[" + std::to_string(t) + "]: vertex index " + std::to_string(v) + " out of range (" +
                                        count(n, "vertices") + ")");
  checkSize(mesh.triangleMaterial.size(), nt, "triangleMaterial", "triangles", source);
  checkIndices(mesh.triangleMaterial, mesh.materials.size(), "triangleMaterial", "materials", true, source);
  checkSize(mesh.triangleGroup.size(), nt, "triangleGroup", "triangles", source);
  checkIndices(mesh.triangleGroup, mesh.groups.size(), "triangleGroup", "groups", true, source);
  checkIndices(mesh.vertexPatch, mesh.patches.size(), "vertexPatch", "patches", false, source);
}

void validateMesh(const Mesh& mesh, const std::string& source, bool normals) {
  checkMeshStructure(mesh, source);
  checkSize(mesh.weldId.size(), mesh.positions.size(), "weldId", "vertices", source);
  // A weld id is a distinct position or location, of which there are no more than vertices.
  checkIndices(mesh.weldId, mesh.positions.size(), "weldId", "vertices", false, source);
  checkFinite(mesh.positions, "positions", source);
  checkWeldPositions(mesh, source);   // after the finite check: NaN equals nothing
  if (normals) checkFinite(mesh.normals, "normals", source);
  checkFinite(mesh.texcoords, "texcoords", source);
  checkFinite(mesh.colors, "colors", source);
}

}  // namespace sffd
