#version 450
// Split deform, steps 1, 2 and 4 (METHOD.md 3.4): every lattice evaluation of a sub-triangle, stored
// for the later steps. Same functions as the fused kernel deform_smooth.
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
  uint b = (SFFD_SAMPLE_FIXED + params.range.z) * st;
  for (uint c = 0u; c < 3u; ++c) {
    samples(b + c) = real4(Q[c], 0);
    samples(b + 3u + c) = real4(QN[c], 0);
    samples(b + 18u + c) = real4(adj[c], 0);
  }
  for (uint e = 0u; e < 6u; ++e) {
    samples(b + 6u + e) = real4(E[e], 0);
    samples(b + 12u + e) = real4(EN[e], 0);
    samples(b + 21u + e) = real4(adjNbr[e], 0);
  }
  for (uint i = 0u; i < params.range.z; ++i) samples(b + SFFD_SAMPLE_FIXED + i) = real4(smoothInteriorNormal(corners, i), 0);
}
