// The result of the deform stage, for every method that makes patches (smooth, accurate): the
// tessellation vertices of each patch with their pre-images, and the welded output mesh.
// Plain data; the error analysis (error_metrics.h) and the writers read it.
#pragma once
#include <cstdint>
#include <vector>

#include "model/mesh.h"

namespace sffd {

// Tessellation at level L: per patch (L+1)(L+2)/2 vertices, row r = 0..L (i = L - r), position
// t = 0..r (k = t, j = r - t), index r(r+1)/2 + t, barycentrics (i, j, k) / L in the patch's
// sub-triangle; L^2 triangles, "up" (r,t),(r+1,t),(r+1,t+1) for t <= r and "down"
// (r,t),(r+1,t+1),(r,t+1) for t < r (METHOD.md 3.4 step 6).
int tessVertexCount(int level);
int tessTriangleCount(int level);
// The L^2 triangles of one patch as local vertex indices, 3 each.
std::vector<uint32_t> tessTriangles(int level);

struct PatchVertices {
  int level = 10;
  std::vector<uint32_t> parent;      // per patch: the original triangle
  std::vector<double> lamParent;     // per patch vertex: 3 barycentrics in the parent (the pre-image)
  std::vector<double> position;      // per patch vertex: 3 coordinates of the result
  std::vector<double> normal;        // per patch vertex: 3 coordinates of the unit shading normal
  size_t patchCount() const { return parent.size(); }
  size_t vertexCount() const { return position.size() / 3; }
};

// Welds patch vertices whose position and normal bits agree (shared boundaries of neighbouring
// patches are bit-identical by construction, so a closed input gives a closed output; crease
// vertices keep one vertex per normal, with a common weldId).
Mesh weldPatchVertices(const PatchVertices& patches);

// The tessellation with every patch vertex its own vertex (so each can carry its own value, e.g. an
// error for colouring).
Mesh unweldedPatchMesh(const PatchVertices& patches);

}  // namespace sffd
