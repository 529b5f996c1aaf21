// Knot-box clipping (Cui & Feng 2015; METHOD.md 2.1): each triangle is cut by the interior knot
// planes of the lattice into convex pieces that each lie in one knot box, and the pieces are fanned
// into sub-triangles. The baseline that the improved (regular) clipping replaces, and the first step
// of accurate FFD.
#pragma once
#include <cstddef>
#include <vector>

#include "model/lattice.h"
#include "model/mesh.h"
#include "model/sub_triangles.h"

namespace sffd {

// Clips every triangle of `mesh` (positions in world space) by the interior knot planes of
// `lattice` (in its parameter space: planes p_d = knot, p = frameLinear * x + frameOffset).
// Watertight: a split point on a parent edge is computed from the edge's endpoint with the lower
// weldId, so both triangles of a shared edge produce bitwise-identical points. Degenerate fans
// (zero area in the parameter space) are skipped.
std::vector<SubTriangle> clipAgainstKnotBoxes(const Mesh& mesh, const Lattice& lattice);
// The same for triangles [firstTriangle, endTriangle), appended to `out`: each triangle is clipped on its
// own, so consecutive ranges give the whole mesh's sub-triangles in order (a streamed job's chunks).
void clipAgainstKnotBoxes(const Mesh& mesh, const Lattice& lattice, size_t firstTriangle, size_t endTriangle,
                          std::vector<SubTriangle>& out);

}  // namespace sffd
