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
  MeshTopology topology;
  size_t triangleCount() const { return triangles.size() / 8; }
  // The slot normals of triangles [first, first + count), 48 reals a triangle (layout.h): per slot the
  // first normal (w: 1 on a crease), then the second (w: 1 when the first is the triangle's own), the
  // corner's own and its neighbour's in vertex-id order, so the neighbour computes the same pair.
  // Made from normals and topology when asked (they would take 384 bytes a triangle in double).
  template <class Real>
  void slotNormals(size_t first, size_t count, Real* out) const;
};

PreparedMesh prepareMesh(const Mesh& mesh);

}  // namespace sffd
