// Deforms a tetrahedron on the CPU device through the installed package: headers, library, glm.
#include <cstdio>

#include <sffd/sffd.h>

int main() try {
  const double xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const uint32_t tris[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  sffd::MeshView view;
  view.positions = xyz;
  view.vertexCount = 4;
  view.triangles = tris;
  view.triangleCount = 4;
  sffd::Mesh mesh = sffd::meshFromView(view);
  sffd::Lattice lattice = sffd::fitLattice(mesh);
  sffd::applyLatticePreset(lattice, "twist", 0.3);
  sffd::Device device = sffd::Device::open({.name = "cpu"});
  sffd::Deformer deformer(device, mesh, lattice, {.tess = 2});
  deformer.deform(lattice);
  sffd::Mesh out = deformer.result();
  std::printf("sffd %d.%d.%d on %s: %zu triangles\n", SFFD_VERSION_MAJOR, SFFD_VERSION_MINOR, SFFD_VERSION_PATCH,
              device.label().c_str(), out.triangles.size());
  return out.triangles.size() > mesh.triangles.size() ? 0 : 1;
} catch (const sffd::Error& e) {
  std::fprintf(stderr, "consumer: %s\n", e.what());
  return e.exitStatus();
}
