#version 450
// Split deform, step 3 (METHOD.md 3.4): control points and normal patch by the constrained fit.
#extension GL_GOOGLE_include_directive : require
#include "../common/prelude.glsl"
#include "smooth_deform.glsl"

void main() {
  uint tid = sffdThreadIndex();
  if (tid >= params.range.y) return;
  uint st = params.range.x + tid;
  uint b = (SFFD_SAMPLE_FIXED + params.range.z) * st;
  real3 Q[3], QN[3], E[6], EN[6];
  for (uint c = 0u; c < 3u; ++c) { Q[c] = samples(b + c).xyz; QN[c] = samples(b + 3u + c).xyz; }
  for (uint e = 0u; e < 6u; ++e) { E[e] = samples(b + 6u + e).xyz; EN[e] = samples(b + 12u + e).xyz; }
  real3 cp[10], ncp[10];
  smoothBoundaryControlPoints(Q, QN, E, EN, cp, ncp);
  P real3 centreN = real3(0);
  for (uint i = 0u; i < params.range.z; ++i) centreN = centreN + smoothCentreTerm(ncp, samples(b + SFFD_SAMPLE_FIXED + i).xyz, i);
  ncp[4] = centreN;
  uint pbase = SFFD_PATCH_STRIDE * st;
  for (uint k = 0u; k < 10u; ++k) {
    patches(pbase + k) = real4(cp[k], 0);
    patches(pbase + 10u + k) = real4(ncp[k], 0);
  }
}
