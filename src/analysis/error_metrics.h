// Error analysis (METHOD.md 5; seed paper 6.3): a deformation result against the exact FFD of the
// same surface points, in double precision on the CPU.
//
// Correspondence: every tessellation vertex of the result has a pre-image, barycentrics lam in a parent
// triangle of the input mesh (PatchVertices). Its reference is the exact FFD of that pre-image:
//  - mesh input: point x = sum lam_i V_i on the flat parent, normal n = normalize(sum lam_i N_i);
//  - .bpt input (mesh.patches, vertexPatch, vertexUV): the exact surface point S(u, v) at
//    (u, v) = sum lam_i (u, v)_i of the parent's vertices, normal Su x Sv (nudged into the patch where
//    it vanishes, as the reader does);
// reference position R(x), reference normal normalize(cof(J(x)) n). Geometry error = distance;
// normal error = angle in degrees (atan2(|a x b|, a.b), accurate also near 0). avg, max and the
// population standard deviation over all tessellation vertices (shared vertices counted per patch).
//
// Volume (closed inputs only): result = signed volume of the output mesh, sum p0.(p1 x p2)/6 (taken
// about the centre of its box, which does not change the sum for a closed mesh); reference = the
// exactly deformed volume, (1/3) integral over the input surface of R . (cof(J) n) dA (divergence
// theorem: n' dA' = cof(J) n dA), integrated per knot-box sub-triangle, where the integrand is a
// polynomial of degree 3n-2 (n = nu+nv+nw), by a collapsed (Duffy) Gauss-Legendre product rule that is
// exact for it. It is the signed volume of the deformed surface, so it stays right under fold-over.
#pragma once
#include <optional>
#include <vector>

#include "model/lattice.h"
#include "model/lattice_pack.h"
#include "model/mesh.h"
#include "pipelines/local_frame.h"
#include "pipelines/patch_output.h"

namespace sffd {

struct ErrorStats {
  double avg = 0, max = 0, std = 0;
};
ErrorStats errorStats(const std::vector<double>& values);

struct VolumeError {
  double reference = 0, result = 0, relError = 0;
};

struct ErrorReport {
  size_t vertices = 0;
  ErrorStats geometry, normalDeg;
  std::optional<VolumeError> volume;   // absent for open meshes
};

// The exact FFD of points of the input surface.
class ExactReference {
 public:
  ExactReference(const Mesh& input, const PackedLattice& lattice);
  // Pre-image on the input surface of barycentrics `lam` in triangle `parent`: point and unit normal.
  void preImage(uint32_t parent, const glm::dvec3& lam, glm::dvec3& x, glm::dvec3& n) const;
  // Exact FFD of a point and its unit normal (the outside rule of the lattice applies).
  void deform(const glm::dvec3& x, const glm::dvec3& n, glm::dvec3& xr, glm::dvec3& nr) const;
  bool exactSurface() const { return bpt_; }

 private:
  const Mesh& mesh_;
  const PackedLattice& lattice_;
  bool bpt_ = false;
};

// Geometry and normal errors of every tessellation vertex of `result` (parents index input.triangles).
ErrorReport measureErrors(const Mesh& input, const PackedLattice& lattice, const PatchVertices& result);

// Classic FFD has no patches. At its own vertices it is exact by construction (R(v) and cof(J) n), so
// it is measured where the surface is: every output triangle tessellated at `level` as a flat patch,
// positions sum lam_i p'_i and normals normalize(sum lam_i n'_i) (what a renderer interpolates), with
// the pre-image lam in the input triangle of the same index (classic keeps the input's connectivity).
PatchVertices linearPatchVertices(const Mesh& output, int level);

// Signed volume sum p0.(p1 x p2)/6 of the triangles (about the centre of their box), in the units of
// `frame` (its scale: a mesh 1e-110 across has a volume in them).
double signedVolume(const Mesh& mesh, const LocalFrame& frame = {});
// No boundary and no non-manifold edges (buildTopology, edges by weldId).
bool isClosed(const Mesh& mesh);
// The exactly deformed volume of the closed input (see above); `quadraturePoints` overrides the
// Gauss-Legendre points per direction (0: exact for the lattice's degree).
double exactDeformedVolume(const Mesh& input, const Lattice& lattice, int quadraturePoints = 0);
// Volume error of `output`, absent when the input is open.
std::optional<VolumeError> measureVolume(const Mesh& input, const Lattice& lattice, const Mesh& output);

// measureErrors and measureVolume computed in `frame` (the Deformer's: Deformer::localOrigin(),
// localScale()) and given in world units: the squared lengths and the volumes of a model 1e-100 or 1e100
// across stay in double's range there, as the devices' computation does.
ErrorReport measureErrorsInFrame(const Mesh& input, const Lattice& lattice, PatchVertices result, const Mesh& output,
                                 const LocalFrame& frame);

// Gauss-Legendre nodes and weights on [0, 1], q points (exact to degree 2q-1).
void gaussLegendre01(int q, std::vector<double>& nodes, std::vector<double>& weights);

}  // namespace sffd
