#version 450
// Kernel deform_smooth (K3 of METHOD.md 3.4, fused): per sub-triangle, (1) sampling and (2)
// constraint points by exact FFD, (3) control points by the constrained least-squares fit, the normal
// patch by the same fit on cofactor-deformed normals, (4) adjusting normals, (5) adjustment of the edge
// control points (tangent plane, or crease line on crease slots) and the PN centre rule, (6)
// tessellation at level L. The split form (deform_step_*) runs the same functions one step a dispatch.
#extension GL_GOOGLE_include_directive : require
#include "../common/prelude.glsl"
#define SFFD_DEFORM_OUT_ACCESS writeonly
#include "smooth_deform.glsl"


void main() {
  uint tid = sffdThreadIndex();
  if (tid >= params.range.y) return;
  uint st = params.range.x + tid;
  real3 Q[3], QN[3], adj[3], adjNbr[6], E[6], EN[6];
  SubCorners corners = smoothSubCorners(st);
  smoothBoundarySamples(st, corners, Q, QN, adj, adjNbr, E, EN);
  real3 cp[10], ncp[10];
  smoothBoundaryControlPoints(Q, QN, E, EN, cp, ncp);
  P real3 centreN = real3(0);
  for (uint i = 0u; i < params.range.z; ++i) centreN = centreN + smoothCentreTerm(ncp, smoothInteriorNormal(corners, i), i);
  ncp[4] = centreN;
  smoothAdjust(smoothCreaseBits(st), adj, adjNbr, cp);

  // The geometry patch, then the normal patch, in the two forms of smoothSubCorners: two iterations of
  // ten stores, or one an iteration through a shift register.
  uint pbase = SFFD_PATCH_STRIDE * st;
  if (!sffdRollsLoops()) {
    for (uint h = 0u; h < 2u; ++h)
      for (uint k = 0u; k < 10u; ++k) patches(pbase + 10u * h + k) = real4(h == 0u ? cp[k] : ncp[k], 0);
  } else {
    real3 r[20] = real3[20](cp[0], cp[1], cp[2], cp[3], cp[4], cp[5], cp[6], cp[7], cp[8], cp[9],
                            ncp[0], ncp[1], ncp[2], ncp[3], ncp[4], ncp[5], ncp[6], ncp[7], ncp[8], ncp[9]);
    for (uint k = 0u; k < sffdRolled(20u); ++k) {
      patches(pbase + k) = real4(r[0], 0);
      for (uint j = 0u; j < 19u; ++j) r[j] = r[j + 1u];
    }
  }
  uint L = params.range.w;
  smoothTessellate(cp, ncp, L, (L + 1u) * (L + 2u) * st);   // 2 * vertex count * st
}
