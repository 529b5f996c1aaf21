// Mesh preparation for smooth FFD (METHOD.md 3.1): triangle adjacency by welded position,
// crease detection from split normals, and per-corner neighbour normals. Plain data in, plain data out.
//
// Conventions: edge e of a triangle joins its corners e and (e+1)%3. Corner slots (6 per triangle,
// the order of the spec's n_nbr and of the PN edge control points): slot 2c is corner c on the
// edge towards corner (c+2)%3, i.e. edge (c+2)%3; slot 2c+1 is corner c on edge c.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "model/mesh.h"

namespace sffd {

struct MeshTopology {
  // Per triangle and edge: the neighbouring triangle across it (-1: boundary or non-manifold) and
  // the neighbour's local index of that edge (-1 when none).
  std::vector<std::array<int32_t, 3>> neighbour;
  std::vector<std::array<int8_t, 3>> neighbourEdge;
  // Per triangle and slot: whether the neighbour's normal at that corner across that edge differs
  // from the corner's own (a crease at this corner).
  std::vector<std::array<uint8_t, 6>> creaseSlot;
  // Per triangle and slot: the neighbour's vertex at that corner across that edge (the corner's own
  // vertex when there is no neighbour), whose normal is the neighbour normal. Lets both sides of an
  // edge order the two normals the same way.
  std::vector<std::array<uint32_t, 6>> neighbourVertex;
  // Counts for the statistics.
  size_t boundaryEdges = 0, nonManifoldEdges = 0, creaseEdges = 0, degenerateTriangles = 0;
};

// Normals closer than this per component count as equal (the authors' test, METHOD.md 3.2).
constexpr double kSameNormalTolerance = 1e-6;

inline int slotEdge(int slot) { return slot % 2 ? slot / 2 : (slot / 2 + 2) % 3; }
inline int slotCorner(int slot) { return slot / 2; }

// Whether a triangle whose corners have weld ids a, b, c has two corners at one welded position: a
// collapsed edge and no area.
inline bool weldsCollapsed(uint32_t a, uint32_t b, uint32_t c) { return a == b || b == c || c == a; }
// The same for triangle t of `mesh` (mesh.weldId). Such a triangle is no neighbour of any (its other two
// edges are the same welded edge twice), and the smooth and accurate results leave its patches out
// (patch_output.h).
bool weldDegenerate(const Mesh& mesh, const std::array<uint32_t, 3>& t);

// Builds adjacency from mesh.weldId (edges with more than two triangles are non-manifold: left
// unconnected and counted), neighbour normals and crease slots.
MeshTopology buildTopology(const Mesh& mesh);

// For meshes whose normals were computed on load (mesh.normalsFromFile == false): marks edges whose
// dihedral angle (between the face normals) exceeds `creaseAngleDeg` as creases, or with
// kCreaseAngleAuto (any negative value) those of the relative rule below, and gives each vertex one
// angle-weighted normal per smoothing fan (the faces around it between creases), splitting vertices as
// needed. The result is the split-normal input the method expects.
void applyCreaseAngle(Mesh& mesh, double creaseAngleDeg);

// The relative rule (kCreaseAngleAuto; chosen by tools/crease_survey.py, docs/METHOD.md 3.1): an edge
// is a crease when its dihedral angle is at least kAutoCreaseSharpDeg, or above kAutoCreaseLooseDeg and
// at least kAutoCreaseRatio times the angle of each of its crossing edges (the other two edges of its
// two triangles) that is below kAutoCreaseSharpDeg; boundary and non-manifold crossing edges count as 0.
// A crease between flat faces, or meeting other creases, passes; a coarse tessellation of a curved
// surface, whose every edge bends about as much as its neighbours, does not.
constexpr double kAutoCreaseLooseDeg = 40;
constexpr double kAutoCreaseSharpDeg = 80;
constexpr double kAutoCreaseRatio = 3;
inline bool autoCrease(double angleDeg, const double crossingDeg[4]) {
  if (angleDeg >= kAutoCreaseSharpDeg) return true;
  if (!(angleDeg > kAutoCreaseLooseDeg)) return false;
  for (int k = 0; k < 4; ++k)
    if (crossingDeg[k] < kAutoCreaseSharpDeg && kAutoCreaseRatio * crossingDeg[k] > angleDeg) return false;
  return true;
}

}  // namespace sffd
