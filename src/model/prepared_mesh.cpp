#include "model/prepared_mesh.h"

#include "core/huge_pages.h"
#include "kernels/common/shader_layout.h"

namespace sffd {

PreparedMesh prepareMesh(const Mesh& mesh) {
  static_assert(SFFD_MESH_TRIANGLE_STRIDE == 2 && SFFD_SLOT_NORMAL_STRIDE == 12, "packing below follows layout.h");
  PreparedMesh P;
  P.topology = buildTopology(mesh);
  const size_t nv = mesh.positions.size(), nt = mesh.triangles.size();
  resizeHuge(P.positions, 4 * nv);
  resizeHuge(P.normals, 4 * nv);
  for (size_t v = 0; v < nv; ++v) {
    const glm::dvec3 &p = mesh.positions[v], &n = mesh.normals[v];
    P.positions[4 * v] = p.x, P.positions[4 * v + 1] = p.y, P.positions[4 * v + 2] = p.z, P.positions[4 * v + 3] = 1;
    P.normals[4 * v] = n.x, P.normals[4 * v + 1] = n.y, P.normals[4 * v + 2] = n.z, P.normals[4 * v + 3] = 0;
  }
  resizeHuge(P.triangles, 8 * nt);
  resizeHuge(P.slotNormals, 48 * nt);
  for (size_t t = 0; t < nt; ++t) {
    const auto& tri = mesh.triangles[t];
    for (int c = 0; c < 3; ++c) {
      P.triangles[8 * t + c] = tri[c];
      P.triangles[8 * t + 4 + c] = mesh.weldId[tri[c]];
    }
    for (int s = 0; s < 6; ++s) {
      uint32_t own = tri[slotCorner(s)], other = P.topology.neighbourVertex[t][s];
      glm::dvec3 nOwn = mesh.normals[own], nOther = P.topology.neighbourNormal[t][s];
      // The pair in vertex-id order: the neighbour computes the same first and second.
      bool ownFirst = own <= other;
      const glm::dvec3& a = ownFirst ? nOwn : nOther;
      const glm::dvec3& b = ownFirst ? nOther : nOwn;
      double* d = &P.slotNormals[48 * t + 8 * s];
      d[0] = a.x, d[1] = a.y, d[2] = a.z, d[3] = P.topology.creaseSlot[t][s] ? 1 : 0;
      d[4] = b.x, d[5] = b.y, d[6] = b.z, d[7] = ownFirst ? 1 : 0;
    }
  }
  return P;
}

}  // namespace sffd
