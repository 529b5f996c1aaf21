// The frame every method computes in (deformer_local_frame.cpp; docs/ROBUSTNESS.md "Models far from the
// origin", "Models of any size"): local = (world - origin) * scale, on the host in double. The origin is 0
// for a lattice box near the world origin; the scale a power of two (exact), 1 for a box from
// 2^kLocalScaleMinExponent to 2^kLocalScaleMaxExponent across, else the one that brings the box to a size
// from 1 to 2. The analysis (`sffd error`) works in it too.
#pragma once
#include <sffd/lattice.h>
#include <sffd/mesh.h>

namespace sffd {

constexpr int kLocalScaleMinExponent = -8, kLocalScaleMaxExponent = 12;

struct LocalFrame {
  glm::dvec3 origin{0.0};
  double scale = 1;
  bool isWorld() const { return origin == glm::dvec3(0.0) && scale == 1; }
  glm::dvec3 toLocal(glm::dvec3 world) const { return (world - origin) * scale; }
  glm::dvec3 toWorld(glm::dvec3 local) const { return local / scale + origin; }
};

// The frame of a lattice's box.
LocalFrame latticeLocalFrame(const Lattice& lattice);
// A mesh's positions (and bicubic patches) in the frame, and back; normals are directions, the same in both.
Mesh localMesh(Mesh mesh, const LocalFrame& frame);
Mesh worldMesh(Mesh mesh, const LocalFrame& frame);
// The lattice as the devices see it: control points and frame moved and scaled, its parameter space
// centred and of a usual size.
Lattice localLattice(Lattice lattice, const LocalFrame& frame);

}  // namespace sffd
