// meshFromView (<sffd/mesh.h>): the caller's arrays become a Mesh by the same checks and normal rules
// as a file (meshio::finishMesh), so a mesh handed over in memory deforms exactly like the same mesh
// read from disk.
#include <sffd/error.h>
#include <sffd/mesh.h>

#include "io/mesh_io_internal.h"

namespace sffd {

Mesh meshFromView(const MeshView& view) {
  if (!view.positions && !view.positionsF32) throw Error(ErrorKind::Input, "mesh view: no positions");
  if (view.triangleCount > 0 && !view.triangles) throw Error(ErrorKind::Input, "mesh view: no triangle indices");
  Mesh mesh;
  const size_t ps = view.positionStride ? view.positionStride : 3, ns = view.normalStride ? view.normalStride : 3;
  if (ps < 3 || ns < 3) throw Error(ErrorKind::Input, "mesh view: a stride is below 3 elements");
  mesh.positions.resize(view.vertexCount);
  for (size_t v = 0; v < view.vertexCount; ++v)
    for (int c = 0; c < 3; ++c)
      mesh.positions[v][c] = view.positions ? view.positions[v * ps + c] : double(view.positionsF32[v * ps + c]);
  std::vector<uint8_t> fromFile;
  if (view.normals || view.normalsF32) {
    mesh.normals.resize(view.vertexCount);
    fromFile.assign(view.vertexCount, 1);
    for (size_t v = 0; v < view.vertexCount; ++v)
      for (int c = 0; c < 3; ++c)
        mesh.normals[v][c] = view.normals ? view.normals[v * ns + c] : double(view.normalsF32[v * ns + c]);
  }
  mesh.triangles.resize(view.triangleCount);
  for (size_t t = 0; t < view.triangleCount; ++t)
    for (int c = 0; c < 3; ++c) mesh.triangles[t][c] = view.triangles[3 * t + c];
  meshio::finishMesh(mesh, fromFile, "mesh view");
  return mesh;
}

}  // namespace sffd
