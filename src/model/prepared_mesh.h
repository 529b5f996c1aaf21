// A mesh as the pre-compute kernels read it (kernels/common/layout.h, "Mesh buffers"): packed vertex
// data, triangles with their weld ids, and per corner slot the two normals that decide its PN edge
// control point, ordered by vertex index so both triangles of an edge see the same pair.
#pragma once
#include <vector>

#include "model/mesh.h"
#include "model/mesh_topology.h"

namespace sffd {

struct PreparedMesh {
  std::vector<double> positions;     // 4 per vertex (x, y, z, 1)
  std::vector<double> normals;       // 4 per vertex (x, y, z, 0)
  std::vector<uint32_t> triangles;   // 8 per triangle: vertex ids, 0, weld ids, 0
  std::vector<double> slotNormals;   // 48 per triangle: per slot, first (w: 1 crease) then second normal (w: 1 when the first is the triangle's own)
  MeshTopology topology;
  size_t triangleCount() const { return triangles.size() / 8; }
};

PreparedMesh prepareMesh(const Mesh& mesh);

}  // namespace sffd
