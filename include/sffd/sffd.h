// sffd: smooth free-form deformation of triangle meshes on any GPU, and on the CPU.
//
// A trivariate B-spline lattice bends a mesh. Beyond moving the vertices (classic FFD), sffd's smooth
// method splits every triangle into near-regular sub-triangles and makes each a cubic triangular
// Bezier patch fitted to the exactly deformed surface, with a deformed normal field and sharp
// creases kept sharp (Lu & Feng, "Improved smooth free-form deformation"; docs/METHOD.md). The same
// GLSL compute kernels run on Vulkan 1.1+ and OpenGL 4.3+, and their C++ twins on the CPU; in strict
// mode all three give the same bits.
//
// The headers, each a page:
//   <sffd/error.h>     sffd::Error and its kinds: every failure is one of them, what() is one line.
//   <sffd/mesh.h>      sffd::Mesh, MeshView (the caller's arrays), readMesh, writeMesh.
//   <sffd/lattice.h>   sffd::Lattice, fitLattice, presets, refineLattice/elevateLattice, lattice files.
//   <sffd/device.h>    sffd::Device: open by name with fallback, or adopt (below); listDevices.
//   <sffd/deformer.h>  sffd::Deformer: prepare once, deform for each new lattice, results on the host
//                      or in device buffers; options, timings, progress and cancel.
//   <sffd/vulkan.h>    adopt the application's VkDevice and queue; the results' VkBuffers.
//   <sffd/opengl.h>    adopt the application's current GL context; the results' GL buffers.
// This header includes all but the two interop headers.
//
// A whole program (link sffd::sffd from find_package(sffd CONFIG)):
//
//   #include <cstdio>
//   #include <sffd/sffd.h>
//   int main() try {
//     sffd::Device device = sffd::Device::open();            // Vulkan, else GL, else the CPU
//     sffd::Mesh mesh = sffd::readMesh("model.obj");
//     sffd::Lattice lattice = sffd::fitLattice(mesh);         // identity 5x5x5, degree 2
//     sffd::applyLatticePreset(lattice, "twist", 0.5);
//     sffd::Deformer deformer(device, mesh, lattice, {.method = sffd::Method::Smooth});
//     deformer.deform(lattice);
//     sffd::writeMesh("twisted.obj", deformer.result());
//   } catch (const sffd::Error& e) {
//     std::fprintf(stderr, "%s\n", e.what());
//     return e.exitStatus();
//   }
//
// Threads: a Device and the Deformers on it are used from one thread at a time, any thread, their
// destruction included (an adopted GL context: only the thread it is current on). Different Devices are
// independent.
#pragma once
#include <sffd/deformer.h>
#include <sffd/device.h>
#include <sffd/error.h>
#include <sffd/lattice.h>
#include <sffd/mesh.h>

// The one place of sffd's version (CMakeLists.txt and python/setup.py read it from here).
#define SFFD_VERSION_MAJOR 0
#define SFFD_VERSION_MINOR 1
#define SFFD_VERSION_PATCH 0

namespace sffd {
// The version of the library loaded at run time ("0.1.0"), for an application to compare with the
// SFFD_VERSION_* it was built against.
const char* version();
}  // namespace sffd
