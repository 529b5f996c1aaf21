// Deforms a tetrahedron on the CPU device through the installed package: headers, library, glm.
#include <cstdio>
#include <string>

#include <vulkan/vulkan.h>   // before <sffd/vulkan.h>, as it says
#include <sffd/opengl.h>     // every public header, under the strict warnings of CMakeLists.txt
#include <sffd/sffd.h>
#include <sffd/vulkan.h>

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
  // The library found at run time is the one these headers describe.
  const std::string built = std::to_string(SFFD_VERSION_MAJOR) + "." + std::to_string(SFFD_VERSION_MINOR) + "." +
                            std::to_string(SFFD_VERSION_PATCH);
  std::printf("sffd %s (built against %s) on %s: %zu triangles\n", sffd::version(), built.c_str(), device.label().c_str(),
              out.triangles.size());
  return out.triangles.size() > mesh.triangles.size() && built == sffd::version() ? 0 : 1;
} catch (const sffd::Error& e) {
  std::fprintf(stderr, "consumer: %s\n", e.what());
  return e.exitStatus();
}
