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
  for (size_t t = 0; t < nt; ++t) {
    const auto& tri = mesh.triangles[t];
    for (int c = 0; c < 3; ++c) {
      P.triangles[8 * t + c] = tri[c];
      P.triangles[8 * t + 4 + c] = mesh.weldId[tri[c]];
    }
  }
  return P;
}

template <class Real>
void PreparedMesh::slotNormals(size_t first, size_t count, Real* out) const {
  for (size_t t = first; t < first + count; ++t)
    for (int s = 0; s < 6; ++s) {
      const uint32_t own = triangles[8 * t + slotCorner(s)], other = topology.neighbourVertex[t][s];
      const bool ownFirst = own <= other;
      const double* a = &normals[4 * size_t(ownFirst ? own : other)];
      const double* b = &normals[4 * size_t(ownFirst ? other : own)];
      Real* d = out + 48 * (t - first) + 8 * s;
      d[0] = Real(a[0]), d[1] = Real(a[1]), d[2] = Real(a[2]), d[3] = topology.creaseSlot[t][s] ? Real(1) : Real(0);
      d[4] = Real(b[0]), d[5] = Real(b[1]), d[6] = Real(b[2]), d[7] = ownFirst ? Real(1) : Real(0);
    }
}
template void PreparedMesh::slotNormals<float>(size_t, size_t, float*) const;
template void PreparedMesh::slotNormals<double>(size_t, size_t, double*) const;

}  // namespace sffd
